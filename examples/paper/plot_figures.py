#!/usr/bin/env python3
"""Render the paper's three figures from the CSV files the nonsep runs wrote, and nothing else.

    /usr/bin/python3 examples/paper/plot_figures.py OUT_DIR

OUT_DIR is the folder `examples/paper/run_figures.sh` fills:
    reference/exact_level_curves.csv   exact level curves H(q, p) = E (nonsep_paper_reference)
    figure1/trajectory.csv             the four Figure 1 orbits (basic, t2 = -2, dt = 0.005)
    figure2_<name>/trajectory.csv      one run per Figure 2 job: paper_circle, paper_triangle, paper_twisted
                                       (the paper's settings), accurate and corrected (MPE 8/3)
    figure3/convergence.csv            the Figure 3 convergence study
and each run's summary.json for its integrator and dt. Writes figure1, figure2 and figure3 into OUT_DIR, each as
a PNG at DPI dots per inch and as a PDF (vector). Legends sit outside the axes, so they never cover data. The
fitted lines of Figure 3 are least squares on log |error| against log dt over each integrator's rows, the same
fit as summary.json's "fits" (the examples test checks that the two agree).
"""
import csv
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 150
PALETTE = 128
FIGURES = ("figure1", "figure2", "figure3")
# Figure 3's series: one colour and one marker each (no two series share either), in convergence.csv's order.
# Symplectic schemes are drawn with filled markers, MPE (not symplectic) with open ones.
COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf", "#000000"]
MARKERS = ["o", "s", "^", "v", "D", "P", "X", "<", ">", "h", "*"]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def save(fig, out, name):
    """name.png at DPI (the PNG's pHYs chunk records it) and name.pdf, both cropped to what is drawn, legends
    outside the axes included. When Pillow is there (Debian's python3-pil, which matplotlib depends on) the PNG
    is stored with a palette of PALETTE colours: a quarter of the bytes, no visible difference for line plots."""
    png = out / f"{name}.png"
    fig.savefig(png, dpi=DPI, bbox_inches="tight")
    fig.savefig(out / f"{name}.pdf", bbox_inches="tight")
    plt.close(fig)
    try:
        from PIL import Image
    except ImportError:
        return
    with Image.open(png) as image:
        small = image.convert("RGB").quantize(colors=PALETTE, method=Image.Quantize.MEDIANCUT)
    small.save(png, optimize=True, dpi=(DPI, DPI))


def summary(run):
    return json.loads((run / "summary.json").read_text())


def fit_power_law(dts, errors):
    """(exponent, constant) of |error| = constant * dt^exponent by least squares in log-log; None if < 2 points."""
    points = [(math.log(abs(d)), math.log(abs(e))) for d, e in zip(dts, errors) if e != 0 and math.isfinite(e)]
    if len(points) < 2:
        return None
    mx = sum(x for x, _ in points) / len(points)
    my = sum(y for _, y in points) / len(points)
    sxx = sum((x - mx) ** 2 for x, _ in points)
    if sxx == 0:
        return None
    n = sum((x - mx) * (y - my) for x, y in points) / sxx
    return n, math.exp(my - n * mx)


def figure1(out):
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    curves = defaultdict(lambda: ([], []))
    for row in read_rows(out / "reference" / "exact_level_curves.csv"):
        qs, ps = curves[row["energy"]]
        qs.append(float(row["q"]))
        ps.append(float(row["p"]))
    for i, (energy, (qs, ps)) in enumerate(curves.items()):
        ax.plot(qs, ps, "-", color="0.3", lw=1, label="exact H = E" if i == 0 else None)
    points = defaultdict(lambda: ([], [], []))
    for row in read_rows(out / "figure1" / "trajectory.csv"):
        qs, ps, es = points[row["trajectory"]]
        qs.append(float(row["q0"]))
        ps.append(float(row["p0"]))
        es.append(abs(float(row["relative_energy_error"])))
    for index, (qs, ps, es) in sorted(points.items()):
        ax.plot(qs, ps, "*", ms=2.5, label=f"q0 = {qs[0]:g}: max |dE/E| = {max(es):.2g}")
    run = summary(out / "figure1")
    ax.set_xlabel("q")
    ax.set_ylabel("p")
    ax.set_title(f"Figure 1: {run['integrator']['scheme']} step, t2 = {run['integrator']['t2']:g}, "
                 f"dt = {run['time']['dt']:g}", fontsize=10)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0, markerscale=3)
    ax.set_aspect("equal")
    save(fig, out, "figure1")


def figure2(out):
    """Left: the paper's settings, one run (and one dt) per orbit; right: the accurate runs. Each legend entry
    names its orbit's integrator and dt; axes and initial states use trajectory.csv's 0-based component names
    (the paper's q1, q2, p1, p2 are q0, q1, p0, p1)."""
    runs = sorted(p for p in out.glob("figure2_*") if (p / "trajectory.csv").exists())
    if not runs:
        raise SystemExit(f"no figure2_*/trajectory.csv in {out}")
    fig, axes = plt.subplots(1, 2, figsize=(10, 5.2))
    for run in runs:
        name = run.name[len("figure2_"):]
        paper = name.startswith("paper")
        ax = axes[0] if paper else axes[1]
        about = summary(run)
        dt = about["time"]["dt"]
        scheme = about["integrator"]["scheme"] + ("" if about["integrator"]["scheme"] == "basic"
                                                  else " " + about["integrator"]["order"])
        orbits = defaultdict(lambda: ([], [], []))
        for row in read_rows(run / "trajectory.csv"):
            q0, q1, start = orbits[row["trajectory"]]
            q0.append(float(row["q0"]))
            q1.append(float(row["q1"]))
            if not start:
                start.extend([float(row["q0"]), float(row["p1"])])
        for index, (q0, q1, start) in sorted(orbits.items()):
            what = name[len("paper_"):] if paper else name
            ax.plot(q0, q1, "-" if paper or name == "corrected" else "--", lw=0.9,
                    label=f"{what}, {scheme}, dt = {dt:g}: q0 = {start[0]:g}, p1 = {start[1]:g}")
    axes[0].set_title("the paper's settings (basic, t2 = -3): one dt per orbit", fontsize=9)
    axes[1].set_title("accurate: the paper's states (dashed), corrected states (solid)", fontsize=9)
    for ax in axes:
        ax.set_xlabel("q0 (the paper's q1)")
        ax.set_ylabel("q1 (the paper's q2)")
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=1)
    fig.suptitle("Figure 2: closed orbits of the 2D radial Hamiltonian (eq. hnd), one revolution", fontsize=10)
    fig.tight_layout()
    save(fig, out, "figure2")


# convergence.csv's column that the study fits: the largest |dH/H0| over each run (H at every step).
ENERGY = "max_abs_relative_energy_error"


def figure3(out):
    """Left: |error| against dt with the fitted lines; right: |error| against gradient evaluations. One legend
    for both panels, below them: each series has its own colour and marker."""
    series = defaultdict(list)
    for row in read_rows(out / "figure3" / "convergence.csv"):
        if row["status"] == "completed" and row[ENERGY]:
            series[row["integrator"]].append(row)
    if len(series) > len(COLOURS):
        raise SystemExit(f"{len(series)} series in figure3/convergence.csv, only {len(COLOURS)} colour-marker pairs")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.6))
    handles = []
    for (name, entries), colour, marker in zip(series.items(), COLOURS, MARKERS):
        dts = [abs(float(e["dt"])) for e in entries]
        # The largest |dH/H0| over each run, signed as the error at t_end: the study's fits use the same.
        errors = [math.copysign(float(e[ENERGY]), float(e["relative_energy_error"])) for e in entries]
        work = [int(e["grad_T"]) + int(e["grad_V"]) for e in entries]
        symplectic = entries[0]["symplectic"] == "true"
        style = dict(marker=marker, ms=5, color=colour, mfc=colour if symplectic else "none", mew=1.0)
        line = left.loglog(dts, [abs(e) for e in errors], linestyle="none", **style)[0]
        fit = fit_power_law(dts, errors)
        label = f"{name} (t2 = {float(entries[0]['t2']):g})"
        if fit:
            n, c = fit
            sign = "-" if errors[-1] < 0 else ""
            xs = [min(dts) / 1.5, max(dts) * 1.5]
            left.loglog(xs, [c * x ** n for x in xs], "-", color=colour, lw=0.8)
            label += f": {sign}{c:.3g} dt^{n:.3f}"
        line.set_label(label)
        handles.append(line)
        right.loglog(work, [abs(e) for e in errors], linestyle="-", lw=0.7, **style)
    left.set_xlabel("dt")
    left.set_ylabel("|relative energy error| at the quarter period")
    left.set_title("Figure 3: error versus step size, fitted c dt^n", fontsize=9)
    right.set_xlabel("gradient evaluations to the quarter period (grad T + grad V)")
    right.set_ylabel("|relative energy error|")
    right.set_title("beyond the paper: error versus work", fontsize=9)
    fig.tight_layout()
    fig.legend(handles=handles, fontsize=7, ncol=3, loc="upper center", bbox_to_anchor=(0.5, 0.0),
               title="filled: symplectic (basic, triplet); open: MPE", title_fontsize=7)
    save(fig, out, "figure3")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    figure1(out)
    figure2(out)
    figure3(out)
    for name in FIGURES:
        print(out / f"{name}.png", out / f"{name}.pdf")


if __name__ == "__main__":
    main()
