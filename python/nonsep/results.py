"""What a nonsep run or study left in its output folder, loaded with numpy: load(output_dir) -> Result.

Files read (README.md, "What a run leaves behind"); each is optional except summary.json:
  summary.json       Result.summary, as a dict (non-finite numbers are None there, as the host writes null)
  trajectories.csv   Result.trajectories, one row per trajectory (None for a study)
  trajectory.csv     Result.samples() and Result.orbit(i): read on first use and kept
  convergence.csv    Result.convergence (a study); Result.fits and Result.exponents come from summary.json's "fits"
  other *.csv        Result.dynamics[name] (poincare.csv -> "poincare", lyapunov.csv, megno.csv, ...): read by
                     header on first use, as tables.read_table types columns
  results.h5         Result.dynamics["results.h5/<dataset path>"]: every dataset, read with h5py on first use
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

    @property
    def status(self):
        return self.summary.get("status")

    def samples(self):
        """Every row of trajectory.csv as a structured array (fields named by the header: trajectory, step, t, q0,
        ..., p0, ..., H, relative_energy_error). Raises FileNotFoundError when the run wrote none (output.every 0)."""
        if self._samples is None:
            self._samples = read_table(self.directory / "trajectory.csv")
        return self._samples

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
        d = sum(1 for name in samples.dtype.names if re.fullmatch(r"q\d+", name))
        q = np.column_stack([rows[f"q{k}"] for k in range(d)])
        p = np.column_stack([rows[f"p{k}"] for k in range(d)])
        return Orbit(rows["step"], rows["t"], q, p, rows["H"], rows["relative_energy_error"])

    def __repr__(self):
        return f"nonsep.Result({str(self.directory)!r}, status={self.status!r})"


def load(output_dir):
    """The Result of the run or study whose outputs are in `output_dir`. Raises FileNotFoundError without
    summary.json there."""
    return Result(output_dir)


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
