#!/usr/bin/env python3
"""Plots the output of nonsep_bench_drift_at_equal_accuracy (drift_at_equal_accuracy.csv).

Usage: python3 plot_drift_at_equal_accuracy.py CSV --out PNG [--dpi N]

One panel per target (the largest phase-space error at t = 10 on the ensemble that every method's setting meets):
the largest relative energy error |H - E0| / E0 within each block of periods (log-spaced, 10 per decade) against the
block's last period, log-log, one line per method: nonsep's Gauss-Legendre solid (greens), Odeint's adaptive methods
dashed (black and greys). A bounded error is a flat line, a linear drift a line of slope 1.
"""
import argparse
import csv
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"nonsep": ["#006d2c", "#74c476"], "odeint": ["#000000", "#666666", "#aaaaaa"]}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv")
    parser.add_argument("--out", required=True)
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    targets = list(OrderedDict.fromkeys(r["target"] for r in rows))
    fig, axes = plt.subplots(1, len(targets), figsize=(6.5 * len(targets), 5.6), squeeze=False, sharey=True)
    for ax, target in zip(axes[0], targets):
        mine = [r for r in rows if r["target"] == target]
        used = {family: 0 for family in COLOURS}
        for method in OrderedDict.fromkeys(r["method"] for r in mine):
            points = [r for r in mine if r["method"] == method]
            family = points[0]["family"]
            colour = COLOURS[family][used[family] % len(COLOURS[family])]
            used[family] += 1
            xs = [int(r["block_last_period"]) for r in points]
            ys = [max(float(r["max_relative_energy_error"]), 1e-17) for r in points]
            label = "%s, %s (%.0f calls/period)" % (method, points[0]["setting"], float(points[0]["calls_per_period"]))
            ax.loglog(xs, ys, color=colour, linestyle="-" if family == "nonsep" else "--", label=label)
        ax.set_title("phase-space error <= %s at t = 10 on the ensemble" % target)
        ax.set_xlabel("period")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
    axes[0][0].set_ylabel("max |dE/E| in the block of periods")
    fig.suptitle("paper1d, the ensemble's largest orbit: energy error over 1e5 periods, each method set for the target")
    fig.tight_layout()
    fig.savefig(args.out, dpi=args.dpi)


if __name__ == "__main__":
    main()
