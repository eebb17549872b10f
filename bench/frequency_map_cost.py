#!/usr/bin/env python3
"""What frequency map analysis (/analysis/frequencies) adds to a run: 1024 orbits of paper1d (q0 = 0.2 + 1.8 j /
1024, p0 = 0), Gauss-Legendre with 3 stages at dt = 0.01, 2^14 steps, with and without the analysis of q + i p
sampled at every step (2^14 samples per orbit: the whole run and both halves by NAFF, frequency_signals.npy
written), each run REPEATS times alternately. Measured is the CPU time (user + system) of `nonsep run`, process start
and plugin loading included, which a machine shared with other work inflates less than the wall time (printed too).

    python3 bench/frequency_map_cost.py build/bin/nonsep [REPEATS] [THREADS] [EVERY]

Prints the medians and ranges of both and their ratio (the analysis's cost is the ratio minus 1). EVERY (default 1)
samples every EVERY-th step instead, with 2^14 EVERY steps, so that the number of samples stays 2^14.
"""
import json
import statistics
import sys
import tempfile
from pathlib import Path

from timed_run import timed_run

nonsep = sys.argv[1]
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
threads = sys.argv[3] if len(sys.argv) > 3 else "1"
every = int(sys.argv[4]) if len(sys.argv) > 4 else 1
samples = 2 ** 14


def job(with_analysis):
    document = {"model": {"plugin": "paper1d"},
                "integrator": {"scheme": "gauss", "stages": 3},
                "initial": [{"q": [0.2 + 1.8 * j / 1024], "p": [0.0]} for j in range(1024)],
                "time": {"dt": 0.01, "steps": samples * every},
                "output": {"every": 0}}
    if with_analysis:
        document["analysis"] = {"frequencies": {"every": every}}
    return document


def run(path, folder):
    return timed_run(nonsep, path, folder / "out", threads)


def describe(name, times):
    cpu = [c for c, _ in times]
    wall = [w for _, w in times]
    return (f"{name}: CPU {statistics.median(cpu):.3f} s (range {min(cpu):.3f} to {max(cpu):.3f}), wall "
            f"{statistics.median(wall):.3f} s")


with tempfile.TemporaryDirectory() as temporary:
    folder = Path(temporary)
    plain, analysed = folder / "plain.json", folder / "analysed.json"
    plain.write_text(json.dumps(job(False)))
    analysed.write_text(json.dumps(job(True)))
    times = {"plain": [], "analysed": []}
    for _ in range(repeats):
        times["plain"].append(run(plain, folder))
        times["analysed"].append(run(analysed, folder))
    print(f"1024 paper1d orbits, gauss 3 stages, {samples * every} steps, {samples} samples each, "
          f"{threads} thread(s), {repeats} repeats")
    for name, values in times.items():
        print(describe(name, values))
    ratio = statistics.median(c for c, _ in times["analysed"]) / statistics.median(c for c, _ in times["plain"])
    print(f"CPU ratio with / without the analysis: {ratio:.3f}")
