"""Render the pictures of the models given by H(q, p) from the outputs run_pictures.sh wrote, with nonsep.load and
nonsep.plot (python/nonsep, found from this file when not on PYTHONPATH).

    /usr/bin/python3 examples/given_by_h/plot_pictures.py OUT_DIR

OUT_DIR holds henon_heiles_portrait/, schwarzschild_section/, schwarzschild_stability_map/ (a sweep of beta),
magnetic_bottle_section/ (poincare.csv: the crossings;
trajectories.csv: each orbit's MEGNO <Y>, which colours its points) and magnetic_bottle_chaos_map/ (trajectory.csv:
each orbit's first state, its place on the map; trajectories.csv: its <Y>; the Henon-Heiles run makes a map of its
starting grid too). Writes given_by_h_henon_heiles, given_by_h_henon_heiles_map, given_by_h_schwarzschild,
given_by_h_schwarzschild_map, given_by_h_magnetic_bottle and given_by_h_magnetic_bottle_section into OUT_DIR as PNG (150 dots per inch).
"""
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

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


def grid_map(out, name, draw, x, y, title, xlabel, ylabel, picture):
    """Each orbit's MEGNO <Y> at its starting point (draw: nonsep.plot.chaos_map or stability_map); {n} in the title
    is the number of orbits."""
    result = nonsep.load(out / name)
    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    draw(result, ax=ax, value="mean_megno", x=x, y=y, colorbar=False, **MEGNO)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(f"{title.format(n=len(result.trajectories))}\n{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(ax.images[0], ax=ax).set_label("<Y> (2: regular)")
    save(fig, out, picture)


def bottle_section(out):
    """The magnetic bottle's crossings of z = 0 in the cylindrical radius and its momentum, (rho, p_rho)."""
    result = nonsep.load(out / "magnetic_bottle_section")
    crossings = result.poincare
    if crossings is None or len(crossings) == 0:
        raise SystemExit(f"{result.directory / 'poincare.csv'} has no crossings")
    x, y, px, py = (np.asarray(crossings[c], dtype=float) for c in ("q0", "q1", "p0", "p1"))
    rho = np.hypot(x, y)
    megno = dict(zip(result.trajectories["trajectory"], result.trajectories["mean_megno"]))
    colour = [megno[t] for t in crossings["trajectory"]]
    fig, ax = plt.subplots(figsize=(6.4, 5.4))
    points = ax.scatter(rho, (x * px + y * py) / rho, c=colour, s=0.8, linewidths=0, **MEGNO)
    ax.set_xlabel("rho = |(x, y)| at z = 0")
    ax.set_ylabel("p_rho = (x p_x + y p_y)/rho")
    ax.set_title(f"Magnetic bottle, section z = 0 at H = 0.5, x p_y - y p_x = 0.5: {len(result.trajectories)} orbits\n"
                 f"{subtitle(result.summary)}", fontsize=10)
    fig.colorbar(points, ax=ax).set_label("orbit's MEGNO <Y> (2: regular)")
    save(fig, out, "given_by_h_magnetic_bottle_section")


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__)
    out = Path(sys.argv[1])
    save(portrait(out, "henon_heiles_portrait", "q1", "p1", "Hénon-Heiles as one H, section q0 = 0 at H = 1/8",
                  "q1 (y)", "p1 (p_y)", 0.5), out, "given_by_h_henon_heiles")
    save(portrait(out, "schwarzschild_section", "q1", "p1",
                  "Charged particle, Schwarzschild + uniform field: section θ = π/2",
                  "q1 (r)", "p1 (p_r)", 2.0), out, "given_by_h_schwarzschild")
    grid_map(out, "henon_heiles_portrait", nonsep.plot.chaos_map, "q1", "p1",
             "Hénon-Heiles as one H: MEGNO <Y> of {n} orbits at H = 1/8 (grey: off the shell)",
             "q1 (y at start; x = 0)", "p1 (p_y at start; p_x >= 0 on the shell)", "given_by_h_henon_heiles_map")
    bottle_section(out)
    grid_map(out, "schwarzschild_stability_map", nonsep.plot.stability_map, "beta", "q1",
             "Charged particle, Schwarzschild + uniform field: MEGNO <Y> of {n} orbits (grey: off the shell)",
             "beta (field strength)", "q1 (r at start; theta = pi/2, p_r = 0)", "given_by_h_schwarzschild_map")
    grid_map(out, "magnetic_bottle_chaos_map", nonsep.plot.chaos_map, "q0", "p1", "Magnetic bottle: MEGNO <Y> of {n} orbits",
             "q0 (x at start; y = z = 0)", "p1 (p_y at start; p_x = 0, p_z = 0.5)", "given_by_h_magnetic_bottle")


if __name__ == "__main__":
    main()
