"""Figures of a Result with matplotlib (imported here, not by `import nonsep`). Each function draws into `ax` (a new
figure's axes when None) and returns the axes, labelled with the quantities and with a legend when it shows more
than one series (and at most MAX_LEGEND; an ensemble's hundred lines get none). Choose the backend before importing
pyplot, e.g. matplotlib.use("Agg") for files only.
"""
import numpy as np

MAX_LEGEND = 12


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt
        _, ax = plt.subplots()
    return ax


def _indices(result, index):
    if index is None:
        return [int(i) for i in np.unique(result.samples()["trajectory"])]
    return [int(index)] if np.isscalar(index) else [int(i) for i in index]


def _label(result, i):
    orbit = result.orbit(i)
    start = ", ".join(f"{v:g}" for v in (*orbit.q[0], *orbit.p[0]))
    return f"trajectory {i}: (q, p)(0) = ({start})"


def orbit(result, i=None, ax=None, **style):
    """Trajectory `i` (an index, a list of indices, or None for all) from trajectory.csv: p against q for a model of
    dimension 1 (the phase plane), q1 against q0 otherwise (the configuration plane, the paper's Figure 2). Axis
    labels name the columns of trajectory.csv, whose components are numbered from 0.
    `style` goes to ax.plot (default: small stars, the paper's Figure 1)."""
    ax = _axes(ax)
    style = {"marker": "*", "linestyle": "none", "markersize": 2.5, **style}
    indices = _indices(result, i)
    for index in indices:
        o = result.orbit(index)
        x, y = (o.q[:, 0], o.p[:, 0]) if o.q.shape[1] == 1 else (o.q[:, 0], o.q[:, 1])
        ax.plot(x, y, label=_label(result, index), **style)
    one_dimensional = result.orbit(indices[0]).q.shape[1] == 1
    ax.set_xlabel("$q$" if one_dimensional else "$q_0$")
    ax.set_ylabel("$p$" if one_dimensional else "$q_1$")
    ax.set_aspect("equal", adjustable="datalim")
    if 1 < len(indices) <= MAX_LEGEND:
        ax.legend(fontsize="small")
    return ax


def energy_error(result, ax=None, i=None, **style):
    """The relative energy error (H - H0) / H0 of the sampled steps against t, one line per trajectory (`i`: an
    index, a list, or None for all)."""
    ax = _axes(ax)
    indices = _indices(result, i)
    for index in indices:
        o = result.orbit(index)
        ax.plot(o.t, o.relative_energy_error, label=_label(result, index), **style)
    ax.set_xlabel("$t$")
    ax.set_ylabel("relative energy error $(H - H_0) / H_0$")
    ax.axhline(0.0, color="0.6", linewidth=0.5)
    if 1 < len(indices) <= MAX_LEGEND:
        ax.legend(fontsize="small")
    return ax


def convergence(result, ax=None):
    """A study's |relative energy error| at t_end against |dt| on log-log axes, one series per integrator
    (circles symplectic, open squares not), with the fitted line c dt^n of summary.json's "fits" over the fitted
    range. Raises ValueError when the result is not a study."""
    if result.convergence is None:
        raise ValueError(f"{result.directory} holds no convergence.csv: not a study")
    ax = _axes(ax)
    table = result.convergence
    fits = {fit["integrator"]: fit for fit in result.fits}
    for name in dict.fromkeys(table["integrator"]):  # in file order
        rows = table[(table["integrator"] == name) & (table["status"] == "completed")]
        rows = rows[np.isfinite(rows["relative_energy_error"])]
        symplectic = bool(rows["symplectic"][0]) if len(rows) else True
        line, = ax.loglog(np.abs(rows["dt"]), np.abs(rows["relative_energy_error"]), "o" if symplectic else "s",
                          markerfacecolor=None if symplectic else "none", markersize=4)
        fit = fits.get(name, {})
        label = name
        if fit.get("exponent") is not None:
            dt = np.array([fit["dt_min"], fit["dt_max"]], dtype=float)
            c, n = fit["constant"], fit["exponent"]
            ax.loglog(dt, np.abs(c) * dt ** n, "-", color=line.get_color(), linewidth=0.8)
            label = f"{name}: ${c:.3g}\\,dt^{{{n:.3f}}}$"
        line.set_label(label)
    ax.set_xlabel("step size $dt$")
    ax.set_ylabel("|relative energy error| at $t_\\mathrm{end}$")
    ax.legend(fontsize="small")
    return ax
