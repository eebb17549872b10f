#!/usr/bin/env python3
"""A model given by H(q, p) against the same Hamiltonian in product form (docs/models-given-by-h.md, "Speed").

paper1d's H = (1 + p^2/2)^2 (1 + q^2) as the shipped product-form plugin paper1d (T = p + p^3/6,
V = q^2/2 + q^4/12, H = T'(p)^2 V''(q)) and as the formula model {"H": "(1 + p0^2/2)^2*(1 + q0^2)"}, compiled by the
host into a model given by H (NONSEP_EXPORT_HAMILTONIAN, its gradient written out from the formula), in one run of
this script with a cache folder of its own:
  first compile   CPU time (user + sys of the nonsep process and the compiler it runs) and wall time of the first
                  formula run with an empty cache
  per step        CPU time of 1024 orbits (q0 = 0.2 + 1.8 j/1024, p0 = 0), gauss 3 stages, dt = 0.01, --steps steps,
                  one thread: the median of the ratios H / product form of --repeats alternating pairs
The machine's load average is printed with the numbers: other work on the machine widens the spread.

Usage: python3 bench/given_by_h.py --nonsep build/bin/nonsep [--repeats 5] [--steps 2000]
"""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

from formula_model import spread, write  # the same bench folder

FORMULA = {"name": "paper1d_as_h", "H": "(1 + p0^2/2)^2*(1 + q0^2)"}


def job(model, steps, output):
    initial = [{"q": [0.2 + 1.8 * j / 1024], "p": [0.0]} for j in range(1024)]
    return {"model": model, "integrator": {"scheme": "gauss", "stages": 3}, "initial": initial,
            "time": {"dt": 0.01, "steps": steps}, "output": {"directory": output, "every": 0}}


def timed_run(nonsep, job_file, environment):
    """(CPU seconds of the children, wall seconds) of one run."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    result = subprocess.run([nonsep, "run", "--quiet", "--force", "--threads", "1", job_file],
                            capture_output=True, text=True, env=environment, check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if result.returncode != 0:
        sys.exit(f"nonsep run {job_file} failed ({result.returncode}):\n{result.stderr}")
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, wall


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=2000)
    arguments = parser.parse_args()
    nonsep = os.path.abspath(arguments.nonsep)
    with tempfile.TemporaryDirectory(prefix="nonsep-given-by-h-bench-") as folder:
        environment = dict(os.environ, NONSEP_CACHE_DIR=os.path.join(folder, "cache"))
        general = write(folder, "general.json", job({"formula": FORMULA}, arguments.steps, "g"))
        product = write(folder, "product.json", job({"plugin": "paper1d"}, arguments.steps, "p"))
        print(f"load average before: {os.getloadavg()}")
        first = write(folder, "first.json", job({"formula": FORMULA}, 1, "f"))
        cpu, wall = timed_run(nonsep, first, environment)
        print(f"first compile (a run of one step with an empty cache): {cpu:.2f} s CPU, {wall:.2f} s wall")
        times = {"general": [], "product": []}
        for _ in range(arguments.repeats):
            times["general"].append(timed_run(nonsep, general, environment)[0])
            times["product"].append(timed_run(nonsep, product, environment)[0])
        ratios = [g / p for g, p in zip(times["general"], times["product"])]
        print(f"1024 orbits x {arguments.steps} steps, gauss 3, 1 thread, CPU s: given by H {spread(times['general'])};"
              f" product form {spread(times['product'])}; given by H / product form: {spread(ratios)} (of pairs)")
        print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
