"""What a nonsep run or study left in its output folder, loaded with numpy: load(output_dir) -> Result.

Files read (docs/outputs.md); each is optional except summary.json:
  summary.json       Result.summary, as a dict (non-finite numbers are None there, as the host writes null)
  trajectories.csv   Result.trajectories, one row per trajectory (None for a study)
  trajectory.csv     Result.samples() and Result.orbit(i): read on first use and kept
  results.h5         instead of trajectory.csv with output.format "hdf5": the same Result.samples() and orbit(i) from
                     its /samples (without trajectory.csv's rows of final states off the sample steps, which are in
                     trajectories), and for either format Result.sample_arrays(): Samples(step, t, q, p, H) as
                     [samples, trajectories, ...] arrays, NaN where a trajectory has no sample
  convergence.csv    Result.convergence (a study); Result.fits and Result.exponents come from summary.json's "fits"
  poincare.csv       Result.poincare (every crossing, rows in (step, trajectory) order; None without the file) and
                     Result.crossings(i) (trajectory i's crossings in order): read on first use and kept
  lyapunov.csv       Result.lyapunov (the running Lyapunov, MEGNO, SALI and GALI estimates; None without the file) and
                     Result.lyapunov_series(i): read on first use and kept
  error_estimate.csv Result.error_estimate (analysis.error_estimate: the estimated errors at every comparison step,
                     rows in (step, trajectory) order; None without the file) and Result.error_estimates(i);
                     trajectories.csv has each trajectory's last estimate and its horizon
  frequency_spectra.csv  Result.frequency_spectra (analysis.frequencies with spectra: the strongest terms of each
                     signal, rows in trajectory order; None without the file)
  frequency_signals.npy  Result.frequency_signals() (analysis.frequencies: the sampled signals q_k + i p_k as a
                     complex array [trajectory, signal, sample], memory-mapped); trajectories.csv has the frequencies
                     and the diffusion index, Result.frequency_analysis the settings (summary.json)
  (trajectories.csv) Result.select(where): the trajectories of some values of swept parameters; and
                     Result.chaotic_fraction(...): the fraction of orbits past an indicator's threshold against a
                     swept parameter, with binomial (Wilson score) intervals
  other *.csv        Result.dynamics[name] (poincare.csv and lyapunov.csv too, the same arrays): read by header on
                     first use, as tables.read_table types columns
  results.h5         also Result.dynamics["results.h5/<dataset path>"]: every dataset, read with h5py on first use
"""
import json
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import NamedTuple

import numpy as np

from .tables import read_table

_KNOWN_FILES = {"trajectory.csv", "trajectories.csv", "convergence.csv"}


class Orbit(NamedTuple):
    """The samples of one trajectory in trajectory.csv, in step order: q and p are [samples, dimension]; H (the
    energy) and relative_energy_error are NaN where the host left them empty (unknown)."""
    step: np.ndarray
    t: np.ndarray
    q: np.ndarray
    p: np.ndarray
    H: np.ndarray
    relative_energy_error: np.ndarray


class Samples(NamedTuple):
    """Every sample of a run as arrays, results.h5's /samples layout: step and t are [S] (step 0, every output.every-th
    step, the last step), q and p [S, N, n] (N trajectories of dimension n), H [S, N]; NaN where a trajectory was no
    longer active (or the run did not reach the sample), and in H where it was not evaluated."""
    step: np.ndarray
    t: np.ndarray
    q: np.ndarray
    p: np.ndarray
    H: np.ndarray


class Crossings(NamedTuple):
    """The Poincare crossings of one trajectory (poincare.csv), in order: crossing counts them from 0, step is the
    step within which each crossed, q and p are [crossings, dimension], H the energy there (NaN when unknown)."""
    crossing: np.ndarray
    step: np.ndarray
    t: np.ndarray
    q: np.ndarray
    p: np.ndarray
    H: np.ndarray


class LyapunovSeries(NamedTuple):
    """The running estimates of one trajectory (lyapunov.csv), in step order: exponents is [rows, k] (columns
    lyapunov0 .. lyapunov<k-1>, k = 0 when only MEGNO was asked for); megno (Y) and mean_megno (<Y>) are None when
    the run did not compute MEGNO; sali is None without analysis.sali; gali is [rows, k - 1] (columns gali2 ..
    gali<k>: gali[:, j - 2] is GALI_j) or None without analysis.gali; fli is None without analysis.fli, ofli without
    analysis.ofli."""
    step: np.ndarray
    t: np.ndarray
    exponents: np.ndarray
    megno: object
    mean_megno: object
    sali: object = None
    gali: object = None
    fli: object = None
    ofli: object = None


class ChaoticFraction(NamedTuple):
    """The fraction of chaotic orbits per value of a swept parameter (Result.chaotic_fraction): `values` are the
    parameter's values in increasing order; `orbits` the completed trajectories of each with a finite indicator,
    `chaotic` those past the threshold, `left_out` the others (diverged, failed, inaccurate, or without a value);
    `fraction` = chaotic / orbits and [lower, upper] its Wilson score interval of z standard deviations (NaN where
    no orbit counts). `criterion` says what counts as chaotic, e.g. "mean_megno > 2.5"."""
    parameter: str
    values: np.ndarray
    chaotic: np.ndarray
    orbits: np.ndarray
    left_out: np.ndarray
    fraction: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    criterion: str


# What counts as chaotic, per column of trajectories.csv: (">" or "<", threshold). MEGNO's <Y> tends to 2 on a
# quasi-periodic orbit and grows like l_1 t / 2 on a chaotic one; SALI and GALI_2 fall exponentially on a chaotic
# orbit (docs/dynamics.md, "Chaotic fraction", measures where regular and chaotic orbits part on paper2d).
CHAOS_THRESHOLDS = {"mean_megno": (">", 2.5), "megno": (">", 2.5), "sali": ("<", 1e-8), "gali2": ("<", 1e-8)}


def chaos_threshold(value, threshold=None):
    """(direction, threshold) for column `value`: the given threshold (a number, or a (direction, number) pair with
    direction ">" or "<"), else CHAOS_THRESHOLDS' default. Raises ValueError for a column without a default."""
    if threshold is None:
        if value not in CHAOS_THRESHOLDS:
            raise ValueError(f"no default threshold for {value!r} (defaults: {', '.join(CHAOS_THRESHOLDS)}): give "
                             "threshold, a number, or (\">\" or \"<\", number)")
        return CHAOS_THRESHOLDS[value]
    if isinstance(threshold, tuple):
        direction, number = threshold
        if direction not in (">", "<"):
            raise ValueError(f"threshold's direction must be \">\" or \"<\", found {direction!r}")
        return direction, float(number)
    return CHAOS_THRESHOLDS.get(value, (">", None))[0], float(threshold)


def wilson_interval(successes, trials, z=1.0):
    """The Wilson score interval of a binomial proportion successes / trials, z standard deviations wide on each
    side: (lower, upper), NaN where trials is 0. Unlike f +- z sqrt(f (1 - f) / n) it stays inside [0, 1] and does
    not shrink to nothing at f = 0 or 1."""
    k, n = np.asarray(successes, dtype=float), np.asarray(trials, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        f = k / n
        centre = (f + z * z / (2 * n)) / (1 + z * z / n)
        half = z / (1 + z * z / n) * np.sqrt(f * (1 - f) / n + z * z / (4 * n * n))
    return np.maximum(centre - half, 0.0), np.minimum(centre + half, 1.0)


class ErrorEstimates(NamedTuple):
    """The estimated global errors of one trajectory (error_estimate.csv), in step order: the Richardson estimates
    of its phase-space error and relative energy error, and whether the run and its half-step twin had separated
    there (then the estimate no longer holds)."""
    step: np.ndarray
    t: np.ndarray
    phase_error: np.ndarray
    relative_energy_error: np.ndarray
    separated: np.ndarray


class Result:
    """The outputs of one run or study in `directory`. See the module's documentation for which file is what."""

    def __init__(self, directory):
        self.directory = Path(directory)
        with open(self.directory / "summary.json") as f:
            self.summary = json.load(f)
        self.trajectories = _trajectories(self.directory)
        convergence = self.directory / "convergence.csv"
        self.convergence = read_table(convergence) if convergence.exists() else None
        self.fits = self.summary.get("fits", [])
        self.exponents = {fit["integrator"]: _number(fit.get("exponent")) for fit in self.fits}
        self.dynamics = _Dynamics(self.directory)
        self._samples = None
        self._order = self._sorted = None
        self._groups = {}

    @property
    def status(self):
        return self.summary.get("status")

    @property
    def format(self):
        """"csv" or "hdf5": the run's output.format (summary.json; "csv" for a study or an older run)."""
        return (self.summary.get("output") or {}).get("format", "csv")

    def samples(self):
        """Every row of trajectory.csv as a structured array (fields named by the header: trajectory, step, t, q0,
        ..., p0, ..., H, relative_energy_error). For an output.format "hdf5" run, the same rows from results.h5's
        /samples (one per trajectory and sample step where it has a state; the final rows that trajectory.csv adds
        off the sample steps are not there). Raises FileNotFoundError when the run wrote none (output.every 0)."""
        if self._samples is None:
            if self.format == "hdf5":
                self._samples = _rows_of_arrays(self.sample_arrays(), self._initial_energies())
            else:
                self._samples = read_table(self.directory / "trajectory.csv")
        return self._samples

    def sample_arrays(self):
        """The samples as Samples(step, t, q, p, H) arrays (see Samples), from results.h5 (read with h5py) or from
        trajectory.csv's rows at the sample steps. Raises FileNotFoundError when the run wrote no samples."""
        if self.format == "hdf5":
            import h5py  # only where results.h5 is read
            path = self.directory / "results.h5"
            with h5py.File(path, "r") as f:
                if "samples" not in f:
                    raise FileNotFoundError(f"{path} has no /samples (output.every was 0)")
                g = f["samples"]
                return Samples(g["step"][()], g["t"][()], g["q"][()], g["p"][()], g["H"][()])
        return _arrays_of_rows(self.samples(), self.summary)

    def _initial_energies(self):
        count = len(self.trajectories)
        return self.trajectories["H0"] if "H0" in self.trajectories.dtype.names else np.full(count, math.nan)

    def orbit(self, index):
        """The samples of trajectory `index` (its position in the job's initial states) as an Orbit. Raises
        KeyError when trajectory.csv has no row of that trajectory."""
        samples = self.samples()
        if self._order is None:  # the rows grouped by trajectory, in file (step) order within each
            self._order = np.argsort(samples["trajectory"], kind="stable")
            self._sorted = samples["trajectory"][self._order]
        begin, end = np.searchsorted(self._sorted, [index, index + 1])
        rows = samples[self._order[begin:end]]
        if len(rows) == 0:
            raise KeyError(f"trajectory.csv in {self.directory} has no rows of trajectory {index}")
        q, p = _components(rows)
        return Orbit(rows["step"], rows["t"], q, p, rows["H"], rows["relative_energy_error"])

    @property
    def poincare(self):
        """Every row of poincare.csv as a structured array (trajectory, crossing, step, t, q0, ..., p0, ..., H), in
        the file's (step, trajectory) order; None when the run wrote none (no analysis.poincare)."""
        return self.dynamics.get("poincare")

    @property
    def lyapunov(self):
        """Every row of lyapunov.csv as a structured array (trajectory, step, t, lyapunov0, ..., and megno,
        mean_megno, sali, gali2, ... when computed), in the file's order; None when the run wrote none (analysis.lyapunov.every 0)."""
        return self.dynamics.get("lyapunov")

    @property
    def error_estimate(self):
        """Every row of error_estimate.csv as a structured array (trajectory, step, t, estimated_phase_error,
        estimated_relative_energy_error, separated); None when the run wrote none (no analysis.error_estimate)."""
        return self.dynamics.get("error_estimate")

    def error_estimates(self, index):
        """The error estimates of trajectory `index` as ErrorEstimates. Raises FileNotFoundError when the run wrote
        no error_estimate.csv, KeyError for an index that is not a trajectory."""
        rows = self._rows_of("error_estimate", index)
        return ErrorEstimates(rows["step"], rows["t"], rows["estimated_phase_error"],
                              rows["estimated_relative_energy_error"], rows["separated"])

    @property
    def frequency_analysis(self):
        """The run's frequency map analysis, summary.json's analysis.frequencies (signals, every, samples, tau,
        columns, ...), or None."""
        return (self.summary.get("analysis") or {}).get("frequencies")

    @property
    def frequency_spectra(self):
        """Every row of frequency_spectra.csv as a structured array (trajectory, signal, term, frequency,
        amplitude_re, amplitude_im); None when the run wrote none (no analysis.frequencies.spectra)."""
        return self.dynamics.get("frequency_spectra")

    def frequency_signals(self):
        """The sampled signals of analysis.frequencies, frequency_signals.npy, as a read-only memory-mapped complex
        array of shape (trajectories, signals, samples): signal j of trajectory i at sample k is q + i p of degree of
        freedom frequency_analysis["signals"][j] at step (k + 1) every, t = (k + 1) tau. A trajectory that stopped
        early has zeros after its last sample. Raises FileNotFoundError when the run wrote none."""
        path = self.directory / "frequency_signals.npy"
        if not path.is_file():
            raise FileNotFoundError(f"{self.directory} has no frequency_signals.npy (the run had no "
                                    "analysis.frequencies)")
        return np.load(path, mmap_mode="r")

    @property
    def section(self):
        """The Poincare section of the run, summary.json's analysis.poincare (normal, value, direction,
        max_crossings, crossings, ...), or None."""
        return (self.summary.get("analysis") or {}).get("poincare")

    def crossings(self, index):
        """The crossings of trajectory `index` as Crossings (empty arrays when it crossed no time). Raises
        FileNotFoundError when the run wrote no poincare.csv, KeyError for an index that is not a trajectory."""
        rows = self._rows_of("poincare", index)
        q, p = _components(rows)
        return Crossings(rows["crossing"], rows["step"], rows["t"], q, p, rows["H"])

    def lyapunov_series(self, index):
        """The running Lyapunov / MEGNO / SALI / GALI / FLI / OFLI estimates of trajectory `index` as a LyapunovSeries. Raises
        FileNotFoundError when the run wrote no lyapunov.csv, KeyError for an index that is not a trajectory."""
        rows = self._rows_of("lyapunov", index)
        names = rows.dtype.names
        k = sum(1 for name in names if re.fullmatch(r"lyapunov\d+", name))
        exponents = np.column_stack([rows[f"lyapunov{j}"] for j in range(k)]) if k else np.empty((len(rows), 0))
        megno = rows["megno"] if "megno" in names else None
        mean_megno = rows["mean_megno"] if "mean_megno" in names else None
        sali = rows["sali"] if "sali" in names else None
        k_gali = sum(1 for name in names if re.fullmatch(r"gali\d+", name)) + 1
        gali = np.column_stack([rows[f"gali{j}"] for j in range(2, k_gali + 1)]) if k_gali > 1 else None
        fli = rows["fli"] if "fli" in names else None
        ofli = rows["ofli"] if "ofli" in names else None
        return LyapunovSeries(rows["step"], rows["t"], exponents, megno, mean_megno, sali, gali, fli, ofli)

    @property
    def swept(self):
        """The swept parameters' names (summary.json's sweep), in its order; [] for a run without a sweep."""
        return list((self.summary.get("sweep") or {}).get("parameters", {}))

    def select(self, where=None):
        """The indices of the trajectories whose swept parameters have the given values: `where` maps a swept
        parameter's name to a value or a list of values, e.g. {"coupling": 0.1} (compared to 1e-9 relative, so the
        decimal written in the job matches); None selects every trajectory. Raises ValueError naming the parameter
        for a name that is not swept, or a value that no trajectory has (with the values there are)."""
        count = len(self.trajectories) if self.trajectories is not None else 0
        mask = np.ones(count, dtype=bool)
        for name, wanted in (where or {}).items():
            if name not in self.swept:
                raise ValueError(f"where: {name!r} is not a swept parameter of {self.directory} (swept: "
                                 f"{', '.join(self.swept) or 'none, not a parameter sweep'})")
            column = np.asarray(self.trajectories[name], dtype=float)
            values = np.unique(column)
            chosen = np.zeros(count, dtype=bool)
            for v in np.atleast_1d(np.asarray(wanted, dtype=float)):
                match = np.isclose(column, v, rtol=1e-9, atol=1e-12)
                if not match.any():
                    raise ValueError(f"where: no trajectory has {name} = {v:g} (its values: "
                                     f"{', '.join(f'{x:g}' for x in values)})")
                chosen |= match
            mask &= chosen
        if where and not mask.any():
            raise ValueError(f"where: no trajectory has all of {where}")
        return np.flatnonzero(mask)

    def chaotic_fraction(self, x=None, value="mean_megno", threshold=None, where=None, z=1.0):
        """The fraction of orbits past `threshold` in column `value` of trajectories.csv, for each value of the swept
        parameter `x` (default: the one swept parameter), as a ChaoticFraction. `threshold`: a number (the direction
        of the column's default: chaotic above for MEGNO, below for SALI), a pair (">" or "<", number), or None for
        CHAOS_THRESHOLDS' default (mean_megno > 2.5, sali < 1e-8, ...). Counted: the trajectories selected by
        `where` (see select) that completed with a finite value; the others are `left_out`. Another swept
        parameter must be fixed by `where` (ValueError otherwise: pooling its values would mix maps). The intervals
        are Wilson score intervals of z standard deviations (wilson_interval)."""
        chosen = self.select(where)
        if x is None:
            varying = [n for n in self.swept if len(np.unique(self.trajectories[n][chosen])) > 1]
            if len(self.swept) == 0:
                raise ValueError(f"{self.directory} is not a parameter sweep (summary.json has no \"sweep\")")
            x = varying[0] if len(varying) == 1 else self.swept[0]
        if x not in self.swept:
            raise ValueError(f"{x!r} is not a swept parameter (swept: {', '.join(self.swept) or 'none'})")
        for other in self.swept:
            if other != x and len(np.unique(self.trajectories[other][chosen])) > 1:
                raise ValueError(f"{other} varies too: fix it with where={{{other!r}: ...}}")
        table = self.trajectories
        if value not in table.dtype.names:
            raise ValueError(f"trajectories.csv has no column {value!r} (its columns: {', '.join(table.dtype.names)})")
        direction, limit = chaos_threshold(value, threshold)
        indicator = np.asarray(table[value], dtype=float)[chosen]
        counted = (table["status"][chosen] == "completed") & np.isfinite(indicator)
        past = (indicator > limit) if direction == ">" else (indicator < limit)
        values, group = np.unique(np.asarray(table[x], dtype=float)[chosen], return_inverse=True)
        orbits = np.bincount(group, weights=counted, minlength=len(values)).astype(int)
        chaotic = np.bincount(group, weights=counted & past, minlength=len(values)).astype(int)
        left_out = np.bincount(group, minlength=len(values)) - orbits
        lower, upper = wilson_interval(chaotic, orbits, z)
        with np.errstate(divide="ignore", invalid="ignore"):
            fraction = chaotic / orbits
        return ChaoticFraction(x, values, chaotic, orbits, left_out, fraction, lower, upper,
                               f"{value} {direction} {limit:g}")

    def initial_states(self):
        """(q, p), each [trajectories, dimension]: every trajectory's state at step 0, from trajectory.csv (the host
        writes step 0 whatever output.every > 0). Raises FileNotFoundError saying what to set when the run had
        output.every 0 (no samples), and ValueError when it has no step-0 row of some trajectory."""
        if self.summary.get("output", {}).get("every") == 0:
            raise FileNotFoundError(
                f"{self.directory} has no samples, so no initial states: the run had output.every = 0. The initial "
                "states are the step-0 samples: run the job with output.every > 0 (its number of steps writes step "
                "0 and the last step only)")
        samples = self.samples()
        first = samples[samples["step"] == 0]
        first = first[np.argsort(first["trajectory"], kind="stable")]
        count = len(self.trajectories) if self.trajectories is not None else len(first)
        if not np.array_equal(first["trajectory"], np.arange(count)):
            raise ValueError(f"trajectory.csv in {self.directory} does not have one step-0 row per trajectory")
        return _components(first)

    def _rows_of(self, name, index):
        """The rows of trajectory `index` in file `name`.csv, in file order: grouped once by a stable sort."""
        table = self.dynamics.get(name)
        if table is None:
            raise FileNotFoundError(f"{self.directory} holds no {name}.csv")
        if name not in self._groups:
            order = np.argsort(table["trajectory"], kind="stable")
            self._groups[name] = (order, table["trajectory"][order])
        count = len(self.trajectories) if self.trajectories is not None else None
        if index < 0 or (count is not None and index >= count):
            raise KeyError(f"{self.directory} has no trajectory {index}")
        order, sorted_indices = self._groups[name]
        begin, end = np.searchsorted(sorted_indices, [index, index + 1])
        return table[order[begin:end]]

    def __repr__(self):
        return f"nonsep.Result({str(self.directory)!r}, status={self.status!r})"


def load(output_dir):
    """The Result of the run or study whose outputs are in `output_dir`. Raises FileNotFoundError without
    summary.json there."""
    return Result(output_dir)


def _components(rows):
    """(q, p) of `rows`, each [rows, dimension], from the columns q0.. and p0.. ."""
    d = sum(1 for name in rows.dtype.names if re.fullmatch(r"q\d+", name))
    q = np.column_stack([rows[f"q{k}"] for k in range(d)]) if d else np.empty((len(rows), 0))
    p = np.column_stack([rows[f"p{k}"] for k in range(d)]) if d else np.empty((len(rows), 0))
    return q, p


def _sample_steps(steps, every):
    """step 0, every, 2 every, ... and the last step: the host's sample steps."""
    listed = list(range(0, steps + 1, every))
    return np.array(listed + ([steps] if listed[-1] != steps else []), dtype=np.uint64)


def _arrays_of_rows(rows, summary):
    """Samples from trajectory.csv's rows: those at the sample steps, put at [sample, trajectory]."""
    every, steps = summary["output"]["every"], summary["time"]["steps"]
    count, (q, p) = summary["trajectories"], _components(rows)
    if every == 0:
        raise FileNotFoundError("the run wrote no samples (output.every 0)")
    step = _sample_steps(steps, every)
    d = q.shape[1]
    # t as the host computes it (time_grid.hpp): step * dt, and t_end exactly at the last step
    t = np.where(step == steps, summary["time"]["t_end"], step.astype(np.float64) * summary["time"]["dt"])
    arrays = Samples(step, t, np.full((len(step), count, d), math.nan),
                     np.full((len(step), count, d), math.nan), np.full((len(step), count), math.nan))
    index = np.searchsorted(step, rows["step"].astype(np.uint64))
    at_sample = (index < len(step)) & (step[np.minimum(index, len(step) - 1)] == rows["step"].astype(np.uint64))
    i, j = index[at_sample], rows["trajectory"][at_sample]
    arrays.q[i, j], arrays.p[i, j], arrays.H[i, j] = q[at_sample], p[at_sample], rows["H"][at_sample]
    return arrays


def _rows_of_arrays(arrays, energies_initial):
    """trajectory.csv's structured rows from Samples: one per (sample, trajectory) with a state, in that order."""
    count, d = arrays.q.shape[1], arrays.q.shape[2]
    present = ~np.all(np.isnan(arrays.q), axis=2) if d else np.zeros(arrays.H.shape, dtype=bool)
    i, j = np.nonzero(present)
    names = ["trajectory", "step", "t"] + [f"q{k}" for k in range(d)] + [f"p{k}" for k in range(d)]
    rows = np.empty(len(i), dtype=[(name, np.int64 if name in ("trajectory", "step") else np.float64)
                                   for name in names] + [("H", np.float64), ("relative_energy_error", np.float64)])
    rows["trajectory"], rows["step"], rows["t"] = j, arrays.step[i], arrays.t[i]
    for k in range(d):
        rows[f"q{k}"], rows[f"p{k}"] = arrays.q[i, j, k], arrays.p[i, j, k]
    rows["H"] = arrays.H[i, j]
    h0 = np.asarray(energies_initial, dtype=np.float64)[j] if count else np.empty(0)
    with np.errstate(divide="ignore", invalid="ignore"):
        rows["relative_energy_error"] = np.where(h0 != 0, (rows["H"] - h0) / h0, math.nan)
    return rows


def _number(value):
    return math.nan if value is None else float(value)


def _trajectories(directory):
    table = directory / "trajectories.csv"
    return read_table(table) if table.exists() else None  # a study has none: its runs are in convergence.csv


class _Dynamics(Mapping):
    """The folder's other CSV files by stem, and the datasets of results.h5, each read on first access."""

    def __init__(self, directory):
        self._directory = directory
        self._loaded = {}
        self._hdf5 = directory / "results.h5"
        self._names = None

    def _list(self):
        if self._names is None:
            names = sorted(p.stem for p in self._directory.glob("*.csv") if p.name not in _KNOWN_FILES)
            if self._hdf5.exists():
                names += [f"results.h5/{name}" for name in _hdf5_datasets(self._hdf5)]
            self._names = names
        return self._names

    def __getitem__(self, name):
        if name not in self._list():
            raise KeyError(name)
        if name not in self._loaded:
            if name.startswith("results.h5/"):
                import h5py  # only where results.h5 is read
                with h5py.File(self._hdf5, "r") as f:
                    self._loaded[name] = f[name[len("results.h5/"):]][()]
            else:
                self._loaded[name] = read_table(self._directory / f"{name}.csv")
        return self._loaded[name]

    def __iter__(self):
        return iter(self._list())

    def __len__(self):
        return len(self._list())


def _hdf5_datasets(path):
    import h5py  # only where results.h5 is read
    names = []
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, item: names.append(name) if isinstance(item, h5py.Dataset) else None)
    return names
