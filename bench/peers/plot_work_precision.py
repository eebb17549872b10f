#!/usr/bin/env python3
"""Plots the output of nonsep_bench_work_precision.

Usage: python3 plot_work_precision.py [DIR] [--out OUTDIR] [--dpi N]
Reads DIR/work_precision.csv and DIR/energy_drift.csv (DIR defaults to the current directory) and writes
OUTDIR/work_precision.png and OUTDIR/energy_drift.png (OUTDIR defaults to DIR).

work_precision.png: error against median wall time, log-log, one panel per problem and error kind. Each curve
is one method's Pareto front over its settings (step count, and t2 for nonsep or the Newton tolerance for
GSL): the smallest error reached at that time or less. Dotted lines mark the targets.
energy_drift.png: the largest relative energy error within each period, against the period, log-log
(bounded: flat; drift: slope 1).
"""
import argparse
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TARGETS = [1e-4, 1e-6, 1e-8, 1e-10]


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def pareto_front(points):
    """Points (time, error) sorted by time, keeping only those that improve on every faster one."""
    front, best = [], math.inf
    for time, error in sorted(points):
        if error < best:
            front.append((time, error))
            best = error
    return front


def plot_work_precision(rows, path, dpi):
    problems = sorted({r["problem"] for r in rows}, key=lambda p: (p != "paper1d", p))
    kinds = [("energy_error", "relative energy error"), ("phase_error", "phase-space error")]
    methods = []
    for r in rows:
        if r["method"] not in methods:
            methods.append(r["method"])
    nonsep = [m for m in methods if any(r["method"] == m and r["family"] == "nonsep" for r in rows)]
    colours = plt.get_cmap("tab20")
    style = {}
    for i, m in enumerate(nonsep):
        style[m] = dict(color=colours(i % 20), linestyle="-", marker=".", linewidth=1.2)
    peer_markers = ["s", "D", "^", "v", "o"]
    peer_colours = ["black", "dimgray", "magenta", "darkcyan", "olive"]
    for i, m in enumerate(x for x in methods if x not in nonsep):
        style[m] = dict(color=peer_colours[i % 5], linestyle="--", marker=peer_markers[i % 5], linewidth=2,
                        markersize=4)

    fig, axes = plt.subplots(len(problems), 2, figsize=(13, 5 * len(problems)), squeeze=False)
    for row_index, problem in enumerate(problems):
        for col_index, (column, label) in enumerate(kinds):
            ax = axes[row_index][col_index]
            for m in methods:
                points = []
                for r in rows:
                    if r["problem"] != problem or r["method"] != m or r["status"] != "ok":
                        continue
                    t, e = float(r["wall_seconds_median"]), float(r[column])
                    if math.isfinite(e) and e > 0 and t > 0:
                        points.append((t, max(e, 1e-17)))
                front = pareto_front(points)
                if front:
                    ax.plot([p[0] for p in front], [p[1] for p in front], label=m, **style[m])
            for target in TARGETS:
                ax.axhline(target, color="gray", linestyle=":", linewidth=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_ylim(1e-14, 1e1)
            ax.set_xlabel("wall time per run [s] (median)")
            ax.set_ylabel(label)
            ax.set_title(f"{problem}: {label}")
            ax.grid(True, which="major", alpha=0.3)
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def plot_energy_drift(rows, path, dpi):
    fig, ax = plt.subplots(figsize=(8, 5))
    methods = []
    for r in rows:
        if r["method"] not in methods:
            methods.append(r["method"])
    for m in methods:
        periods = [int(r["period"]) for r in rows if r["method"] == m]
        errors = [float(r["energy_error_max"]) for r in rows if r["method"] == m]
        dt = next(float(r["dt"]) for r in rows if r["method"] == m)
        ax.plot(periods, errors, label=m, linewidth=1.2)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("period")
    ax.set_ylabel("max |relative energy error| within the period")
    ax.set_title(f"paper1d from (q, p) = (2, 0), dt = {dt:.4g}")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", nargs="?", default=".", help="folder with the CSV files")
    parser.add_argument("--out", help="folder for the PNG files (default: the CSV folder)")
    parser.add_argument("--dpi", type=int, default=80)
    args = parser.parse_args()
    out = args.out or args.dir
    os.makedirs(out, exist_ok=True)
    plot_work_precision(read_rows(os.path.join(args.dir, "work_precision.csv")),
                        os.path.join(out, "work_precision.png"), args.dpi)
    plot_energy_drift(read_rows(os.path.join(args.dir, "energy_drift.csv")),
                      os.path.join(out, "energy_drift.png"), args.dpi)
    print(f"wrote {os.path.join(out, 'work_precision.png')} and {os.path.join(out, 'energy_drift.png')}")


if __name__ == "__main__":
    main()
