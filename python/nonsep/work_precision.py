"""Plots the work_precision.csv of a nonsep study (docs/studies.md, "Work-precision studies"); installed with the package.

Usage: /usr/bin/python3 -m nonsep.work_precision STUDY_DIR --out FILE.png [--title TEXT]
           [--peers PEERS_CSV --problem NAME] [--error phase|energy|relative-phase] [--dpi N]

Two panels: the error against the median wall time, and against the evaluations (grad_T + grad_V +
grad_H per trajectory), log-log: the phase-space error at t_end, or with --error energy the largest relative
energy error |dH/H0| over the run (column max_abs_relative_energy_error; a study written before that column
existed gives the error at t_end, and the axis says so). Each curve is one integrator's Pareto front over its
step counts: the smallest error reached at that cost or less. Failed or diverged runs are left out. --error
relative-phase divides the phase-space error by the length |(q, p)_ref| of the study's reference state
(summary.json study.reference), so that an accuracy means the same per degree of freedom whatever the dimension.
With --peers, the rows of bench/peers' work_precision.csv for --problem (GSL rk2imp/rk4imp, Odeint dopri5/rk4; columns method, problem,
wall_seconds_median, evaluations, energy_error, phase_error, status) join both panels as dashed fronts.
Needs matplotlib (Debian's python3-matplotlib: /usr/bin/python3).
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def pareto_front(points):
    """(cost, error) pairs sorted by cost, keeping only those that improve on every cheaper one."""
    front, best = [], math.inf
    for cost, error in sorted(points):
        if error < best:
            front.append((cost, error))
            best = error
    return front


def number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return abs(value) if math.isfinite(value) and value != 0.0 else None


def reference_length(study_dir):
    """|(q, p)_ref| of a study's reference state (summary.json study.reference)."""
    with open(os.path.join(study_dir, "summary.json")) as f:
        reference = json.load(f)["study"].get("reference")
    if not reference:
        sys.exit(f"nonsep.work_precision: {study_dir}/summary.json has no study.reference (a study with a reference)")
    return math.sqrt(sum(x * x for x in reference["q"] + reference["p"]))


def study_curves(path, error_column, scale=1.0):
    """{label: (family, [(wall, evaluations, error / scale)])} from a study's work_precision.csv."""
    curves = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["status"] != "completed":
                continue
            error = number(row[error_column])
            if error is None:
                continue
            family = row["family"]
            curves.setdefault(row["integrator"], (family, []))[1].append(
                (float(row["wall_seconds"]), float(row["evaluations"]), error / scale))
    return curves


def peer_curves(path, problem, error_column):
    curves = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["problem"] != problem or row["status"] not in ("ok", "completed"):
                continue
            if not row["method"].startswith(("gsl", "odeint")):
                continue
            error = number(row[error_column])
            if error is None:
                continue
            curves.setdefault(row["method"], ("peer", []))[1].append(
                (float(row["wall_seconds_median"]), float(row["evaluations"]), error))
    return curves


def energy_column(study_dir):
    """The largest |dH/H0| over each run when the study has it, else the error at t_end."""
    with open(os.path.join(study_dir, "work_precision.csv"), newline="") as f:
        header = next(csv.reader(f), [])
    return "max_abs_relative_energy_error" if "max_abs_relative_energy_error" in header else "relative_energy_error"


def title(text, families):
    """The figure's title and the line styles of the families it shows (peers only when there are some)."""
    names = [(family, style) for family, style in (("chin", "solid: Chin"), ("comparator", "dash-dot: comparators"),
                                                   ("peer", "dashed: peers")) if family in families]
    legend = ", ".join(style for _, style in names)
    return (text + " (" + legend + ")").strip() if legend else text


STYLE = {"chin": "-", "comparator": "-.", "peer": "--"}
MARKER = {"chin": "o", "comparator": "s", "peer": "^"}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("study_dir")
    parser.add_argument("--out", required=True)
    parser.add_argument("--title", default="")
    parser.add_argument("--peers")
    parser.add_argument("--problem")
    parser.add_argument("--error", choices=["phase", "energy", "relative-phase"], default="phase")
    parser.add_argument("--dpi", type=int, default=150)
    args = parser.parse_args()
    column = energy_column(args.study_dir) if args.error == "energy" else "phase_error"
    scale = reference_length(args.study_dir) if args.error == "relative-phase" else 1.0
    curves = study_curves(os.path.join(args.study_dir, "work_precision.csv"), column, scale)
    if args.peers:
        if not args.problem:
            sys.exit("nonsep.work_precision: --peers needs --problem (paper1d, tao_product, ...)")
        if args.error == "relative-phase":
            sys.exit("nonsep.work_precision: --peers gives absolute phase errors; use --error phase with --peers")
        peer_column = "phase_error" if args.error == "phase" else "energy_error"
        curves.update(peer_curves(args.peers, args.problem, peer_column))
    if not curves:
        sys.exit("nonsep.work_precision: no completed run with a finite non-zero " + column)
    figure, axes = plt.subplots(1, 2, figsize=(12, 5))
    colors = plt.get_cmap("tab20").colors
    for index_curve, (label, (family, points)) in enumerate(sorted(curves.items())):
        for axis, index, name in ((axes[0], 0, "median wall seconds per run"), (axes[1], 1, "evaluations")):
            front = pareto_front([(p[index], p[2]) for p in points])
            axis.loglog([c for c, _ in front], [e for _, e in front], STYLE.get(family, ":"),
                        marker=MARKER.get(family, "x"), markersize=3, label=label,
                        color=colors[index_curve % len(colors)])
            axis.set_xlabel(name)
    ylabel = {"phase": "phase-space error at t_end",
              "energy": ("largest |dH/H0| over the run" if column == "max_abs_relative_energy_error"
                         else "relative energy error at t_end"),
              "relative-phase": "relative phase-space error at t_end"}[args.error]
    for axis in axes:
        axis.set_ylabel(ylabel)
        axis.grid(True, which="major", alpha=0.3)
    axes[1].legend(fontsize=7, ncol=2)
    figure.suptitle(title(args.title, {family for family, _ in curves.values()}))
    figure.tight_layout()
    figure.savefig(args.out, dpi=args.dpi)
    print("wrote " + args.out)


if __name__ == "__main__":
    main()
