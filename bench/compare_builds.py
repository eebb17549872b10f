#!/usr/bin/env python3
"""Two builds of nonsep on one job, interleaved, so that a change of speed between them is seen when it happens.

The default job is the Chin state kernel's: 1024 paper1d trajectories (q0 = 0.2 + 1.8 j / 1024, p0 = 0), the basic
step at dt = 1e-6, 195312 steps, one thread, no output but the summary. Each build runs with its own plugins (the
executable finds the build's plugins beside it), alternately, REPEATS times; measured is the CPU time (user + system)
of `nonsep run`, process start and plugin loading included. A ratio above 1 means the second build is slower.

    python3 bench/compare_builds.py OLD/bin/nonsep NEW/bin/nonsep [--repeats 7] [--job FILE] [--threads 1]

To build the comparison: `git worktree add /tmp/old COMMIT && cmake -S /tmp/old -B /tmp/old/build
-DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF && cmake --build /tmp/old/build -j2` (the same compiler and flags as
the new build). Prints each build's median, range and the pairwise ratios' median and range.
"""
import argparse
import json
import statistics
import tempfile
from pathlib import Path

from timed_run import timed_run


def default_job():
    return {"model": {"plugin": "paper1d"},
            "integrator": {"scheme": "basic"},
            "initial": [{"q": [0.2 + 1.8 * j / 1024], "p": [0.0]} for j in range(1024)],
            "time": {"dt": 1e-6, "steps": 195312},
            "output": {"every": 0}}


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--job", type=Path, help="a job file instead of the Chin state kernel's job")
    parser.add_argument("--threads", type=int, default=1)
    arguments = parser.parse_args()
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        job = arguments.job
        if job is None:
            job = folder / "job.json"
            job.write_text(json.dumps(default_job()))
        times = {"old": [], "new": []}
        for _ in range(arguments.repeats):
            for name in ("old", "new"):
                times[name].append(timed_run(getattr(arguments, name), job.resolve(), folder / name, arguments.threads)[0])
        for name in ("old", "new"):
            cpu = times[name]
            print(f"{name} ({getattr(arguments, name)}): CPU {statistics.median(cpu):.3f} s "
                  f"(range {min(cpu):.3f} to {max(cpu):.3f})")
        ratios = [n / o for o, n in zip(times["old"], times["new"])]
        print(f"new / old: {statistics.median(ratios):.3f} (pairs {min(ratios):.3f} to {max(ratios):.3f})")


if __name__ == "__main__":
    main()
