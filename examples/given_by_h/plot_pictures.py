"""Render the pictures of the models given by H(q, p) from the outputs run_pictures.sh wrote, with nonsep.load and
nonsep.plot (python/nonsep, found from this file when not on PYTHONPATH).

    /usr/bin/python3 examples/given_by_h/plot_pictures.py OUT_DIR

OUT_DIR holds henon_heiles_portrait/, schwarzschild_section/ (poincare.csv: the crossings; trajectories.csv: each
orbit's MEGNO <Y>, which colours its points) and magnetic_bottle_chaos_map/ (trajectory.csv: each orbit's first
state, its place on the map; trajectories.csv: its <Y>). Writes given_by_h_henon_heiles, given_by_h_schwarzschild and
given_by_h_magnetic_bottle into OUT_DIR as PNG (150 dots per inch).
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

try:
    import nonsep.plot
except ImportError:  # run from the source tree without PYTHONPATH=python
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
    import nonsep.plot

DPI = 150
# MEGNO <Y>: 2 for quasi-periodic orbits (blue), growing for chaotic ones (red); 8 and above drawn alike.
MEGNO = {"cmap": "coolwarm", "vmin": 1.0, "vmax": 8.0}


def subtitle(summary):
    integrator = summary["integrator"]
    return (f"{integrator['scheme']} of order {integrator['order']}, dt = {summary['time']['dt']:g}, "
            f"t = {summary['time']['t_end']:g}")


def portrait(out, name, x, y, title, xlabel, ylabel, size):
    result = nonsep.load(out / name)
    if result.poincare is None or len(result.poincare) == 0:
        raise SystemExit(f"{result.directory / 'poincare.csv'} has no crossings")
    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    nonsep.plot.poincare(result, ax=ax, x=x, y=y, color_by="mean_megno", colorbar=False, s=size, **MEGNO)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(f"{title}, {len(result.trajectories)} orbits\n{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.collections[0], ax=ax).set_label("orbit's MEGNO <Y> (2: regular)")
    return fig


def save(fig, out, name):
    fig.savefig(out / f"{name}.png", dpi=DPI, bbox_inches="tight")
    plt.close(fig)


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = Path(sys.argv[1])
    save(portrait(out, "henon_heiles_portrait", "q1", "p1", "Hénon-Heiles as one H, section q0 = 0 at H = 1/8",
                  "q1 (y)", "p1 (p_y)", 0.5), out, "given_by_h_henon_heiles")
    save(portrait(out, "schwarzschild_section", "q1", "p1",
                  "Charged particle, Schwarzschild + uniform field: section θ = π/2",
                  "q1 (r)", "p1 (p_r)", 2.0), out, "given_by_h_schwarzschild")
    result = nonsep.load(out / "magnetic_bottle_chaos_map")
    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    nonsep.plot.chaos_map(result, ax=ax, value="mean_megno", x="q0", y="p1", colorbar=False, **MEGNO)
    ax.set_xlabel("q0 (x at start; y = z = 0)")
    ax.set_ylabel("p1 (p_y at start; p_x = 0, p_z = 0.5)")
    ax.set_title(f"Magnetic bottle: MEGNO <Y> of {len(result.trajectories)} orbits\n"
                 f"{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.images[0], ax=ax).set_label("<Y> (2: regular)")
    save(fig, out, "given_by_h_magnetic_bottle")


if __name__ == "__main__":
    main()
