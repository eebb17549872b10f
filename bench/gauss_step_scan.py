"""The phase error of Gauss-Legendre at every step count of a range, on the states scheme auto pilots: whether the
error between the pilot ladder's rungs (n, 2n, 4n steps) follows the order, so that a step between them could be
certified by a pilot at that step, or is erratic in the step, so that one pilot there proves nothing.

Usage: /usr/bin/python3 bench/gauss_step_scan.py BUILD_BIN/nonsep [--stages 8] [--from 1200] [--to 2088] [--by 24]

The states are the 8 that auto pilots of the paper2d ensemble of bench/ensemble_work_precision.py (coupling 0.2,
q = (0, 0), p = (0.5 + 0.08 j / 1024, 2), j = k 1023 / 7 for k = 0 .. 7), to t = 100. For each step count N of the
range: the largest phase-space distance at t = 100 over the 8 from Gauss 16 at 8192 steps (whatever --stages; its
own error there is at the round-off these orbits amplify, about 1e-11, as auto's pilots measure it), each state's
distance, and the largest distance from the twin run (the same
N steps with a step one ulp larger, as auto's pilots measure round-off): a twin distance far below the error says the
error is the step's own, deterministic, not rounding. One thread; a few seconds for the default range.
"""
import argparse
import csv
import json
import math
import subprocess
import sys
import tempfile
from pathlib import Path

T_END = 100.0
LAST_ERROR = [""]  # nonsep's stderr of the last run that failed
STATES = [{"q": [0.0, 0.0], "p": [0.5 + 0.08 * (k * 1023 // 7) / 1024, 2.0]} for k in range(8)]


def run(nonsep, folder, stages, steps, dt):
    job = {"model": {"plugin": "paper2d"}, "integrator": {"scheme": "gauss", "stages": stages}, "initial": STATES,
           "output": {"every": 0}}
    # t_end from the steps (time.steps) so that the twin's step is exactly one ulp larger
    job["time"] = {"dt": dt, "steps": steps}
    path = folder / "scan.json"
    path.write_text(json.dumps(job))
    out = folder / "scan"
    done = subprocess.run([str(nonsep), "run", str(path), "-o", str(out), "--force", "--quiet", "--threads", "1"],
                          capture_output=True, text=True)
    if done.returncode != 0:
        LAST_ERROR[0] = done.stderr.strip()
        return None
    rows = list(csv.DictReader(open(out / "trajectories.csv")))
    return [[float(r[c]) for c in ("q0", "q1", "p0", "p1")] for r in rows]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("nonsep", type=Path)
    parser.add_argument("--stages", type=int, default=8)
    parser.add_argument("--from", dest="first", type=int, default=1200)
    parser.add_argument("--to", dest="last", type=int, default=2088)
    parser.add_argument("--by", type=int, default=24)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        reference = run(args.nonsep, folder, 8, 8192, T_END / 8192)
        if reference is None:
            sys.exit("gauss_step_scan: the reference run (Gauss 16, 8192 steps) failed: " + LAST_ERROR[0])
        print("| steps | largest error | twin distance | each state's error |")
        print("|---|---|---|---|")
        for steps in range(args.first, args.last + 1, args.by):
            dt = T_END / steps
            ended = run(args.nonsep, folder, args.stages, steps, dt)
            twin = run(args.nonsep, folder, args.stages, steps, math.nextafter(dt, 2 * dt))
            if ended is None or twin is None:
                print(f"| {steps} | failed | - | - |")
                continue
            errors = [math.dist(a, b) for a, b in zip(ended, reference)]
            twins = max(math.dist(a, b) for a, b in zip(ended, twin))
            print(f"| {steps} | {max(errors):.2e} | {twins:.1e} | {' '.join(f'{e:.1e}' for e in errors)} |")


if __name__ == "__main__":
    main()
