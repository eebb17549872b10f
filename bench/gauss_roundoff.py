#!/usr/bin/env python3
"""Round-off in H over 10^7 steps of Gauss-Legendre (docs/accuracy.md, "Round-off of Gauss-Legendre").

64 paper1d orbits (q0 = 0.2 + 0.8 j/64, p0 = 0), gauss with --stages stages (3) at dt = --dt (0.001: the truncation
error in H is below 1e-16 there), --steps steps (10^7), H written every steps/1000 steps. For each written step the
mean over the orbits of |dH/H0| is computed, and its growth exponent is fitted (least squares of log mean against
log step) over the steps from 10^4 on: 0.5 is Brouwer's law (round-off errors that add like a random walk), 1 a
linear drift. With --nonsep-before a second build runs the same job (for example the main before a change), and
both are printed. Each run takes 4 to 6 minutes of CPU at the defaults; one thread each. --plot draws the means
against the steps with sqrt(steps) for comparison (docs/gauss_roundoff.png; matplotlib: use /usr/bin/python3).

Usage: python3 bench/gauss_roundoff.py --nonsep build/bin/nonsep [--nonsep-before OTHER] [--steps N] [--csv OUT]
                                       [--plot PNG]
"""
import argparse
import collections
import csv
import json
import math
import os
import subprocess
import sys
import tempfile


def job(stages, dt, steps, output):
    initial = [{"q": [0.2 + 0.8 * j / 64], "p": [0.0]} for j in range(64)]
    return {"model": {"plugin": "paper1d"}, "integrator": {"scheme": "gauss", "stages": stages},
            "initial": initial, "time": {"dt": dt, "steps": steps},
            "output": {"directory": output, "every": max(1, steps // 1000)}}


def mean_errors(series):
    """{step: mean over the orbits of |dH/H0|} from trajectory.csv."""
    sums, counts = collections.defaultdict(float), collections.defaultdict(int)
    with open(series, newline="") as handle:
        for row in csv.DictReader(handle):
            step = int(row["step"])
            sums[step] += abs(float(row["relative_energy_error"]))
            counts[step] += 1
    return {step: sums[step] / counts[step] for step in sorted(sums)}


def fitted_exponent(means, first):
    points = [(math.log(step), math.log(mean)) for step, mean in means.items() if step >= first and mean > 0]
    n = len(points)
    mx = sum(x for x, _ in points) / n
    my = sum(y for _, y in points) / n
    return sum((x - mx) * (y - my) for x, y in points) / sum((x - mx) ** 2 for x, _ in points)


def run(nonsep, folder, name, arguments):
    job_file = os.path.join(folder, name + ".json")
    with open(job_file, "w") as handle:
        json.dump(job(arguments.stages, arguments.dt, arguments.steps, name), handle)
    subprocess.run([nonsep, "run", "--quiet", "--force", "--threads", "1", job_file], check=True)
    return mean_errors(os.path.join(folder, name, "trajectory.csv"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--nonsep-before")
    parser.add_argument("--stages", type=int, default=3)
    parser.add_argument("--dt", type=float, default=0.001)
    parser.add_argument("--steps", type=int, default=10**7)
    parser.add_argument("--csv", help="write step and the mean |dH/H0| of each build here")
    parser.add_argument("--plot", help="draw the means against the steps into this PNG file")
    arguments = parser.parse_args()
    builds = [("this build", arguments.nonsep)]
    if arguments.nonsep_before:
        builds.append(("before", arguments.nonsep_before))
    first = min(10**4, arguments.steps // 100)
    results = {}
    with tempfile.TemporaryDirectory(prefix="nonsep-gauss-roundoff-") as folder:
        for index, (label, nonsep) in enumerate(builds):
            results[label] = run(os.path.abspath(nonsep), folder, f"run{index}", arguments)
    print(f"gauss {arguments.stages} stages, dt = {arguments.dt}, {arguments.steps} steps, 64 paper1d orbits; "
          f"load average {os.getloadavg()[0]:.2f}")
    for label, means in results.items():
        last = means[max(means)]
        print(f"  {label}: mean |dH/H0| at the end {last:.3g}, growth exponent from step {first} on "
              f"{fitted_exponent(means, first):.3f}")
    if arguments.csv:
        with open(arguments.csv, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(["step"] + list(results))
            for step in next(iter(results.values())):
                writer.writerow([step] + [results[label][step] for label in results])
    if arguments.plot:
        plot(results, arguments, first, arguments.plot)


def plot(results, arguments, first, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, axes = plt.subplots(figsize=(6.4, 4.2))
    for label, means in results.items():
        steps = [step for step in means if step > 0]
        axes.loglog(steps, [means[step] for step in steps],
                    label=f"{label} (exponent {fitted_exponent(means, first):.2f})")
    reference = next(iter(results.values()))
    start = min(step for step in reference if step >= first)
    steps = [step for step in reference if step >= first]
    axes.loglog(steps, [reference[start] * (step / start) ** 0.5 for step in steps], "k--", label="sqrt(steps)")
    axes.set_xlabel("steps")
    axes.set_ylabel("mean over 64 orbits of |dH/H0|")
    axes.set_title(f"gauss {arguments.stages} stages, dt = {arguments.dt}, paper1d: round-off in H")
    axes.legend()
    figure.tight_layout()
    figure.savefig(path, dpi=100)


if __name__ == "__main__":
    sys.exit(main())
