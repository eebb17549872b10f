#!/usr/bin/env python3
"""Runs the example jobs with a built `nonsep` and writes a manifest of their outputs' hashes.

Usage: scripts/check_example_outputs.py NONSEP WORK_FOLDER MANIFEST [--compare EARLIER_MANIFEST]

Every job in examples/jobs, examples/dynamics and examples/paper is copied into WORK_FOLDER/jobs (the long ones
shortened, see SHORTENED) together with a few jobs of its own (EXTRA: the comparator schemes, HDF5 output,
Lyapunov/MEGNO/Poincare observers, an energy bound that retires trajectories, a checkpoint policy), run with
`nonsep run -q JOB -o WORK_FOLDER/out/NAME`, and every output file is hashed. What legitimately differs from run
to run is left out before hashing: in JSON files the keys ending in "seconds", "job", "path" and "directory"
(wall time, where the job and the plugin are); in CSV files the columns "wall_seconds" and "repeats" of
work_precision.csv (measured times); .nonsep.lock (a process id) is left out; HDF5 files are dumped with h5dump (attributes and data, not the file's
byte layout; the same keys left out of its summary attribute) when h5dump is installed, and hashed as bytes otherwise.

A refactoring that changes no behaviour leaves the manifest byte for byte the same: with --compare the script
exits with status 1 and lists the files whose hashes differ.
"""
import argparse
import copy
import csv
import hashlib
import io
import json
import pathlib
import shutil
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
FOLDERS = ["examples/jobs", "examples/dynamics", "examples/paper"]

# Jobs that take longer than a few seconds, shortened: the keys given replace the job's own.
SHORTENED = {
    # 10^5 periods: 10^8 steps; the first 100 periods keep its every / energy_every strides meaningful.
    "mathews_lakshmanan_long": {"time": {"dt": 0.008944568181778066, "t_end": 915.923781814074},
                                "output": {"every": 10240, "energy_every": 1000}},
    # a 61 x 61 grid to t = 100: a 9 x 9 grid to t = 10 with the same analyses
    "chaos_map": {"initial": {"grid": {"q": [{"from": -1.6, "to": 1.6, "count": 9}, 0.0],
                                       "p": [{"from": -1.8, "to": 1.8, "count": 9}, 0.0]},
                              "energy": 7.0, "solve_for": "p1"},
                  "time": {"dt": 0.005, "t_end": 10}, "output": {"every": 2000}},
    # a 13 x 13 grid to t = 2000: a 5 x 5 grid to t = 200
    "poincare_portrait": {"initial": {"grid": {"q": [{"from": -1.6, "to": 1.6, "count": 5}, 0.0],
                                               "p": [{"from": -1.8, "to": 1.8, "count": 5}, 0.0]},
                                      "energy": 7.0, "solve_for": "p1"},
                          "time": {"dt": 0.005, "t_end": 200}},
    # the shell H = 8 over 31 and 11 couplings to t = 100: 4 couplings, 5 starting points (5 x 5) to t = 10
    "stability_map_shell8": {"model": {"plugin": "paper2d",
                                       "parameters": {"coupling": {"from": 0.0, "to": 0.3, "count": 4}}},
                             "initial": {"grid": {"q": [{"from": -2.2, "to": 2.2, "count": 5}, 0.0], "p": [0.0, 0.0]},
                                         "energy": 8.0, "solve_for": "p1"},
                             "time": {"dt": 0.02, "t_end": 10}, "output": {"every": 500}},
    "chaotic_fraction": {"model": {"plugin": "paper2d",
                                   "parameters": {"coupling": {"from": 0.0, "to": 0.3, "count": 4}}},
                         "initial": {"grid": {"q": [{"from": -2.1, "to": 2.1, "count": 5}, 0.0],
                                              "p": [{"from": -1.8, "to": 1.8, "count": 5}, 0.0]},
                                     "energy": 8.0, "solve_for": "p1"},
                         "time": {"dt": 0.02, "t_end": 10}, "output": {"every": 500}},
    # models given by H itself: a 16 x 16 grid to t = 500, tau = 10000: shorter
    "magnetic_bottle_chaos_map": {"initial": {"grid": {"q": [{"from": 0.2, "to": 2.0, "count": 4}, 0.0, 0.0],
                                                       "p": [0.0, {"from": -1.0, "to": 1.0, "count": 4}, 0.5]}},
                                  "time": {"dt": 0.02, "t_end": 20}},
    "schwarzschild_charged_orbit": {"time": {"dt": 1.0, "t_end": 500}},
}

QUICK = {"model": {"plugin": "paper1d"}, "hamiltonian": "TTV",
         "initial": [{"q": [2.0], "p": [0.0]}, {"q": [1.0], "p": [0.3]}],
         "time": {"dt": 0.01, "t_end": 2.0}, "output": {"every": 7}}


def quick(**changes):
    job = copy.deepcopy(QUICK)
    job.update(changes)
    return job


# Jobs of this script's own, for what the examples do not reach: each scheme, each observer, each format.
EXTRA = {
    "extra_tao2": quick(integrator={"scheme": "tao", "order": "2"}),
    "extra_tao4_hdf5": quick(integrator={"scheme": "tao", "order": "4", "omega": 10},
                             output={"every": 5, "format": "hdf5"}),
    "extra_tao6": quick(integrator={"scheme": "tao", "order": "6"}, output={"every": 0, "energy_every": 3}),
    "extra_midpoint": quick(integrator={"scheme": "implicit_midpoint"}),
    "extra_gauss3": quick(integrator={"scheme": "gauss", "stages": 3}),
    "extra_mpe_hdf5": quick(integrator={"scheme": "mpe", "order": "2"}, output={"every": 3, "format": "hdf5"}),
    "extra_basic_bound": quick(integrator={"scheme": "basic", "t2": -2.0}, time={"dt": 0.05, "t_end": 2.0},
                               analysis={"max_relative_energy_error": 0.01, "closest_return_after": 0.5}),
    "extra_triplet_checkpoint": quick(integrator={"scheme": "triplet", "order": "2"},
                                      checkpoint={"every_steps": 50}),
    "extra_lyapunov": {"model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
                       "integrator": {"scheme": "triplet", "order": "4/3"},
                       "initial": [{"q": [0.5, 0.0], "p": [0.0, 1.0]}, {"q": [1.0, 0.0], "p": [0.3, 1.2]}],
                       "time": {"dt": 0.01, "t_end": 20}, "output": {"every": 100},
                       "analysis": {"lyapunov": {"vectors": 2, "renormalize_every": 5, "every": 200},
                                    "megno": True,
                                    "poincare": {"component": "q1", "value": 0.0, "direction": "+",
                                                 "max_crossings": 5}}},
    "extra_lyapunov_hdf5": {"model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
                            "integrator": {"scheme": "mpe", "order": "4/3"},
                            "initial": [{"q": [0.5, 0.0], "p": [0.0, 1.0]}],
                            "time": {"dt": 0.01, "t_end": 20}, "output": {"every": 100, "format": "hdf5"},
                            "analysis": {"lyapunov": {"vectors": 1, "every": 300}, "megno": True,
                                         "poincare": {"component": "q1", "value": 0.0, "max_crossings": 3}}},
    "extra_lattice_study": {"model": {"plugin": "lattice_chain"},
                            "initial": {"q": [0.1 * ((i % 5) - 2) for i in range(16)],
                                        "p": [0.05 * ((i % 3) - 1) for i in range(16)]},
                            "time": {"t_end": 0.5},
                            "study": {"integrators": [{"scheme": "basic", "steps": [64, 128, 256]},
                                                      {"scheme": "tao", "order": "4", "steps": [16, 32, 64]},
                                                      {"scheme": "gauss", "stages": 2, "steps": [8, 16, 32]}]}},
}

VOLATILE_KEY_ENDINGS = ("seconds", "job", "path", "directory")
VOLATILE_COLUMNS = {"wall_seconds", "repeats"}
SKIPPED_FILES = {".nonsep.lock"}  # the process id of the run


def scrub(value):
    if isinstance(value, dict):
        return {k: scrub(v) for k, v in value.items() if not k.endswith(VOLATILE_KEY_ENDINGS)}
    if isinstance(value, list):
        return [scrub(v) for v in value]
    return value


def normalised(path):
    data = path.read_bytes()
    if path.suffix == ".json":
        return json.dumps(scrub(json.loads(data)), sort_keys=True).encode()
    if path.suffix == ".csv":
        rows = list(csv.reader(io.StringIO(data.decode())))
        if rows and VOLATILE_COLUMNS & set(rows[0]):
            keep = [i for i, name in enumerate(rows[0]) if name not in VOLATILE_COLUMNS]
            out = io.StringIO()
            csv.writer(out, lineterminator="\n").writerows([[row[i] for i in keep if i < len(row)] for row in rows])
            return out.getvalue().encode()
        return data
    if path.suffix == ".h5" and shutil.which("h5dump"):
        dump = subprocess.run(["h5dump", path.name], cwd=path.parent, capture_output=True, check=True).stdout
        # summary.json is an attribute of the file, as text: its volatile keys are left out line by line
        volatile = tuple(f'"{key}'.encode() for key in ("wall_seconds", "job", "path", "directory"))
        return b"\n".join(line for line in dump.splitlines() if not line.strip().startswith(volatile))
    return data


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("nonsep")
    parser.add_argument("work")
    parser.add_argument("manifest")
    parser.add_argument("--compare")
    args = parser.parse_args()
    work = pathlib.Path(args.work).resolve()
    shutil.rmtree(work, ignore_errors=True)
    (work / "jobs").mkdir(parents=True)
    jobs = {}
    for folder in FOLDERS:
        for path in sorted((ROOT / folder).glob("*.json")):
            job = json.loads(path.read_text())
            job.pop("$schema", None)
            job.update(SHORTENED.get(path.stem, {}))
            jobs[path.stem] = job
    jobs.update(EXTRA)
    lines = []
    for name, job in jobs.items():
        job_file = work / "jobs" / f"{name}.json"
        job_file.write_text(json.dumps(job, indent=1))
        out = work / "out" / name
        result = subprocess.run([args.nonsep, "run", "-q", "-j", "2", str(job_file), "-o", str(out)],
                                capture_output=True, text=True)
        lines.append(f"{name} exit {result.returncode}")
        if result.returncode not in (0, 1):
            sys.stderr.write(f"{name}: exit {result.returncode}\n{result.stderr}")
        for file in sorted(p for p in out.rglob("*") if p.is_file() and p.name not in SKIPPED_FILES):
            digest = hashlib.sha256(normalised(file)).hexdigest()
            lines.append(f"{name}/{file.relative_to(out)} {digest}")
    pathlib.Path(args.manifest).write_text("\n".join(lines) + "\n")
    if args.compare:
        before = pathlib.Path(args.compare).read_text().splitlines()
        if before != lines:
            for line in sorted(set(before) ^ set(lines)):
                print(("- " if line in before else "+ ") + line)
            return 1
        print(f"{len(lines)} lines, the same as {args.compare}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
