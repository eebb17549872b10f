#!/usr/bin/env python3
"""Formula models against the hand-written plugin of the same H (docs/formula-models.md, "Measured").

The formula twin of the shipped paper1d plugin (T = p0 + p0^3/6, V = q0^2/2 + q0^4/12) against paper1d itself, in
one run of this script, with a cache folder of its own:
  first compile   wall time of the first formula run with an empty cache (the host's "compiled in" line), and of
                  the same source compiled with all three kernel sets (what a shipped plugin carries), for the
                  trade-off of compiling one wide set only
  cached run      wall time of a 10-step run, formula (from the cache) minus plugin: medians of 11, alternating
  per step        wall time of 64 states x 200000 steps on one thread, formula over plugin: the median of the
                  ratios of 5 alternating pairs (pairs, so that a change of the machine's load between pairs cancels)
The machine's load average is printed with the numbers: other work on the machine widens the spread.

Usage: python3 bench/formula_model.py --nonsep build/bin/nonsep [--repeats 5] [--steps 200000]
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

FORMULA = {"name": "paper1d_formula", "T": "p0 + p0^3/6", "V": "q0^2/2 + q0^4/12"}


def job(model, states, steps, output):
    initial = [{"q": [0.1 + 1.5 * i / states], "p": [0.2]} for i in range(states)]
    return {"model": model, "integrator": {"scheme": "triplet", "order": "4/3", "t2": -2.0},
            "initial": initial, "time": {"dt": 0.001, "steps": steps},
            "output": {"directory": output, "every": 0}}


def timed_run(nonsep, job_file, environment):
    start = time.perf_counter()
    result = subprocess.run([nonsep, "run", "--quiet", "--force", "--threads", "1", job_file],
                            capture_output=True, text=True, env=environment, check=False)
    seconds = time.perf_counter() - start
    if result.returncode != 0:
        sys.exit(f"nonsep run {job_file} failed ({result.returncode}):\n{result.stderr}")
    return seconds, result.stderr


def write(folder, name, content):
    path = os.path.join(folder, name)
    with open(path, "w", encoding="utf-8") as file:
        json.dump(content, file)
    return path


def spread(values):
    return f"median {statistics.median(values):.4g}, min {min(values):.4g}, max {max(values):.4g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=200000)
    arguments = parser.parse_args()
    nonsep = os.path.abspath(arguments.nonsep)
    with tempfile.TemporaryDirectory(prefix="nonsep-formula-bench-") as folder:
        environment = dict(os.environ, NONSEP_CACHE_DIR=os.path.join(folder, "cache"))
        formula_model = {"formula": FORMULA}
        plugin_model = {"plugin": "paper1d"}
        small_formula = write(folder, "small_formula.json", job(formula_model, 1, 10, "sf"))
        small_plugin = write(folder, "small_plugin.json", job(plugin_model, 1, 10, "sp"))
        print(f"load average before: {os.getloadavg()}")

        seconds, stderr = timed_run(nonsep, small_formula, environment)
        compiled = re.search(r"compiled in ([0-9.]+) s", stderr)
        print(f"first compile: the run took {seconds:.2f} s, of which the compile {compiled.group(1)} s "
              f"(kernels: baseline and {os.environ.get('NONSEP_INSTRUCTION_SET', 'the widest this processor runs')})")
        source = subprocess.run([nonsep, "model", "compile", write(folder, "model.json", FORMULA), "--print-source"],
                                capture_output=True, text=True, check=True).stdout
        toolchain_file = os.path.join(os.path.dirname(nonsep), "..", "share", "nonsep", "formula", "toolchain.json")
        with open(toolchain_file, encoding="utf-8") as file:
            toolchain = json.load(file)
        with open(os.path.join(folder, "all_sets.cpp"), "w", encoding="utf-8") as file:
            file.write(source)
        includes = [f"-I{os.path.join(os.path.dirname(toolchain_file), d)}" for d in toolchain["include_directories"]]
        start = time.perf_counter()
        subprocess.run([toolchain["compiler"], *toolchain["flags"], "-DNONSEP_SDK_WIDE_KERNEL_SETS=3", *includes,
                        "-o", os.path.join(folder, "all_sets.so"), os.path.join(folder, "all_sets.cpp")], check=True)
        print(f"the same source with all three kernel sets: {time.perf_counter() - start:.2f} s")

        small = {"formula": [], "plugin": []}
        for _ in range(11):
            small["formula"].append(timed_run(nonsep, small_formula, environment)[0])
            small["plugin"].append(timed_run(nonsep, small_plugin, environment)[0])
        overhead = statistics.median(small["formula"]) - statistics.median(small["plugin"])
        print(f"cached run, 10 steps: formula {spread(small['formula'])} s; plugin {spread(small['plugin'])} s; "
              f"overhead {overhead * 1000:.1f} ms")

        big_formula = write(folder, "big_formula.json", job(formula_model, 64, arguments.steps, "bf"))
        big_plugin = write(folder, "big_plugin.json", job(plugin_model, 64, arguments.steps, "bp"))
        big = {"formula": [], "plugin": []}
        for _ in range(arguments.repeats):
            big["formula"].append(timed_run(nonsep, big_formula, environment)[0])
            big["plugin"].append(timed_run(nonsep, big_plugin, environment)[0])
        ratios = [f / p for f, p in zip(big["formula"], big["plugin"])]
        print(f"64 states x {arguments.steps} steps, 1 thread: formula {spread(big['formula'])} s; plugin "
              f"{spread(big['plugin'])} s; time per step formula/plugin: {spread(ratios)} (of pairs)")
        print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
