#!/usr/bin/env python3
"""Render the dynamics pictures of paper2d from the CSV files the nonsep runs wrote, and nothing else.

    /usr/bin/python3 examples/dynamics/plot_dynamics.py OUT_DIR

OUT_DIR is the folder `examples/dynamics/run_dynamics.sh` fills:
    poincare_portrait/poincare.csv       the crossings of q1 = 0 (upwards) of every orbit started on the shell
    poincare_portrait/trajectories.csv   each orbit's MEGNO <Y> (mean_megno), which colours its points
    chaos_map/trajectory.csv             each trajectory's first state (its place on the map)
    chaos_map/trajectories.csv           each trajectory's <Y> and largest exponent
    */summary.json                       the energy shell, the integrator and the time, for the titles
Writes dynamics_poincare and dynamics_chaos_map into OUT_DIR, each as a PNG at DPI dots per inch and as a PDF.
"""
import csv
import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LinearSegmentedColormap  # noqa: E402

DPI = 200
PALETTE = 64
MEGNO_TOP = 8.0  # <Y> at or above this is drawn as the most chaotic colour
# <Y> = 2 (quasi-periodic) blue, rising to red for chaotic orbits.
CHAOS = LinearSegmentedColormap.from_list("chaos", ["#2166ac", "#67a9cf", "#fddbc7", "#ef8a62", "#b2182b"])


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def save(fig, out, name):
    """name.png at DPI (recorded in its pHYs chunk) and name.pdf. With Pillow (python3-pil, a matplotlib
    dependency) the PNG is stored with a palette of PALETTE colours: a fraction of the bytes, no visible change."""
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


def subtitle(summary):
    integrator = summary["integrator"]
    shell = summary["energy_shell"]
    return (f"paper2d, H = {shell['energy']:g}; {integrator['scheme']} {integrator['order']}, "
            f"dt = {summary['time']['dt']:g}, t = {summary['time']['t_end']:g}")


def portrait(out):
    folder = out / "poincare_portrait"
    summary = json.loads((folder / "summary.json").read_text())
    megno = {int(r["trajectory"]): float(r["mean_megno"]) if r["mean_megno"] else math.nan
             for r in read_rows(folder / "trajectories.csv")}
    crossings = read_rows(folder / "poincare.csv")
    if not crossings:
        raise SystemExit(f"{folder / 'poincare.csv'} has no crossings")
    q0 = [float(r["q0"]) for r in crossings]
    p0 = [float(r["p0"]) for r in crossings]
    colour = [min(megno[int(r["trajectory"])], MEGNO_TOP) for r in crossings]
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    points = ax.scatter(q0, p0, c=colour, cmap=CHAOS, vmin=2.0 - (MEGNO_TOP - 2.0) / 8, vmax=MEGNO_TOP, s=0.4,
                        linewidths=0, rasterized=True)
    ax.set_xlabel("q0")
    ax.set_ylabel("p0")
    ax.set_title(f"Poincaré section q1 = 0 (upwards), {len(megno)} orbits\n{subtitle(summary)}", fontsize=10)
    bar = fig.colorbar(points, ax=ax)
    bar.set_label(f"orbit's MEGNO <Y> (2: regular; >= {MEGNO_TOP:g} shown alike)")
    save(fig, out, "dynamics_poincare")


def chaos_map(out):
    folder = out / "chaos_map"
    summary = json.loads((folder / "summary.json").read_text())
    job = json.loads(Path(summary["job"]).read_text())
    axes = job["initial"]["grid"]
    q_axis, p_axis = axes["q"][0], axes["p"][0]

    def index(value, axis):
        step = (axis["to"] - axis["from"]) / (axis["count"] - 1)
        return round((value - axis["from"]) / step)

    start = {}
    for r in read_rows(folder / "trajectory.csv"):
        if r["step"] == "0":
            start[int(r["trajectory"])] = (float(r["q0"]), float(r["p0"]))
    grid = [[math.nan] * q_axis["count"] for _ in range(p_axis["count"])]
    for r in read_rows(folder / "trajectories.csv"):
        q, p = start[int(r["trajectory"])]
        grid[index(p, p_axis)][index(q, q_axis)] = float(r["mean_megno"]) if r["mean_megno"] else math.nan
    half_q = (q_axis["to"] - q_axis["from"]) / (q_axis["count"] - 1) / 2
    half_p = (p_axis["to"] - p_axis["from"]) / (p_axis["count"] - 1) / 2
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    cmap = CHAOS.copy()
    cmap.set_bad("#d9d9d9")  # off the shell: H > E already at p1 = 0
    image = ax.imshow([[min(v, MEGNO_TOP) for v in row] for row in grid], origin="lower", cmap=cmap,
                      vmin=2.0 - (MEGNO_TOP - 2.0) / 8, vmax=MEGNO_TOP, interpolation="nearest", aspect="auto",
                      extent=(q_axis["from"] - half_q, q_axis["to"] + half_q, p_axis["from"] - half_p,
                              p_axis["to"] + half_p))
    ax.set_xlabel("q0 (initial; q1 = 0)")
    ax.set_ylabel("p0 (initial; p1 >= 0 on the shell)")
    ax.set_title(f"Chaos map: MEGNO <Y> of {len(start)} orbits (grey: off the shell)\n{subtitle(summary)}",
                 fontsize=10)
    bar = fig.colorbar(image, ax=ax)
    bar.set_label(f"<Y> (2: regular; >= {MEGNO_TOP:g} shown alike)")
    save(fig, out, "dynamics_chaos_map")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = Path(sys.argv[1])
    portrait(out)
    chaos_map(out)


if __name__ == "__main__":
    main()
