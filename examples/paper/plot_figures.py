#!/usr/bin/env python3
"""Render the paper's three figures from the CSV files the nonsep runs wrote, and nothing else.

    /usr/bin/python3 examples/paper/plot_figures.py OUT_DIR

OUT_DIR is the folder `examples/paper/run_figures.sh` fills:
    reference/exact_level_curves.csv   exact level curves H(q, p) = E (nonsep_paper_reference)
    figure1/trajectory.csv             the four Figure 1 orbits (basic, t2 = -2, dt = 0.005)
    figure2_<name>/trajectory.csv      one run per Figure 2 job: paper_circle, paper_triangle, paper_twisted
                                       (the paper's settings), accurate and corrected (MPE 8/3)
    figure3/convergence.csv            the Figure 3 convergence study
Writes figure1.png, figure2.png and figure3.png into OUT_DIR. The fitted lines of Figure 3 are least squares on
log |error| against log dt over each integrator's rows, the same fit as summary.json's "fits" (the examples test
checks that the two agree).
"""
import csv
import math
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

DPI = 80


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


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
    fig, ax = plt.subplots(figsize=(6, 5))
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
    ax.set_xlabel("q")
    ax.set_ylabel("p")
    ax.set_title("Figure 1: basic step, t2 = -2, dt = 0.005", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(out / "figure1.png", dpi=DPI)
    plt.close(fig)


def figure2(out):
    runs = sorted(p for p in out.glob("figure2_*") if (p / "trajectory.csv").exists())
    if not runs:
        raise SystemExit(f"no figure2_*/trajectory.csv in {out}")
    fig, axes = plt.subplots(1, 2, figsize=(10, 6))
    for run in runs:
        name = run.name[len("figure2_"):]
        paper = name.startswith("paper")
        ax = axes[0] if paper else axes[1]
        orbits = defaultdict(lambda: ([], [], []))
        for row in read_rows(run / "trajectory.csv"):
            q1, q2, start = orbits[row["trajectory"]]
            q1.append(float(row["q0"]))
            q2.append(float(row["q1"]))
            if not start:
                start.extend([float(row["q0"]), float(row["p1"])])
        for index, (q1, q2, start) in sorted(orbits.items()):
            what = name[len("paper_"):] if paper else name
            ax.plot(q1, q2, "-" if paper or name == "corrected" else "--", lw=0.9,
                    label=f"{what}: q1 = {start[0]:g}, p2 = {start[1]:g}")
    axes[0].set_title("paper's settings: basic, t2 = -3, dt = 0.0012 / 0.001 / 0.0005", fontsize=9)
    axes[1].set_title("accurate (MPE 8/3, dt = 0.0005): paper's states (dashed), corrected", fontsize=9)
    for ax in axes:
        ax.set_xlabel("q1")
        ax.set_ylabel("q2")
        ax.set_aspect("equal")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    fig.suptitle("Figure 2: closed orbits of the 2D radial Hamiltonian (eq. hnd), one revolution", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "figure2.png", dpi=DPI, bbox_inches="tight")
    plt.close(fig)


def figure3(out):
    series = defaultdict(list)
    for row in read_rows(out / "figure3" / "convergence.csv"):
        if row["status"] == "completed" and row["relative_energy_error"]:
            series[row["integrator"]].append(row)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 5.5))
    for name, entries in series.items():
        dts = [abs(float(e["dt"])) for e in entries]
        errors = [float(e["relative_energy_error"]) for e in entries]
        work = [int(e["grad_T"]) + int(e["grad_V"]) for e in entries]
        symplectic = entries[0]["symplectic"] == "true"
        marker = "o" if symplectic else "s"
        face = None if symplectic else "none"
        line = left.loglog(dts, [abs(e) for e in errors], marker, ms=4, mfc=face)[0]
        fit = fit_power_law(dts, errors)
        label = name
        if fit:
            n, c = fit
            sign = "-" if errors[-1] < 0 else ""
            xs = [min(dts) / 1.5, max(dts) * 1.5]
            left.loglog(xs, [c * x ** n for x in xs], "-", color=line.get_color(), lw=0.8)
            label = f"{name}: {sign}{c:.3g} dt^{n:.3f}"
        line.set_label(label)
        right.loglog(work, [abs(e) for e in errors], marker + "-", ms=4, mfc=face, color=line.get_color(),
                     label=f"{name} (t2 = {float(entries[0]['t2']):g})", lw=0.7)
    left.set_xlabel("dt")
    left.set_ylabel("|relative energy error| at the quarter period")
    left.set_title("Figure 3: error versus step size; fitted c dt^n (circles symplectic, squares MPE)", fontsize=9)
    left.legend(fontsize=6, loc="lower right")
    right.set_xlabel("gradient evaluations to the quarter period (grad T + grad V)")
    right.set_ylabel("|relative energy error|")
    right.set_title("beyond the paper: error versus work", fontsize=9)
    right.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(out / "figure3.png", dpi=DPI)
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = Path(sys.argv[1])
    figure1(out)
    figure2(out)
    figure3(out)
    for name in ("figure1.png", "figure2.png", "figure3.png"):
        print(out / name)


if __name__ == "__main__":
    main()
