#!/usr/bin/env python3
"""Automatic derivatives against the formula twin and the hand-written plugin: MEGNO with Gauss-Legendre.

One H, paper2d's (T = p1 + p2 + (p1^3 + p2^3)/6, V = |q|^2/2 + |q|^4/12 + 0.2 q1^2 q2^2), three ways:
  autodiff   bench/paper2d_autodiff.cpp: every derivative by the SDK's dual numbers over T and V (a plugin written
             with templated T and V only; built with the benchmarks, -DNONSEP_BUILD_BENCHMARKS=ON)
  formula    the formula twin in the job (its gradients written from the formulas, higher derivatives by duals
             over them), compiled first into a cache folder of this run
  shipped    plugins/paper2d: gradients, Hessian-vector products and third derivatives written by hand
The job: 256 orbits q = (0.1 + 0.5 j/256, 0.2), p = (0, 1), Gauss-Legendre 3 stages, dt 0.02, 2000 steps, one
thread, MEGNO (one tangent vector), and the same without MEGNO (the stepping alone). User CPU time of each run
(getrusage of the child), rounds alternating the six runs; printed: medians with min and max, and the median over
rounds of each run's ratio to the formula twin's in the same round (so that a change of the machine's speed between
rounds cancels). The three mean MEGNO must agree (to 1e-10): else the script fails.

Usage: python3 bench/autodiff_megno.py --build build [--rounds 5]
"""
import argparse
import csv
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile

FORMULA = {"name": "paper2d_formula", "T": "p0 + p1 + (p0^3 + p1^3)/6",
           "V": "(q0^2 + q1^2)/2 + (q0^2 + q1^2)^2/12 + coupling*q0^2*q1^2",
           "parameters": {"coupling": {"value": 0.2, "min": -0.1, "max": 0.3}}}


def job(model, megno, output):
    initial = [{"q": [0.1 + 0.5 * j / 256, 0.2], "p": [0.0, 1.0]} for j in range(256)]
    content = {"model": model, "integrator": {"scheme": "gauss", "stages": 3}, "initial": initial,
               "time": {"dt": 0.02, "steps": 2000}, "output": {"directory": output, "every": 2000}}
    if megno:
        content["analysis"] = {"megno": True}
    return content


def user_seconds(nonsep, job_file, environment):
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    result = subprocess.run([nonsep, "run", "--quiet", "--force", "--threads", "1", job_file],
                            capture_output=True, text=True, env=environment, check=False)
    if result.returncode != 0:
        sys.exit(f"nonsep run {job_file} failed ({result.returncode}):\n{result.stderr}")
    return resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before


def mean_megno(folder):
    with open(os.path.join(folder, "trajectories.csv"), encoding="utf-8") as file:
        rows = [row for row in csv.DictReader(file) if row["step"] == "2000"]
    return statistics.fmean(float(row["mean_megno"]) for row in rows)


def spread(values):
    return f"median {statistics.median(values):.3f} [{min(values):.3f}, {max(values):.3f}]"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", required=True, help="the build folder (benchmarks on)")
    parser.add_argument("--rounds", type=int, default=5)
    arguments = parser.parse_args()
    build = os.path.abspath(arguments.build)
    nonsep = os.path.join(build, "bin", "nonsep")
    autodiff = os.path.join(build, "bench", "plugins", "paper2d_autodiff.so")
    if not os.path.exists(autodiff):
        sys.exit(f"{autodiff} is missing: configure with -DNONSEP_BUILD_BENCHMARKS=ON and build")
    models = {"formula": {"formula": FORMULA}, "autodiff": {"plugin": autodiff, "parameters": {"coupling": 0.2}},
              "shipped": {"plugin": "paper2d", "parameters": {"coupling": 0.2}}}
    with tempfile.TemporaryDirectory(prefix="nonsep-autodiff-bench-") as folder:
        environment = dict(os.environ, NONSEP_CACHE_DIR=os.path.join(folder, "cache"))
        runs = {}
        for name, model in models.items():
            for megno in (True, False):
                label = f"{name}{' megno' if megno else ''}"
                path = os.path.join(folder, label.replace(" ", "_") + ".json")
                with open(path, "w", encoding="utf-8") as file:
                    json.dump(job(model, megno, os.path.join(folder, label.replace(" ", "_") + ".out")), file)
                runs[label] = path
        user_seconds(nonsep, runs["formula"], environment)  # the compile, not measured
        print(f"load average before: {os.getloadavg()}")
        times = {label: [] for label in runs}
        for _ in range(arguments.rounds):
            for label, path in runs.items():
                times[label].append(user_seconds(nonsep, path, environment))
        for label in runs:
            reference = times["formula megno" if "megno" in label else "formula"]
            ratios = [t / r for t, r in zip(times[label], reference)]
            print(f"{label:16s} user CPU {spread(times[label])} s; over the formula twin {spread(ratios)}")
        print(f"load average after: {os.getloadavg()}")
        means = {name: mean_megno(os.path.join(folder, f"{name}_megno.out")) for name in models}
        print("mean <Y> over the orbits: " + ", ".join(f"{name} {value:.15f}" for name, value in means.items()))
        if max(means.values()) - min(means.values()) > 1e-10:
            sys.exit("the three models' mean MEGNO differ by more than 1e-10")


if __name__ == "__main__":
    main()
