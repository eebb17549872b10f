"""nonsep from Python: run job files (or dicts) with the `nonsep` executable and load what the runs leave behind.

    import nonsep
    result = nonsep.run("examples/jobs/ensemble.json", output="ensemble.out")
    result.trajectories["relative_energy_error"]     # one row per trajectory
    orbit = result.orbit(0)                            # orbit.t, orbit.q [n, d], orbit.p, orbit.H, ...

run(), validate() and the executable: nonsep.process; load() and Result: nonsep.results; figures: nonsep.plot
(imported on its own, as it needs matplotlib); nonsep.work_precision plots a study's work_precision.csv
(`python3 -m nonsep.work_precision`).

The package needs numpy (and matplotlib, h5py where used): Debian's python3-numpy serves Debian's /usr/bin/python3.
"""
import sys

try:
    import numpy  # noqa: F401
except ImportError as missing:
    raise ImportError(
        f"nonsep needs numpy, which this Python ({sys.executable}) cannot import. Debian's python3-numpy (installed "
        "by scripts/setup.sh) serves /usr/bin/python3: run /usr/bin/python3, or install numpy (and matplotlib, "
        "h5py) for this interpreter") from missing

from .process import (ExecutableNotFound, Problem, RunError, RunInterrupted, executable, parse_problems, run,
                      validate)
from .results import ChaoticFraction, Crossings, ErrorEstimates, LyapunovSeries, Orbit, Result, Samples, load

__all__ = ["ChaoticFraction", "Crossings", "ErrorEstimates", "ExecutableNotFound", "LyapunovSeries", "Orbit", "Problem",
           "Result", "RunError", "RunInterrupted", "Samples", "executable", "load", "parse_problems", "run", "validate"]
