#!/usr/bin/env python3
"""Plots the CSV of nonsep_bench_scaling (docs/scaling.md) and fits the growth exponent of each configuration.

Usage: /usr/bin/python3 scripts/plot_scaling.py SCALING.csv --out FILE.png [--fit-from N] [--dpi N]

Left panel: seconds per step (median, with the lowest and highest repetition as error bars) against n, log-log.
Right panel: the same as a ratio to one gradient evaluation at that n. Prints one line per configuration with the
least-squares slope of log(seconds per step) against log(n) over n >= --fit-from (default 100): the exponent e of
cost ~ n^e. Needs matplotlib (Debian's python3-matplotlib: /usr/bin/python3).
"""
import argparse
import csv
import math
import sys


def read(path):
    rows = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            rows.setdefault(row["configuration"], []).append(
                (int(row["n"]), float(row["seconds_per_step"]), float(row["lowest"]), float(row["highest"]),
                 float(row["ratio_to_gradient"])))
    if not rows:
        sys.exit(f"{path}: no rows (expected the CSV of nonsep_bench_scaling)")
    return rows


def slope(points):
    xs = [math.log(n) for n, *_ in points]
    ys = [math.log(s) for _, s, *_ in points]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx if sxx > 0 else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv")
    parser.add_argument("--out", required=True)
    parser.add_argument("--fit-from", type=int, default=100)
    parser.add_argument("--dpi", type=int, default=110)
    args = parser.parse_args()
    rows = read(args.csv)
    print(f"{'configuration':28s} exponent (n >= {args.fit_from})   ratio to a gradient at the largest n")
    for name, points in rows.items():
        fitted = [p for p in points if p[0] >= args.fit_from]
        e = slope(fitted) if len(fitted) >= 2 else float("nan")
        print(f"{name:28s} {e:8.3f}                 {points[-1][4]:8.2f}")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (left, right) = plt.subplots(1, 2, figsize=(14, 5))
    # More configurations than the default cycle's ten colours: each its own colour and a marker of its own.
    colours = plt.get_cmap("tab20").colors
    markers = "os^vD<>pXh*P"
    for k, (name, points) in enumerate(rows.items()):
        n = [p[0] for p in points]
        median = [p[1] for p in points]
        errors = [[p[1] - p[2] for p in points], [p[3] - p[1] for p in points]]
        style = dict(color=colours[(2 * k) % 20 + (2 * k) // 20 % 2], marker=markers[k % len(markers)], label=name)
        left.errorbar(n, median, yerr=errors, capsize=2, **style)
        right.plot(n, [p[4] for p in points], **style)
    left.set(xscale="log", yscale="log", xlabel="n (sites)", ylabel="seconds per step (median)")
    right.set(xscale="log", yscale="log", xlabel="n (sites)", ylabel="time / one gradient evaluation")
    for axis in (left, right):
        axis.grid(True, which="both", alpha=0.3)
    right.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.suptitle("lattice_chain: cost per step against n")
    fig.tight_layout()
    fig.savefig(args.out, dpi=args.dpi)


if __name__ == "__main__":
    main()
