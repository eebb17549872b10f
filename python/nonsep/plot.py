"""Figures of a Result with matplotlib (imported here, not by `import nonsep`): orbit, energy_error, convergence,
and for the dynamics outputs poincare (the crossings of poincare.csv), chaos_map (MEGNO or a Lyapunov exponent
over the grid of initial conditions), stability_map (the same over a parameter sweep's plane) and
indicator_series (the running estimates of lyapunov.csv against t). Each function draws into `ax` (a new figure's axes when None) and returns
the axes, labelled with the quantities and with a legend when it shows more than one series (and at most
MAX_LEGEND; an ensemble's hundred lines get none). Choose the backend before importing pyplot, e.g.
matplotlib.use("Agg") for files only.
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


def poincare(result, ax=None, x=None, y=None, i=None, color_by=None, cmap=None, colorbar=True, **style):
    """The crossings of poincare.csv as points, x against y (column names such as "q0", "p0"; default: q and p of
    the first degree of freedom the section's plane leaves out, e.g. q0 and p0 for the plane q1 = 0 of a 2D model).
    `i`: a trajectory index, a list, or None for all. Points are coloured per trajectory (a qualitative colour map
    over trajectory indices, `cmap` default "tab20"), or with `color_by` a column of trajectories.csv such as
    "mean_megno" by that trajectory's value (`cmap` default "viridis", with a labelled colour bar when `colorbar`).
    One scatter call whatever the number of points; `style` goes to ax.scatter (default: dots of size 2, rasterized).
    The title names the plane. Raises ValueError when the run wrote no poincare.csv."""
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
    if i is not None:
        table = table[np.isin(table["trajectory"], [int(i)] if np.isscalar(i) else [int(k) for k in i])]
    ax = _axes(ax)
    style = {"s": 2.0, "linewidths": 0, "rasterized": True, **style}
    trajectory = table["trajectory"]
    if color_by is None:
        colours = _colour_map(cmap, "tab20")
        points = ax.scatter(table[x], table[y], c=colours(trajectory % colours.N), **style)
    else:
        values = _per_trajectory(result, color_by)[trajectory]
        points = ax.scatter(table[x], table[y], c=values, cmap=cmap or "viridis", **style)
        if colorbar:
            ax.figure.colorbar(points, ax=ax).set_label(_value_label(color_by))
    ax.set_xlabel(_math(x))
    ax.set_ylabel(_math(y))
    ax.set_title(_section_title(section, dimension), fontsize="medium")
    return ax


def _per_trajectory(result, column):
    table = result.trajectories
    if table is None or column not in table.dtype.names:
        names = ", ".join(table.dtype.names) if table is not None else "none"
        raise ValueError(f"trajectories.csv has no column {column!r} (its columns: {names})")
    if not np.array_equal(table["trajectory"], np.arange(len(table))):
        raise ValueError("trajectories.csv does not list the trajectories 0, 1, ... in order")
    return np.asarray(table[column], dtype=float)


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
    return column


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


def chaos_map(result, ax=None, value="mean_megno", x=None, y=None, cmap=None, colorbar=True, **style):
    """An image of `value` (a column of trajectories.csv: "mean_megno", the default, "lyapunov0", ...) over the
    grid of initial conditions, one cell per trajectory at its initial (x, y) (column names such as "q0", "p0").
    The initial states come from trajectory.csv's step-0 rows; x and y default to the two components that tell the
    states apart as a grid (see _grid_axes): for a grid over q0 and p0 on an energy shell, q0 and p0. Cells without
    a trajectory (states left off the shell) or without a value (diverged or failed) are grey. A uniform grid is
    drawn with ax.imshow, another with ax.pcolormesh; `style` goes there (e.g. vmin, vmax). Returns the axes, with a
    colour bar labelled with the quantity when `colorbar`."""
    values = _per_trajectory(result, value)
    columns = _initial_columns(result)
    if x is None or y is None:
        x, y = _grid_axes(columns, len(values))
    return _grid_image(_axes(ax), columns, x, y, values, value, None, cmap, colorbar, style)


def stability_map(result, ax=None, value="mean_megno", x=None, y=None, reduce=None, cmap=None, colorbar=True,
                  **style):
    """An image of `value` (a column of trajectories.csv) over a plane of a parameter sweep: a swept parameter
    against an initial-condition component ("coupling" x "q0"), or two swept parameters against each other. x and
    y name swept parameters (summary.json's sweep, columns of trajectories.csv) or components of the initial state
    (step-0 rows of trajectory.csv, as in chaos_map); they default to the two swept parameters, or to the one swept
    parameter and the initial component that, with it, tells the trajectories apart with the fewest cells. When
    several trajectories fall in one cell (a parameter x parameter plane over several initial states) `reduce`
    combines them ("mean", "median", "max", "min" or a function of an array); without it that is an error. Cells
    without a value are grey; `style` goes to imshow or pcolormesh as in chaos_map. Returns the axes."""
    swept = list((result.summary.get("sweep") or {}).get("parameters", {}))
    if not swept:
        raise ValueError(f"{result.directory} is not a parameter sweep (summary.json has no \"sweep\"): use chaos_map")
    values = _per_trajectory(result, value)
    columns = {name: _per_trajectory(result, name) for name in swept}
    needs_states = any(name not in columns for name in (x, y)) or (x is None and len(swept) == 1)
    if needs_states:
        columns.update(_initial_columns(result))
    if x is None or y is None:
        if len(swept) >= 2:
            x, y = swept[0], swept[1]
        else:
            others = {name: c for name, c in columns.items() if name != swept[0]}
            y = min(others, key=lambda name: _cells(columns[swept[0]], others[name], len(values)))
            x = swept[0]
    for name in (x, y):
        if name not in columns:
            raise ValueError(f"no parameter or initial component {name!r} (choose from {', '.join(columns)})")
    return _grid_image(_axes(ax), columns, x, y, values, value, reduce, cmap, colorbar, style)


def indicator_series(result, i=None, value="mean_megno", ax=None, **style):
    """The running estimate `value` of lyapunov.csv ("mean_megno", the default, "megno", "lyapunov0", ...) against t,
    one line per trajectory (`i`: an index, a list, or None for all in the file), labelled with the trajectory and,
    in a parameter sweep, its swept parameters. Needs analysis.lyapunov.every > 0. Returns the axes."""
    table = result.lyapunov
    if table is None:
        raise FileNotFoundError(f"{result.directory} holds no lyapunov.csv: run with analysis.lyapunov.every > 0")
    if value not in table.dtype.names:
        raise ValueError(f"lyapunov.csv has no column {value!r} (its columns: {', '.join(table.dtype.names)})")
    indices = [int(k) for k in np.unique(table["trajectory"])] if i is None else \
        ([int(i)] if np.isscalar(i) else [int(k) for k in i])
    swept = list((result.summary.get("sweep") or {}).get("parameters", {}))
    ax = _axes(ax)
    for index in indices:
        rows = result._rows_of("lyapunov", index)
        label = f"trajectory {index}" + "".join(
            f", {name} = {result.trajectories[name][index]:g}" for name in swept)
        ax.plot(rows["t"], rows[value], label=label, **style)
    ax.set_xlabel("$t$")
    ax.set_ylabel(_value_label(value))
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


def _grid_image(ax, columns, x, y, values, value, reduce, cmap, colorbar, style):
    """`values` as an image over the distinct values of columns[x] and columns[y]; see chaos_map."""
    xs, column_of = np.unique(columns[x], return_inverse=True)
    ys, row_of = np.unique(columns[y], return_inverse=True)
    grid = np.full((len(ys), len(xs)), np.nan)
    counts = np.zeros(grid.shape, dtype=int)
    np.add.at(counts, (row_of, column_of), 1)
    if counts.max() > 1 and reduce is None:
        raise ValueError(f"several trajectories start at the same ({x}, {y}): not a grid over them (give reduce)")
    if counts.max() > 1:
        combine = REDUCTIONS[reduce] if isinstance(reduce, str) else reduce
        cell = row_of * len(xs) + column_of
        for c in np.unique(cell):
            grid.flat[c] = combine(values[cell == c])
    else:
        grid[row_of, column_of] = values
    colours = _colour_map(cmap, "viridis").copy()
    colours.set_bad("#d9d9d9")
    if _uniform(xs) and _uniform(ys):
        half_x = (xs[-1] - xs[0]) / (len(xs) - 1) / 2 if len(xs) > 1 else 0.5
        half_y = (ys[-1] - ys[0]) / (len(ys) - 1) / 2 if len(ys) > 1 else 0.5
        style = {"interpolation": "nearest", "aspect": "auto", **style}
        image = ax.imshow(np.ma.masked_invalid(grid), origin="lower", cmap=colours,
                          extent=(xs[0] - half_x, xs[-1] + half_x, ys[0] - half_y, ys[-1] + half_y), **style)
    else:
        image = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(grid), cmap=colours, **style)
    ax.set_xlabel(_axis_label(x))
    ax.set_ylabel(_axis_label(y))
    if colorbar:
        ax.figure.colorbar(image, ax=ax).set_label(_value_label(value))
    return ax


def _colour_map(cmap, default):
    """A Colormap from a name, a Colormap, or None (the default's name)."""
    import matplotlib
    return matplotlib.colormaps[cmap or default] if cmap is None or isinstance(cmap, str) else cmap


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
