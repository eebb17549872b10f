#!/usr/bin/env python3
"""Render the paper's three figures from the CSV files the nonsep runs wrote, and nothing else.

    python3 examples/paper/plot_figures.py OUT_DIR

OUT_DIR is the folder `examples/paper/run_figures.sh` fills:
    reference/exact_level_curves.csv       exact level curves H(q, p) = E (nonsep_paper_reference)
    figure1/trajectory.csv                 the four Figure 1 orbits (basic, t2 = -2, dt = 0.005)
    figure2_<name>/trajectory.csv          one run per Figure 2 orbit and setting
    figure3/convergence.csv                the Figure 3 convergence study
Writes figure1.png, figure2.png and figure3.png into OUT_DIR.
"""
import csv
import math
import sys
from collections import defaultdict
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def figure1(out):
    fig, ax = plt.subplots(figsize=(6, 5))
    curves = defaultdict(lambda: ([], []))
    for row in read_rows(out / "reference" / "exact_level_curves.csv"):
        qs, ps = curves[row["energy"]]
        qs.append(float(row["q"]))
        ps.append(float(row["p"]))
    for energy, (qs, ps) in curves.items():
        ax.plot(qs, ps, "-", color="0.4", lw=1, label="exact" if energy == next(iter(curves)) else None)
    points = defaultdict(lambda: ([], []))
    for row in read_rows(out / "figure1" / "trajectory.csv"):
        qs, ps = points[row["trajectory"]]
        qs.append(float(row["q0"]))
        ps.append(float(row["p0"]))
    for index, (qs, ps) in sorted(points.items()):
        ax.plot(qs, ps, "*", ms=3, label=f"computed, q0 = {qs[0]:g}")
    ax.set_xlabel("q")
    ax.set_ylabel("p")
    ax.set_title("Figure 1: H = (1 + p²/2)² (1 + q²), basic step, t2 = -2, dt = 0.005")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(out / "figure1.png", dpi=90)


def figure2(out):
    runs = sorted(p for p in out.glob("figure2_*") if (p / "trajectory.csv").exists())
    fig, axes = plt.subplots(1, 2, figsize=(10, 5))
    for run in runs:
        name = run.name[len("figure2_"):]
        ax = axes[0] if name.startswith("paper") else axes[1]
        by_trajectory = defaultdict(lambda: ([], []))
        for row in read_rows(run / "trajectory.csv"):
            qs, ps = by_trajectory[row["trajectory"]]
            qs.append(float(row["q0"]))
            ps.append(float(row["q1"]))
        for index, (q1, q2) in sorted(by_trajectory.items()):
            ax.plot(q1, q2, "-", lw=0.8, label=f"{name} #{index}")
    axes[0].set_title("paper's settings: basic, t2 = -3")
    axes[1].set_title("accurate: MPE 8/3 (paper's and corrected initial states)")
    for ax in axes:
        ax.set_xlabel("q1")
        ax.set_ylabel("q2")
        ax.set_aspect("equal")
        ax.legend(fontsize=6)
    fig.suptitle("Figure 2: closed orbits of the 2D radial Hamiltonian (eq. hnd)")
    fig.tight_layout()
    fig.savefig(out / "figure2.png", dpi=90)


def figure3(out):
    rows = read_rows(out / "figure3" / "convergence.csv")
    series = defaultdict(list)
    for row in rows:
        series[row["integrator"]].append(row)
    fits = {}
    summary = out / "figure3" / "summary.json"
    if summary.exists():
        import json
        for entry in json.loads(summary.read_text()).get("fits", []):
            fits[entry["integrator"]] = entry
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 5))
    for name, entries in series.items():
        dts = [abs(float(e["dt"])) for e in entries]
        errors = [abs(float(e["relative_energy_error"])) for e in entries]
        work = [int(e["grad_T"]) + int(e["grad_V"]) for e in entries]
        symplectic = entries[0]["symplectic"] == "true"
        marker = "o" if symplectic else "s"
        face = None if symplectic else "none"
        line = left.loglog(dts, errors, marker, mfc=face, label=name)[0]
        fit = fits.get(name)
        if fit:
            c, n = fit["constant"], fit["exponent"]
            xs = [min(dts), max(dts)]
            left.loglog(xs, [abs(c) * x ** n for x in xs], "-", color=line.get_color(), lw=0.8)
            line.set_label(f"{name}: {c:.3g} dt^{n:.3f}")
        right.loglog(work, errors, marker + "-", mfc=face, color=line.get_color(), label=name, lw=0.6)
    left.set_xlabel("dt")
    left.set_ylabel("|relative energy error| at the quarter period")
    left.set_title("Figure 3: error versus step size, fitted c dt^n")
    left.legend(fontsize=6)
    right.set_xlabel("gradient evaluations (grad T + grad V)")
    right.set_ylabel("|relative energy error|")
    right.set_title("what each order gains per gradient evaluation")
    right.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(out / "figure3.png", dpi=90)


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
