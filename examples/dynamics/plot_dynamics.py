"""Render the dynamics pictures of paper2d from the outputs the nonsep runs wrote, with nonsep.load and
nonsep.plot.poincare / chaos_map / stability_map / chaotic_fraction / indicator_series / frequency_map (python/nonsep,
found from this file when not on PYTHONPATH), on their default colour scales (MEGNO <Y> from 1.25 to 8, 2 marked).

    /usr/bin/python3 examples/dynamics/plot_dynamics.py OUT_DIR

OUT_DIR is the folder `examples/dynamics/run_dynamics.sh` fills:
    poincare_portrait/poincare.csv       the crossings of q1 = 0 (upwards) of every orbit started on the shell
    poincare_portrait/trajectories.csv   each orbit's MEGNO <Y> (mean_megno), which colours its points
    chaos_map/trajectory.csv             each trajectory's first state (its place on the map)
    chaos_map/trajectories.csv           each trajectory's <Y> and largest exponent
    stability_map/trajectories.csv       each trajectory's coupling (a column of the sweep) and <Y>
    stability_map/trajectory.csv         each trajectory's first state (its q0 on the map)
    stability_map/lyapunov.csv           the running <Y> of every trajectory, for the time series beside the map
    stability_map_shell8/                the same on the shell H = 8 over the couplings 0 to 0.3 (no lyapunov.csv)
    chaotic_fraction/                    <Y> of a (q0, p0) grid on the shell H = 8 for each coupling
    frequency_map/                       the frequencies and the diffusion index of Henon-Heiles on H = 1/8
    */summary.json                       the energy shell, the integrator and the time, for the titles
Writes dynamics_poincare, dynamics_chaos_map, dynamics_stability_map, dynamics_stability_map_shell8,
dynamics_chaotic_fraction and dynamics_frequency_map into OUT_DIR, each as a PNG at DPI dots per inch and as a PDF,
and prints the chaotic fractions and the range of the diffusion index.
"""
import sys
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

try:
    import nonsep.plot
except ImportError:  # run from the source tree without PYTHONPATH=python
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
    import nonsep.plot

DPI = 200
PALETTE = 64


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


def portrait(out):
    result = nonsep.load(out / "poincare_portrait")
    if result.poincare is None or len(result.poincare) == 0:
        raise SystemExit(f"{result.directory / 'poincare.csv'} has no crossings")
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    nonsep.plot.poincare(result, ax=ax, color_by="mean_megno", s=0.4)
    ax.set_title(f"Poincaré section q1 = 0 (upwards) of {len(result.trajectories)} orbits, coloured by their "
                 f"MEGNO\n{nonsep.plot.describe_run(result)}", fontsize=10)
    save(fig, out, "dynamics_poincare")


def chaos_map(out):
    result = nonsep.load(out / "chaos_map")
    fig, ax = plt.subplots(figsize=(6.4, 5.6))
    nonsep.plot.chaos_map(result, ax=ax, value="mean_megno", x="q0", y="p0")
    ax.set_xlabel("q0 (initial; q1 = 0)")
    ax.set_ylabel("p0 (initial; p1 >= 0 on the shell)")
    save(fig, out, "dynamics_chaos_map")


def stability_map(out):
    result = nonsep.load(out / "stability_map")
    fig, (ax, series) = plt.subplots(1, 2, figsize=(12.0, 5.2), gridspec_kw={"width_ratios": [1.15, 1]})
    nonsep.plot.stability_map(result, ax=ax, value="mean_megno", x="coupling", y="q0")
    ax.set_ylabel("q0 (initial; q1 = p0 = 0, p1 >= 0 on the shell)")
    # Beside it, <Y>(t) of the most chaotic orbit and of the most regular one with its coupling.
    table = result.trajectories
    chaotic = int(np.nanargmax(table["mean_megno"]))
    same = np.flatnonzero(table["coupling"] == table["coupling"][chaotic])
    regular = int(same[np.nanargmin(np.abs(table["mean_megno"][same] - 2.0))])
    nonsep.plot.indicator_series(result, i=[regular, chaotic], value="mean_megno", ax=series)
    series.set_title("<Y>(t) of the most chaotic orbit and the most regular one at its coupling\n"
                     "(lyapunov.csv; dashed: 2, the quasi-periodic limit)", fontsize=10)
    fig.tight_layout()
    save(fig, out, "dynamics_stability_map")


def stability_map_shell8(out):
    result = nonsep.load(out / "stability_map_shell8")
    fig, ax = plt.subplots(figsize=(7.2, 5.4))
    nonsep.plot.stability_map(result, ax=ax, value="mean_megno", x="coupling", y="q0")
    ax.set_ylabel("q0 (initial; q1 = p0 = 0, p1 >= 0 on the shell)")
    save(fig, out, "dynamics_stability_map_shell8")


def chaotic_fraction(out):
    """The fraction against the coupling, between the chaos maps of the smallest and the largest coupling."""
    result = nonsep.load(out / "chaotic_fraction")
    couplings = np.unique(result.trajectories["coupling"])
    fig, (first, fraction, last) = plt.subplots(1, 3, figsize=(17.0, 5.0), gridspec_kw={"width_ratios": [1, 1.1, 1]})
    for ax, coupling in ((first, couplings[0]), (last, couplings[-1])):
        nonsep.plot.chaos_map(result, ax=ax, x="q0", y="p0", where={"coupling": coupling})
    nonsep.plot.chaotic_fraction(result, ax=fraction)
    fig.tight_layout()
    save(fig, out, "dynamics_chaotic_fraction")
    counts = result.chaotic_fraction()
    for value, chaotic, orbits, lower, upper in zip(counts.values, counts.chaotic, counts.orbits, counts.lower,
                                                     counts.upper):
        print(f"coupling {value:g}: {chaotic} of {orbits} orbits with {counts.criterion} "
              f"({chaotic / orbits:.3f}, interval {lower:.3f} to {upper:.3f})")


def frequency_map(out):
    """The frequency map of Henon-Heiles (nu_1 against nu_0, coloured by the diffusion index) beside the diffusion
    index over the starting points."""
    result = nonsep.load(out / "frequency_map")
    fig, (frequencies, diffusion) = plt.subplots(1, 2, figsize=(13.0, 5.4), gridspec_kw={"width_ratios": [1.1, 1]})
    nonsep.plot.frequency_map(result, ax=frequencies)
    # The starting point q = p0 = 0 moves in q1 alone: its z_0 = 0 has the frequency 0, far off the others.
    table = result.trajectories
    bulk = table["frequency0"][np.abs(table["frequency0"]) > 0.5]
    frequencies.set_xlim(bulk.min() - 0.01, bulk.max() + 0.01)
    nonsep.plot.chaos_map(result, ax=diffusion, value="diffusion", x="q1", y="p1")
    diffusion.set_xlabel("q1 (initial; q0 = 0)")
    diffusion.set_ylabel("p1 (initial; p0 >= 0 on the shell)")
    fig.tight_layout()
    save(fig, out, "dynamics_frequency_map")
    index = table["diffusion"][np.isfinite(table["diffusion"])]
    print(f"frequency map: {len(index)} orbits analysed, diffusion index from {index.min():.2f} to "
          f"{index.max():.2f}, {int((index > -3).sum())} above -3, {int((index < -6).sum())} below -6")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = Path(sys.argv[1])
    portrait(out)
    chaos_map(out)
    stability_map(out)
    stability_map_shell8(out)
    chaotic_fraction(out)
    frequency_map(out)


if __name__ == "__main__":
    main()
