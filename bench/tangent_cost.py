#!/usr/bin/env python3
"""What one Lyapunov vector adds to a Gauss-Legendre run: 1024 orbits of paper1d (q0 = 0.2 + 1.8 j / 1024, p0 = 0)
or of paper2d (q0 = (0.1 + 0.5 j / 1024, 0.2), p0 = (0, 1)), Gauss-Legendre with STAGES stages (default 3) at
dt = 0.01, 2000 steps, one thread, with and without /analysis/lyapunov (VECTORS vectors, default 1, renormalised every
10 steps), each run REPEATS times alternately. Measured is the CPU time (user + system) of `nonsep run`, process
start and plugin loading included, which a machine shared with other work inflates less than the wall time.

    python3 bench/tangent_cost.py build/bin/nonsep [REPEATS] [MODEL] [VECTORS] [STAGES]

Prints the medians and ranges of both, their ratio, and the grad H per state and step of each run (summary.json's
evaluation counts: the iterations of the stages, times the stages).
"""
import json
import statistics
import sys
import tempfile
from pathlib import Path

from timed_run import timed_run

nonsep = sys.argv[1]
repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 5
model = sys.argv[3] if len(sys.argv) > 3 else "paper1d"
vectors = int(sys.argv[4]) if len(sys.argv) > 4 else 1
stages = int(sys.argv[5]) if len(sys.argv) > 5 else 3
orbits, steps = 1024, 2000


def initial(j):
    if model == "paper1d":
        return {"q": [0.2 + 1.8 * j / orbits], "p": [0.0]}
    return {"q": [0.1 + 0.5 * j / orbits, 0.2], "p": [0.0, 1.0]}


def job(with_tangents):
    document = {"model": {"plugin": model},
                "integrator": {"scheme": "gauss", "stages": stages},
                "initial": [initial(j) for j in range(orbits)],
                "time": {"dt": 0.01, "steps": steps},
                "output": {"every": 0}}
    if with_tangents:
        document["analysis"] = {"lyapunov": {"vectors": vectors, "renormalize_every": 10}}
    return document


def run(path, out):
    return timed_run(nonsep, path, out)[0]


def evaluations(out):
    counts = json.loads((out / "summary.json").read_text())["evaluations"]
    per = orbits * steps
    return f"grad_H {counts['grad_H'] / per:.2f}"


with tempfile.TemporaryDirectory() as temporary:
    folder = Path(temporary)
    plain, tangent = folder / "plain.json", folder / "tangent.json"
    plain.write_text(json.dumps(job(False)))
    tangent.write_text(json.dumps(job(True)))
    times = {"plain": [], "tangent": []}
    for _ in range(repeats):
        times["plain"].append(run(plain, folder / "plain"))
        times["tangent"].append(run(tangent, folder / "tangent"))
    for name in times:
        cpu = times[name]
        print(f"{name}: CPU {statistics.median(cpu):.3f} s (range {min(cpu):.3f} to {max(cpu):.3f}); per state and "
              f"step: {evaluations(folder / name)}")
    ratios = sorted(t / p for p, t in zip(times["plain"], times["tangent"]))
    print(f"{model}, gauss {stages} stages, {vectors} vector(s): tangent / plain = "
          f"{statistics.median(times['tangent']) / statistics.median(times['plain']):.2f} (pairwise "
          f"{ratios[0]:.2f} to {ratios[-1]:.2f})")
