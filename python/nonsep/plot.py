"""Figures of a Result with matplotlib (imported here, not by `import nonsep`): orbit, energy_error, convergence,
and for the dynamics outputs poincare (the crossings of poincare.csv), chaos_map (an indicator such as MEGNO, a
Lyapunov exponent, SALI or GALI over the grid of initial conditions), stability_map (the same over a parameter
sweep's plane), chaotic_fraction (the fraction of orbits past an indicator's threshold against a swept parameter,
with binomial error bars) and indicator_series (the running estimates of lyapunov.csv against t). Each function
draws into `ax` (a new figure's axes when None) and returns the axes, labelled with the quantities and with a
legend when it shows more than one series (and at most MAX_LEGEND; an ensemble's hundred lines get none).

The dynamics helpers share their arguments: `value` names the indicator (a column of trajectories.csv), `where`
chooses trajectories by the values of swept parameters (Result.select, e.g. where={"coupling": 0.1}), `reduce`
combines the values of trajectories that share a cell of a map; their titles say what is drawn and of which run
(describe_run), and their colours follow the indicator's scale (colour_scale). Choose the backend before importing
pyplot, e.g. matplotlib.use("Agg") for files only.
"""
from typing import NamedTuple

import numpy as np

from .results import CHAOS_THRESHOLDS

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


def _math(name):
    """A column name of the files (components numbered from 0) as mathtext: q0 -> $q_0$, p12 -> $p_{12}$."""
    letter, index = name[0], name[1:]
    if not index.isdigit():
        return name
    return f"${letter}_{index}$" if len(index) == 1 else f"${letter}_{{{index}}}$"


def _component_names(dimension):
    return [f"q{k}" for k in range(dimension)] + [f"p{k}" for k in range(dimension)]


def _section_axes(section, dimension):
    """The default (x, y) of a section plot: q and p of the first degree of freedom the plane's normal leaves out
    (for the plane q1 = 0 of a 2D model: q0 and p0), else q0 and p0."""
    normal = (section or {}).get("normal")
    if normal is not None and len(normal) == 2 * dimension:
        for k in range(dimension):
            if normal[k] == 0 and normal[dimension + k] == 0:
                return f"q{k}", f"p{k}"
    return "q0", "p0"


def _section_title(section, dimension):
    if not section:
        return "Poincaré section"
    names = _component_names(dimension)
    normal, value = section.get("normal") or [], section.get("value", 0.0)
    nonzero = [k for k, c in enumerate(normal) if c != 0]
    if len(nonzero) == 1 and len(normal) == len(names):
        plane = f"{_math(names[nonzero[0]])} = {value / normal[nonzero[0]]:g}"
    else:
        plane = f"$n \\cdot (q, p) = {value:g}$"
    direction = {"+": ", upward crossings", "-": ", downward crossings"}.get(section.get("direction"), "")
    return f"Poincaré section {plane}{direction}"


def poincare(result, ax=None, x=None, y=None, i=None, color_by=None, cmap=None, colorbar=True, where=None, **style):
    """The crossings of poincare.csv as points, x against y (column names such as "q0", "p0"; default: q and p of
    the first degree of freedom the section's plane leaves out, e.g. q0 and p0 for the plane q1 = 0 of a 2D model).
    `i`: a trajectory index, a list, or None for all; `where` keeps those of some swept parameters' values
    (Result.select, e.g. {"coupling": 0.1}). Points are coloured per trajectory (a qualitative colour map over
    trajectory indices, `cmap` default "tab20"), or with `color_by` a column of trajectories.csv such as
    "mean_megno" by that trajectory's value, on that indicator's colour scale (colour_scale; vmin, vmax or norm in
    `style` override it), with a labelled colour bar when `colorbar`. One scatter call whatever the number of
    points; `style` goes to ax.scatter (default: dots of size 2, rasterized). The title names the plane and the run
    (describe_run). Raises ValueError when the run wrote no poincare.csv."""
    table = result.poincare
    if table is None:
        raise ValueError(f"{result.directory} holds no poincare.csv: the job had no analysis.poincare")
    dimension = sum(1 for name in table.dtype.names if name[0] == "q" and name[1:].isdigit())
    section = result.section
    default_x, default_y = _section_axes(section, dimension)
    x, y = x or default_x, y or default_y
    for name in (x, y):
        if name not in table.dtype.names:
            raise ValueError(f"poincare.csv has no column {name!r}; it has {', '.join(table.dtype.names)}")
    chosen = result.select(where)
    if i is not None:
        chosen = np.intersect1d(chosen, [int(i)] if np.isscalar(i) else [int(k) for k in i])
    table = table[np.isin(table["trajectory"], chosen)]
    ax = _axes(ax)
    style = {"s": 2.0, "linewidths": 0, "rasterized": True, **style}
    trajectory = table["trajectory"]
    if color_by is None:
        colours = _colour_map(cmap, "tab20")
        ax.scatter(table[x], table[y], c=colours(trajectory % colours.N), **style)
    else:
        values = _per_trajectory(result, color_by)[trajectory]
        norm, colours, marks = _colours(color_by, cmap, style)
        points = ax.scatter(table[x], table[y], c=_shown(values, norm), cmap=colours, norm=norm, **style)
        if colorbar:
            _colour_bar(ax, points, color_by, values, marks)
    ax.set_xlabel(_math(x))
    ax.set_ylabel(_math(y))
    ax.set_title(f"{_section_title(section, dimension)}\n{describe_run(result, where)}", fontsize="medium")
    return ax


def _per_trajectory(result, column):
    table = result.trajectories
    if table is None or column not in table.dtype.names:
        names = ", ".join(table.dtype.names) if table is not None else "none"
        raise ValueError(f"trajectories.csv has no column {column!r} (its columns: {names})")
    if not np.array_equal(table["trajectory"], np.arange(len(table))):
        raise ValueError("trajectories.csv does not list the trajectories 0, 1, ... in order")
    return np.asarray(table[column], dtype=float)


def _indicator_name(column):
    """A column of trajectories.csv as a short name for titles: "MEGNO <Y>", "SALI", "GALI_3", ..."""
    if column == "mean_megno":
        return "MEGNO $\\langle Y \\rangle$"
    if column == "megno":
        return "MEGNO $Y$"
    if column.startswith("lyapunov") and column[8:].isdigit():
        return f"Lyapunov exponent $\\lambda_{{{column[8:]}}}$"
    if column == "sali":
        return "SALI"
    if column.startswith("gali") and column[4:].isdigit():
        return f"GALI$_{{{column[4:]}}}$"
    if column == "diffusion":
        return "diffusion index"
    frequency = _frequency_symbol(column)
    return f"frequency {frequency}" if frequency else column


def _frequency_symbol(column):
    """"frequency1" -> "$\\nu_1$", "frequency1_first" -> "$\\nu_1$ (first half)"; None for other columns."""
    if not column.startswith("frequency"):
        return None
    degree, _, part = column[len("frequency"):].partition("_")
    if not degree.isdigit() or part not in ("", "first", "second"):
        return None
    return f"$\\nu_{{{degree}}}$" + (f" ({part} half)" if part else "")


def _value_label(column):
    if column == "mean_megno":
        return "MEGNO $\\langle Y \\rangle$ (2: quasi-periodic)"
    if column == "megno":
        return "MEGNO $Y$"
    if column.startswith("lyapunov") and column[8:].isdigit():
        return f"finite-time Lyapunov exponent $\\lambda_{{{column[8:]}}}$ ({column})"
    if column == "sali":
        return "SALI (-> 0: chaotic)"
    if column.startswith("gali") and column[4:].isdigit():
        return f"GALI$_{{{column[4:]}}}$"
    if column == "diffusion":
        return "diffusion index $\\log_{10} |\\nu_2 - \\nu_1| / |\\nu|$ (small: a torus)"
    frequency = _frequency_symbol(column)
    return f"{frequency}, rad per unit time" if frequency else column


def _grid_axes(columns, count):
    """The two columns of the initial states that index them as a 2D grid: of the columns that vary, the pair whose
    values tell every state apart with the fewest distinct values (on an energy shell the solved momentum varies
    too, with as many values as states)."""
    distinct = {name: len(np.unique(values)) for name, values in columns.items()}
    varying = [name for name in columns if distinct[name] > 1]
    best = None
    for a_index, a in enumerate(varying):
        for b in varying[a_index + 1:]:
            cells = distinct[a] * distinct[b]
            if best is not None and cells >= best[0]:
                continue
            pairs = np.unique(np.column_stack([columns[a], columns[b]]), axis=0)
            if len(pairs) == count:
                best = (cells, a, b)
    if best is None:
        raise ValueError("the initial states are not a grid over two of their components; give x and y")
    return best[1], best[2]


def chaos_map(result, ax=None, value="mean_megno", x=None, y=None, cmap=None, colorbar=True, where=None, reduce=None,
              **style):
    """An image of `value` (a column of trajectories.csv: "mean_megno", the default, "lyapunov0", "sali", ...) over
    the grid of initial conditions, one cell per trajectory at its initial (x, y) (column names such as "q0", "p0").
    The initial states come from trajectory.csv's step-0 rows; x and y default to the two components that tell the
    states apart as a grid (see _grid_axes): for a grid over q0 and p0 on an energy shell, q0 and p0. In a parameter
    sweep every parameter set starts from the same grid: choose one set with `where` (Result.select, e.g.
    {"coupling": 0.1}), or combine the sets' values in each cell with `reduce` ("mean", "median", "max", "min" or a
    function of an array); without either that is an error. Cells without a trajectory (states left off the shell)
    or without a value (diverged or failed) are grey. Colours follow the indicator's scale (colour_scale: MEGNO
    from 1.25 to 8 with 2 marked on the colour bar, SALI and GALI on log scales); vmin, vmax or norm in `style`
    override it. A uniform grid is drawn with ax.imshow, another with ax.pcolormesh; `style` goes there. The title
    says what is drawn and of which run (describe_run). Returns the axes, with a labelled colour bar when
    `colorbar`."""
    chosen = result.select(where)
    values = _per_trajectory(result, value)[chosen]
    columns = {name: column[chosen] for name, column in _initial_columns(result).items()}
    if x is None or y is None:
        sets = np.column_stack([result.trajectories[name][chosen] for name in result.swept]) if result.swept \
            else np.zeros((len(chosen), 1))
        first_set = np.all(sets == sets[:1], axis=1)  # the grid is found on one set's states
        if not first_set.all() and reduce is None:
            raise ValueError(_shared_cells_message("the initial states", result, where))
        x, y = _grid_axes({name: column[first_set] for name, column in columns.items()}, int(first_set.sum()))
    ax = _axes(ax)
    _grid_image(ax, columns, x, y, values, value, reduce, cmap, colorbar, style, result, where)
    return ax


def stability_map(result, ax=None, value="mean_megno", x=None, y=None, reduce=None, cmap=None, colorbar=True,
                  where=None, **style):
    """An image of `value` (a column of trajectories.csv) over a plane of a parameter sweep: a swept parameter
    against an initial-condition component ("coupling" x "q0"), or two swept parameters against each other. x and
    y name swept parameters (summary.json's sweep, columns of trajectories.csv) or components of the initial state
    (step-0 rows of trajectory.csv, as in chaos_map); they default to the two swept parameters that vary among the
    trajectories chosen by `where` (Result.select: fix the others there, e.g. {"alpha": 1.0}), or to the one that
    varies and the initial component that, with it, tells the trajectories apart with the fewest cells. When
    several trajectories fall in one cell (a parameter x parameter plane over several initial states) `reduce`
    combines them ("mean", "median", "max", "min" or a function of an array); without it that is an error. Colours,
    grey cells, `style` and the title as in chaos_map. Returns the axes."""
    swept = result.swept
    if not swept:
        raise ValueError(f"{result.directory} is not a parameter sweep (summary.json has no \"sweep\"): use chaos_map")
    chosen = result.select(where)
    values = _per_trajectory(result, value)[chosen]
    columns = {name: _per_trajectory(result, name)[chosen] for name in swept}
    varying = [name for name in swept if len(np.unique(columns[name])) > 1] or swept[:1]
    needs_states = any(name not in columns for name in (x, y) if name is not None) or \
        ((x is None or y is None) and len(varying) == 1)
    if needs_states:
        columns.update({name: column[chosen] for name, column in _initial_columns(result).items()})
    if x is None or y is None:
        if len(varying) >= 2:
            x, y = varying[0], varying[1]
        else:
            others = {name: c for name, c in columns.items() if name not in swept}
            y = min(others, key=lambda name: _cells(columns[varying[0]], others[name], len(values)))
            x = varying[0]
    for name in (x, y):
        if name not in columns:
            raise ValueError(f"no parameter or initial component {name!r} (choose from {', '.join(columns)})")
    ax = _axes(ax)
    _grid_image(ax, columns, x, y, values, value, reduce, cmap, colorbar, style, result, where)
    return ax


def chaotic_fraction(result, x=None, value="mean_megno", threshold=None, where=None, z=1.0, ax=None, **style):
    """The fraction of chaotic orbits against a swept parameter `x` (default: the one swept parameter), with error
    bars: Result.chaotic_fraction's counts (the completed orbits whose `value` is past `threshold`: by default
    mean_megno > 2.5, sali < 1e-8; see CHAOS_THRESHOLDS) and their Wilson score intervals of z standard deviations,
    the sampling error of a fraction of a finite number of orbits. `where` chooses the trajectories (Result.select),
    and fixes any other swept parameter. `style` goes to ax.errorbar (default: dots joined by a line). The title
    says the criterion and the run, and how many orbits were left out (not completed, or without a value) when any
    were. Returns the axes; the numbers are result.chaotic_fraction(x, value, threshold, where, z)."""
    counts = result.chaotic_fraction(x, value, threshold, where, z)
    ax = _axes(ax)
    style = {"marker": "o", "markersize": 4, "capsize": 3, "linewidth": 1, **style}
    ax.errorbar(counts.values, counts.fraction,
                yerr=np.vstack([counts.fraction - counts.lower, counts.upper - counts.fraction]), **style)
    criterion = _criterion_text(counts.criterion, value)
    ax.set_xlabel(_axis_label(counts.parameter))
    ax.set_ylabel(f"fraction of orbits with {criterion}")
    ax.set_ylim(-0.02, 1.02)
    left_out = int(counts.left_out.sum())
    note = f"; {left_out} left out (not completed, or no value)" if left_out else ""
    ax.set_title(f"Chaotic fraction: {criterion} at t = {_end_time(result):g}\n{int(counts.orbits.sum())} orbits, "
                 f"bars: Wilson interval of {z:g} sigma{note}\n{describe_run(result, where)}", fontsize="medium")
    return ax


def frequency_map(result, ax=None, x=None, y=None, value="diffusion", where=None, cmap=None, colorbar=True,
                  **style):
    """Laskar's frequency map: each analysed trajectory as a point at its fundamental frequencies (x, y: columns of
    trajectories.csv from /analysis/frequencies, by default the whole run's frequencies of the first two signals the
    run analysed, "frequency0" and "frequency1" for a 2D model), coloured by `value`
    (the diffusion index by default: blue where the frequencies stay put between the halves of the run, a torus; red
    where they drift, a chaotic zone). On a family of tori the points lie on smooth curves; resonances show as lines
    the points gather on, chaotic zones as scattered red points. Trajectories without an analysis (not completed)
    are left out, and counted in the title. `where` chooses trajectories (Result.select); `style` goes to
    ax.scatter. Returns the axes."""
    if x is None or y is None:
        facts = (result.summary.get("analysis") or {}).get("frequencies")
        if facts is None:
            raise ValueError(f"{result.directory} has no frequency map (the run had no analysis.frequencies)")
        signals = facts["signals"]
        if len(signals) < 2:
            raise ValueError(f"the run analysed one signal (frequency{signals[0]}): give x and y, e.g. "
                             f"x=\"frequency{signals[0]}_first\", y=\"frequency{signals[0]}_second\"")
        x = x or f"frequency{signals[0]}"
        y = y or f"frequency{signals[1]}"
    chosen = result.select(where)
    xs, ys = (_per_trajectory(result, name)[chosen] for name in (x, y))
    values = _per_trajectory(result, value)[chosen]
    shown = np.isfinite(xs) & np.isfinite(ys) & np.isfinite(values)
    ax = _axes(ax)
    norm, colours, marks = _colours(value, cmap, style)
    style = {"s": 6, "linewidths": 0, **style}
    points = ax.scatter(xs[shown], ys[shown], c=_shown(values[shown], norm), cmap=colours, norm=norm, **style)
    if colorbar:
        _colour_bar(ax, points, value, values[shown], marks)
    ax.set_xlabel(_value_label(x))
    ax.set_ylabel(_value_label(y))
    left_out = int((~shown).sum())
    note = f", {left_out} without an analysis left out" if left_out else ""
    ax.set_title(f"Frequency map: {_indicator_name(y)} against {_indicator_name(x)}, {int(shown.sum())} orbits"
                 f"{note}\n{describe_run(result, where)}", fontsize="medium")
    return ax


def indicator_series(result, i=None, value="mean_megno", ax=None, where=None, **style):
    """The running estimate `value` of lyapunov.csv ("mean_megno", the default, "megno", "lyapunov0", ...) against t,
    one line per trajectory (`i`: an index, a list, or None for all in the file; `where` keeps those of some swept
    parameters' values, Result.select), labelled with the trajectory and, in a parameter sweep, its swept
    parameters; SALI and GALI on a logarithmic axis, with the marks of their colour scale (colour_scale: 2 for
    MEGNO) as dashed lines. Needs analysis.lyapunov.every > 0. Returns the axes."""
    table = result.lyapunov
    if table is None:
        raise FileNotFoundError(f"{result.directory} holds no lyapunov.csv: run with analysis.lyapunov.every > 0")
    if value not in table.dtype.names:
        raise ValueError(f"lyapunov.csv has no column {value!r} (its columns: {', '.join(table.dtype.names)})")
    indices = [int(k) for k in np.unique(table["trajectory"])] if i is None else \
        ([int(i)] if np.isscalar(i) else [int(k) for k in i])
    chosen = set(result.select(where).tolist())
    indices = [k for k in indices if k in chosen]
    ax = _axes(ax)
    for index in indices:
        rows = result._rows_of("lyapunov", index)
        label = f"trajectory {index}" + "".join(
            f", {name} = {result.trajectories[name][index]:g}" for name in result.swept)
        ax.plot(rows["t"], rows[value], label=label, **style)
    ax.set_xlabel("$t$")
    ax.set_ylabel(_value_label(value))
    scale = colour_scale(value)
    if scale.log:
        ax.set_yscale("log")
    for mark, _ in scale.marks:
        ax.axhline(mark, color="0.5", linewidth=0.8, linestyle="--")
    ax.set_title(f"{_indicator_name(value)} against $t$\n{describe_run(result, where)}", fontsize="medium")
    if 1 < len(indices) <= MAX_LEGEND:
        ax.legend(fontsize="small")
    return ax


def _axis_label(name):
    """q0 -> "$q_0$ (initial)"; a parameter's name as it is."""
    return f"{_math(name)} (initial)" if name[:1] in "qp" and name[1:].isdigit() else name


def _initial_columns(result):
    q, p = result.initial_states()
    return dict(zip(_component_names(q.shape[1]), np.column_stack([q, p]).T))


def _cells(a, b, count):
    """The cells of the plane (a, b), or infinity when two trajectories share one."""
    pairs = np.unique(np.column_stack([a, b]), axis=0)
    return len(np.unique(a)) * len(np.unique(b)) if len(pairs) == count else np.inf


REDUCTIONS = {"mean": np.mean, "median": np.median, "max": np.max, "min": np.min}


def _shared_cells_message(what, result, where):
    """Why a plane cannot be drawn without `reduce`, and, in a sweep, which parameters to fix with `where`."""
    free = [name for name in result.swept if name not in (where or {})]
    if not free:
        return f"several trajectories share a cell: {what} are not a grid; give x and y, or reduce"
    return (f"several trajectories share a cell: {what} repeat across the parameter sets ({', '.join(free)}); "
            f"choose one set with where={{{free[0]!r}: value}} or combine them with reduce=\"mean\" (or \"median\", "
            "\"max\", \"min\", a function of an array)")


def _grid_image(ax, columns, x, y, values, value, reduce, cmap, colorbar, style, result, where):
    """`values` as an image over the distinct values of columns[x] and columns[y], coloured on the indicator's
    scale, with its title; see chaos_map."""
    xs, column_of = np.unique(columns[x], return_inverse=True)
    ys, row_of = np.unique(columns[y], return_inverse=True)
    grid = np.full((len(ys), len(xs)), np.nan)
    counts = np.zeros(grid.shape, dtype=int)
    np.add.at(counts, (row_of, column_of), 1)
    shared = counts.max(initial=0) > 1
    if shared and reduce is None:
        raise ValueError(f"several trajectories start at the same ({x}, {y}): not a grid over them. "
                         + _shared_cells_message(f"the ({x}, {y}) pairs", result, where))
    if shared:
        if isinstance(reduce, str) and reduce not in REDUCTIONS:
            raise ValueError(f"reduce: unknown reduction {reduce!r} (choose from {', '.join(REDUCTIONS)}, or give "
                             "a function of an array)")
        combine = REDUCTIONS[reduce] if isinstance(reduce, str) else reduce
        cell = row_of * len(xs) + column_of
        for c in np.unique(cell):
            mine = values[cell == c]
            mine = mine[np.isfinite(mine)]
            grid.flat[c] = combine(mine) if len(mine) else np.nan
    else:
        grid[row_of, column_of] = values
    norm, colours, marks = _colours(value, cmap, style)
    shown = np.ma.masked_invalid(_shown(grid, norm))
    if _uniform(xs) and _uniform(ys):
        half_x = (xs[-1] - xs[0]) / (len(xs) - 1) / 2 if len(xs) > 1 else 0.5
        half_y = (ys[-1] - ys[0]) / (len(ys) - 1) / 2 if len(ys) > 1 else 0.5
        style = {"interpolation": "nearest", "aspect": "auto", **style}
        image = ax.imshow(shown, origin="lower", cmap=colours, norm=norm,
                          extent=(xs[0] - half_x, xs[-1] + half_x, ys[0] - half_y, ys[-1] + half_y), **style)
    else:
        image = ax.pcolormesh(_edges(xs), _edges(ys), shown, cmap=colours, norm=norm, **style)
    ax.set_xlabel(_axis_label(x))
    ax.set_ylabel(_axis_label(y))
    combined = f", {reduce if isinstance(reduce, str) else 'reduced'} per cell" if shared else ""
    grey = " (grey: no orbit or no value)" if np.isnan(grid).any() else ""
    ax.set_title(f"{_indicator_name(value)} at t = {_end_time(result):g} of {int(np.isfinite(values).sum())} orbits"
                 f"{combined}{grey}\n{describe_run(result, where)}", fontsize="medium")
    if colorbar:
        _colour_bar(ax, image, value, grid, marks)
    return image


class ColourScale(NamedTuple):
    """An indicator's default colours: a colour map (a matplotlib name, or "chaos" / "chaos_r": blue for regular
    to red for chaotic, and reversed), the range drawn (None: the data's), whether logarithmic, and values marked
    on the colour bar as (value, text)."""
    cmap: str
    vmin: object
    vmax: object
    log: bool
    marks: tuple


MEGNO_RANGE = (1.25, 8.0)  # <Y> from just below 2 (regular) to 8 (clearly chaotic); beyond, the end colours
ALIGNMENT_RANGE = (1e-16, 1.0)  # SALI and GALI: from round-off to unaligned, logarithmic
DIFFUSION_RANGE = (-10.0, 0.0)  # the diffusion index: from a torus's frequencies kept to 1e-10 to a drift of order 1


def colour_scale(value):
    """The default ColourScale of a column of trajectories.csv: MEGNO (mean_megno, megno) from 1.25 to 8, blue to
    red, 2 (regular) marked; SALI and GALI_k on a log scale from 1e-16 to 1, red (small: chaotic) to blue, with
    the chaos threshold marked where there is a default one (CHAOS_THRESHOLDS: SALI and GALI_2, 1e-8); Lyapunov
    exponents from 0 to the data's largest; the diffusion index from -10 to 0; anything else viridis over the data's
    range."""
    threshold = CHAOS_THRESHOLDS.get(value)
    if value in ("mean_megno", "megno"):
        return ColourScale("chaos", *MEGNO_RANGE, False, ((2.0, "regular"),))
    if value == "sali" or (value.startswith("gali") and value[4:].isdigit()):
        return ColourScale("chaos_r", *ALIGNMENT_RANGE, True, ((threshold[1], "chaotic below"),) if threshold else ())
    if value.startswith("lyapunov") and value[8:].isdigit():
        return ColourScale("chaos", 0.0, None, False, ())
    if value == "diffusion":
        return ColourScale("chaos", *DIFFUSION_RANGE, False, ())
    return ColourScale("viridis", None, None, False, ())


def _colours(value, cmap, style):
    """(norm, colour map with grey for missing values, marks) of `value`'s scale; vmin, vmax and norm are taken out
    of `style` and override the scale's."""
    from matplotlib.colors import LogNorm, Normalize
    scale = colour_scale(value)
    norm = style.pop("norm", None)
    vmin, vmax = style.pop("vmin", scale.vmin), style.pop("vmax", scale.vmax)
    if norm is None:
        norm = LogNorm(vmin, vmax) if scale.log else Normalize(vmin, vmax)
    colours = _colour_map(cmap, scale.cmap).copy()
    colours.set_bad("#d9d9d9")
    return norm, colours, scale.marks


def _shown(values, norm):
    """The values as drawn: on a log scale 0 (an index below the smallest double) as the smallest positive double,
    which the colour bar's lower end shows, not as a missing value."""
    from matplotlib.colors import LogNorm
    values = np.asarray(values, dtype=float)
    if not isinstance(norm, LogNorm):
        return values
    return np.where(np.isfinite(values) & (values <= 0), np.nextafter(0.0, 1.0), values)


def _colour_bar(ax, mappable, value, values, marks):
    """A colour bar labelled with the quantity, with triangles at the ends the data pass and lines at the marks."""
    norm = mappable.norm
    finite = np.asarray(values, dtype=float)
    finite = finite[np.isfinite(finite)]
    below = norm.vmin is not None and bool((finite < norm.vmin).any())
    above = norm.vmax is not None and bool((finite > norm.vmax).any())
    extend = {(True, True): "both", (True, False): "min", (False, True): "max"}.get((below, above), "neither")
    bar = ax.figure.colorbar(mappable, ax=ax, extend=extend)
    label = _value_label(value)
    for mark, text in marks:
        bar.ax.axhline(mark, color="black", linewidth=1.2)
        if f"{mark:g}:" not in label:
            label += f" (line: {mark:g}, {text})"
    bar.set_label(label)
    return bar


def _criterion_text(criterion, value):
    _, direction, limit = criterion.split(" ")
    return f"{_indicator_name(value)} {direction} {limit}"


def _end_time(result):
    return (result.summary.get("time") or {}).get("t_end", float("nan"))


def describe_run(result, where=None):
    """One line saying which run a picture shows, from summary.json: the model with its fixed parameters, the
    energy shell, the values chosen by `where`, the scheme, dt and t_end; e.g.
    "paper2d, H = 8, coupling = 0.1; gauss order 6, dt = 0.02, t = 100"."""
    summary = result.summary
    model = summary.get("model") or {}
    parts = [model.get("plugin", "model")]
    for name, given in (model.get("parameters") or {}).items():
        if name not in result.swept and isinstance(given, (int, float)) and not isinstance(given, bool):
            parts.append(f"{name} = {given:g}")
    shell = summary.get("energy_shell")
    if shell:
        parts.append(f"H = {shell['energy']:g}")
    for name, wanted in (where or {}).items():
        parts.append(f"{name} = {', '.join(f'{v:g}' for v in np.atleast_1d(np.asarray(wanted, dtype=float)))}")
    integrator, time = summary.get("integrator") or {}, summary.get("time") or {}
    run = [integrator.get("scheme", "") + (f" order {integrator['order']}" if "order" in integrator else "")]
    if "dt" in time:
        run.append(f"dt = {time['dt']:g}")
    if "t_end" in time:
        run.append(f"t = {time['t_end']:g}")
    run = [part for part in run if part]
    return ", ".join(parts) + ("; " + ", ".join(run) if run else "")


CHAOS_COLOURS = ["#2166ac", "#67a9cf", "#fddbc7", "#ef8a62", "#b2182b"]  # regular blue to chaotic red


def _colour_map(cmap, default):
    """A Colormap from a name ("chaos", "chaos_r" or matplotlib's), a Colormap, or None (the default's name)."""
    import matplotlib
    from matplotlib.colors import LinearSegmentedColormap
    if cmap is not None and not isinstance(cmap, str):
        return cmap
    name = cmap or default
    if name in ("chaos", "chaos_r"):
        colours = CHAOS_COLOURS if name == "chaos" else CHAOS_COLOURS[::-1]
        return LinearSegmentedColormap.from_list(f"nonsep_{name}", colours)
    return matplotlib.colormaps[name]


def _uniform(values):
    if len(values) < 3:
        return True
    steps = np.diff(values)
    return bool(np.allclose(steps, steps[0], rtol=1e-6, atol=0.0))


def _edges(values):
    if len(values) == 1:
        return np.array([values[0] - 0.5, values[0] + 0.5])
    middle = (values[1:] + values[:-1]) / 2
    return np.concatenate([[2 * values[0] - middle[0]], middle, [2 * values[-1] - middle[-1]]])
