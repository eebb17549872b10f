#!/usr/bin/env python3
"""The cost of a parameter sweep beyond the cost of its trajectories: a sweep of S couplings of paper2d with N
states each against one run of the same S x N states with one coupling (the same numbers of steps and of
evaluations; with MEGNO, whose tangent map takes the evaluation path, or without, where the plugin's kernel steps
whole chunks), each run REPEATS times. Measured is the CPU time (user + system) of
`nonsep run`, process start and plugin loading included, which a machine shared with other work inflates less than
the wall time (printed too). The overhead per parameter set is (median sweep - median single run) / S: the plugin
instance created per set at load (and per set and thread in the run), blocks cut at every set, the sweep's cells
of trajectories.csv.

    python3 bench/sweep_overhead.py build/bin/nonsep [REPEATS] [THREADS] [plain|megno]

Prints one line per configuration: S, N, steps, the medians and ranges of both, the overhead per set, and S times
the CPU time of one of the S separate runs of N states that the sweep replaces.
"""
import json
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

nonsep = sys.argv[1]
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
threads = sys.argv[3] if len(sys.argv) > 3 else "1"


def timed(job, folder):
    path = folder / "job.json"
    path.write_text(json.dumps(job))
    cpu, wall = [], []
    for _ in range(repeats):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run([nonsep, "run", "-q", "--force", "--threads", threads, "--output", str(folder / "out"),
                        str(path)], check=True)
        wall.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return cpu, wall


def configuration(sets, states, steps, megno, folder):
    couplings = [0.1 * k / sets for k in range(sets)]
    initial = [{"q": [0.2 + 0.6 * k / states, 0.1], "p": [0.0, 0.5]} for k in range(states)]
    job = {"model": {"plugin": "paper2d", "parameters": {"coupling": couplings}},
           "integrator": {"scheme": "mpe", "order": 4}, "initial": initial,
           "time": {"dt": 0.005, "steps": steps}, "output": {"every": 0}, "analysis": {"megno": megno}}
    sweep, sweep_wall = timed(job, folder)
    single = dict(job, model={"plugin": "paper2d", "parameters": {"coupling": 0.05}}, initial=initial * sets)
    alone, alone_wall = timed(single, folder)
    separate, _ = timed(dict(single, initial=initial), folder)  # one of the S separate runs the sweep replaces
    a, b = statistics.median(sweep), statistics.median(alone)
    print(f"{sets} sets x {states} states, {steps} steps{', MEGNO' if megno else ''}: CPU time sweep {a:.3f} s ({min(sweep):.3f}-{max(sweep):.3f}), "
          f"one parameter set {b:.3f} s ({min(alone):.3f}-{max(alone):.3f}); overhead per set "
          f"{(a - b) / sets * 1e6:.0f} us ({(a / b - 1) * 100:+.1f}%); wall time medians "
          f"{statistics.median(sweep_wall):.3f} s and {statistics.median(alone_wall):.3f} s; the {sets} separate runs "
          f"it replaces {sets * statistics.median(separate):.3f} s of CPU time", flush=True)


with tempfile.TemporaryDirectory() as work:
    only = sys.argv[4] if len(sys.argv) > 4 else None  # "plain" or "megno": those configurations only
    for sets, states, steps, megno in ((1000, 1, 10, True), (1000, 1, 1000, True), (100, 10, 1000, True),
                                       (31, 31, 1000, True), (1000, 1, 1000, False), (31, 31, 1000, False),
                                       (31, 32, 1000, False)):
        if only is None or only == ("megno" if megno else "plain"):
            configuration(sets, states, steps, megno, Path(work))
