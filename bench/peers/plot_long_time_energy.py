#!/usr/bin/env python3
"""Plots the output of nonsep_bench_long_time (long_time_energy.csv).

Usage: python3 plot_long_time_energy.py CSV --out PNG [--dpi N]

One panel per budget (model calls per period): the largest relative energy error |H - E0| / E0 within each block
of periods (blocks log-spaced, 10 per decade) against the block's last period, log-log, one line per scheme,
coloured by family (Chin: reds, Tao: blues, Gauss: greens, peers: black/grey, dashed). A bounded error is a flat
line, a linear drift a line of slope 1. Schemes that failed at a budget are listed in the panel's legend title.
"""
import argparse
import csv
from collections import OrderedDict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {
    "chin": ["#b2182b", "#ef8a62", "#f4a582"],
    "tao": ["#08519c", "#3182bd", "#6baed6"],
    "gauss": ["#006d2c", "#31a354", "#74c476"],
    "peer": ["#000000", "#777777"],
}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv")
    parser.add_argument("--out", required=True)
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    with open(args.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    budgets = list(OrderedDict.fromkeys(r["budget"] for r in rows))
    fig, axes = plt.subplots(1, len(budgets), figsize=(6.5 * len(budgets), 6.4), squeeze=False, sharey=True)
    for ax, budget in zip(axes[0], budgets):
        mine = [r for r in rows if r["budget"] == budget]
        schemes = list(OrderedDict.fromkeys(r["scheme"] for r in mine))
        used = {family: 0 for family in COLOURS}
        failed = []
        for scheme in schemes:
            points = [r for r in mine if r["scheme"] == scheme and r["max_relative_energy_error"]]
            if not points:
                failed.append(scheme)
                continue
            family = points[0]["family"]
            colour = COLOURS[family][used[family] % len(COLOURS[family])]
            used[family] += 1
            xs = [int(r["block_last_period"]) for r in points]
            ys = [max(float(r["max_relative_energy_error"]), 1e-17) for r in points]
            label = "%s (%s steps/period)" % (scheme, points[0]["steps_per_period"])
            ax.loglog(xs, ys, color=colour, linestyle="--" if family == "peer" else "-", label=label)
        ax.set_title("budget %s model calls per period" % float(budget).__format__(".0f"))
        ax.set_xlabel("period")
        ax.grid(True, which="major", alpha=0.3)
        title = "failed at this budget: " + ", ".join(failed) if failed else None
        ax.legend(fontsize=7, title=title, title_fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2)
    axes[0][0].set_ylabel("max |dE/E| in the block of periods")
    fig.suptitle("paper1d from (2, 0): energy error over 1e5 periods at equal cost per period")
    fig.tight_layout()
    fig.savefig(args.out, dpi=args.dpi)


if __name__ == "__main__":
    main()
