"""Render the dynamics pictures of paper2d from the outputs the nonsep runs wrote, with nonsep.load and
nonsep.plot.poincare / chaos_map / stability_map / indicator_series (python/nonsep, found from this file when not on
PYTHONPATH).

    /usr/bin/python3 examples/dynamics/plot_dynamics.py OUT_DIR

OUT_DIR is the folder `examples/dynamics/run_dynamics.sh` fills:
    poincare_portrait/poincare.csv       the crossings of q1 = 0 (upwards) of every orbit started on the shell
    poincare_portrait/trajectories.csv   each orbit's MEGNO <Y> (mean_megno), which colours its points
    chaos_map/trajectory.csv             each trajectory's first state (its place on the map)
    chaos_map/trajectories.csv           each trajectory's <Y> and largest exponent
    stability_map/trajectories.csv       each trajectory's coupling (a column of the sweep) and <Y>
    stability_map/trajectory.csv         each trajectory's first state (its q0 on the map)
    stability_map/lyapunov.csv           the running <Y> of every trajectory, for the time series beside the map
    */summary.json                       the energy shell, the integrator and the time, for the titles
Writes dynamics_poincare, dynamics_chaos_map and dynamics_stability_map into OUT_DIR, each as a PNG at DPI dots per
inch and as a PDF.
"""
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import LinearSegmentedColormap  # noqa: E402

try:
    import nonsep.plot
except ImportError:  # run from the source tree without PYTHONPATH=python
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
    import nonsep.plot

DPI = 200
PALETTE = 64
MEGNO_TOP = 8.0  # <Y> at or above this is drawn as the most chaotic colour
# <Y> = 2 (quasi-periodic) blue, rising to red for chaotic orbits.
CHAOS = LinearSegmentedColormap.from_list("chaos", ["#2166ac", "#67a9cf", "#fddbc7", "#ef8a62", "#b2182b"])


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


# <Y> from just below 2 to MEGNO_TOP; larger values take the top colour.
COLOURS = {"cmap": CHAOS, "vmin": 2.0 - (MEGNO_TOP - 2.0) / 8, "vmax": MEGNO_TOP}
BAR = f"(2: regular; >= {MEGNO_TOP:g} shown alike)"


def portrait(out):
    result = nonsep.load(out / "poincare_portrait")
    if result.poincare is None or len(result.poincare) == 0:
        raise SystemExit(f"{result.directory / 'poincare.csv'} has no crossings")
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    nonsep.plot.poincare(result, ax=ax, color_by="mean_megno", colorbar=False, s=0.4, **COLOURS)
    ax.set_title(f"Poincaré section q1 = 0 (upwards), {len(result.trajectories)} orbits\n"
                 f"{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.collections[0], ax=ax).set_label(f"orbit's MEGNO <Y> {BAR}")
    save(fig, out, "dynamics_poincare")


def chaos_map(out):
    result = nonsep.load(out / "chaos_map")
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    nonsep.plot.chaos_map(result, ax=ax, value="mean_megno", x="q0", y="p0", colorbar=False, **COLOURS)
    ax.set_xlabel("q0 (initial; q1 = 0)")
    ax.set_ylabel("p0 (initial; p1 >= 0 on the shell)")
    ax.set_title(f"Chaos map: MEGNO <Y> of {len(result.trajectories)} orbits (grey: off the shell)\n"
                 f"{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.images[0], ax=ax).set_label(f"<Y> {BAR}")
    save(fig, out, "dynamics_chaos_map")


def stability_map(out):
    result = nonsep.load(out / "stability_map")
    fig, (ax, series) = plt.subplots(1, 2, figsize=(12.0, 5.2), gridspec_kw={"width_ratios": [1.15, 1]})
    nonsep.plot.stability_map(result, ax=ax, value="mean_megno", x="coupling", y="q0", colorbar=False, **COLOURS)
    ax.set_ylabel("q0 (initial; q1 = p0 = 0, p1 >= 0 on the shell)")
    ax.set_title(f"Stability map: MEGNO <Y> of {len(result.trajectories)} orbits (grey: off the shell)\n"
                 f"{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.images[0], ax=ax).set_label(f"<Y> {BAR}")
    # Beside it, <Y>(t) of the most chaotic orbit and of the most regular one with its coupling.
    table = result.trajectories
    chaotic = int(np.nanargmax(table["mean_megno"]))
    same = np.flatnonzero(table["coupling"] == table["coupling"][chaotic])
    regular = int(same[np.nanargmin(np.abs(table["mean_megno"][same] - 2.0))])
    nonsep.plot.indicator_series(result, i=[regular, chaotic], value="mean_megno", ax=series)
    series.axhline(2.0, color="grey", linewidth=0.8, linestyle="--")
    series.set_title(f"<Y>(t) of the most chaotic orbit and the most regular one at its coupling\n"
                     f"(lyapunov.csv; dashed: 2, the quasi-periodic limit)", fontsize=10)
    fig.tight_layout()
    save(fig, out, "dynamics_stability_map")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = Path(sys.argv[1])
    portrait(out)
    chaos_map(out)
    stability_map(out)


if __name__ == "__main__":
    main()
