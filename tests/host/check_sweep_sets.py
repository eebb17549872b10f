#!/usr/bin/env python3
"""Sweeps whatever their size, checked set by set:

  1. A sweep of one value (a list, {"values": [...]} or a range of count 1) runs to the end like the job without
     a sweep: exit 0, summary.json written, no temporary file left, with one and two threads.
  2. For every shipped plugin (`nonsep models`) and each of its parameters (`nonsep inspect`), a sweep of the one
     default value writes the same files as the run without a sweep: trajectories.csv plus the parameter's column,
     the other files byte for byte, summary.json but for its sweep.
  3. Ranges: 0 to 0.3 in 16 values is accepted by a parameter of maximum 0.3 and writes 0.06 (not
     0.05999999999999999) in the coupling column; 0 to 0.4 in 9 values is refused for 0.35 and 0.4 only; a grid axis
     of count 1 is its `from`.
  4. A sweep that changes the model's dimension (lattice_chain "sites") is refused before anything runs (exit 2),
     naming the swept key and the set, with an energy shell too.
With MPIEXEC: part 1 alone, on two MPI ranks.
Usage: check_sweep_sets.py NONSEP WORKDIR [MPIEXEC]
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

nonsep, work = sys.argv[1], Path(sys.argv[2])
mpiexec = sys.argv[3] if len(sys.argv) > 3 else None
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def write_job(name, job):
    path = work / f"{name}.json"
    path.write_text(json.dumps(job, indent=1))
    return path


def run(args, expected=0, prefix=()):
    r = subprocess.run([*prefix, nonsep, *args], env=env, capture_output=True, text=True, timeout=300)
    check(expected is None or r.returncode == expected,
          f"nonsep {' '.join(args[:2])}...: exit {r.returncode} (expected {expected}) {r.stderr[-400:]}")
    return r


def run_job(name, job, *options, expected=0, prefix=()):
    folder = work / name
    r = run(["run", "-q", *options, "--output", str(folder), str(write_job(name, job))], expected=expected,
            prefix=prefix)
    return folder, r


def files(folder):
    return sorted(p.name for p in folder.iterdir() if p.name != ".nonsep.lock") if folder.is_dir() else []


def without_sweep(summary):
    summary = dict(summary)
    for key in ("sweep", "wall_seconds", "job"):
        summary.pop(key, None)
    summary["model"] = {k: v for k, v in summary["model"].items() if k != "parameters"}
    summary["output"] = {k: v for k, v in summary["output"].items() if k != "directory"}
    return summary


def same_but_column(swept, alone, name, value_text, what):
    """swept's files equal alone's, trajectories.csv with the column `name` (cells value_text) added."""
    check(files(swept) == files(alone), f"{what}: the same files ({files(swept)} / {files(alone)})")
    check(not any(".tmp-" in f for f in files(swept)), f"{what}: no temporary file left")
    for file in files(alone):
        if file == ".nonsep-run.json" or not (swept / file).exists():
            continue
        a, b = (swept / file).read_bytes(), (alone / file).read_bytes()
        if file == "trajectories.csv":
            lines = [line + "\n" for line in a.decode().splitlines()]
            expected = [line + (f",{name}\n" if i == 0 else f",{value_text}\n")
                        for i, line in enumerate(b.decode().splitlines())]
            check(lines == expected, f"{what}: trajectories.csv is the run's with the column {name}")
        elif file == "summary.json":
            sa, sb = json.loads(a), json.loads(b)
            check(without_sweep(sa) == without_sweep(sb) and sa["model"]["parameters"][name] is not None,
                  f"{what}: summary.json the run's but for its sweep")
        else:
            check(a == b, f"{what}: {file} byte for byte")


# 1. The sweep of one value, as the attack ran it: paper2d, mpe 4, one state, no energy shell.
base = {"model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
        "integrator": {"scheme": "mpe", "order": 4},
        "initial": {"q": [0.5, 0.1], "p": [0.2, -0.1]},
        "time": {"dt": 0.01, "steps": 200}, "output": {"every": 50}}
alone, _ = run_job("alone", base)
for label, value in (("list", [0.2]), ("values", {"values": [0.2]}), ("range", {"from": 0.2, "to": 0.3, "count": 1})):
    job = dict(base, model={"plugin": "paper2d", "parameters": {"coupling": value}})
    r = run(["validate", str(write_job(f"one_{label}", job))])
    check("(1 value): 1 parameter set x 1 state = 1 trajectory" in r.stdout, f"validate names a one-value sweep: {r.stdout}")
    for threads in ("1", "2"):
        if mpiexec:
            folder, r = run_job(f"one_{label}_ranks", job, "--threads", "1", prefix=(mpiexec, "-n", "2"))
            what = f"one value ({label}), two MPI ranks"
        else:
            folder, r = run_job(f"one_{label}_{threads}", job, "--threads", threads)
            what = f"one value ({label}), {threads} threads"
        check((folder / "summary.json").exists(), f"{what}: summary.json written")
        same_but_column(folder, alone, "coupling", "0.2", what)
        if mpiexec:
            break
if mpiexec:
    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    sys.exit(1 if failures else 0)

# 2. Every shipped plugin, every parameter: a sweep of its default value.
shipped = {p.name for p in (Path(__file__).resolve().parents[2] / "plugins").iterdir() if p.is_dir()} - {"sdk"}
models = {}
for line in run(["models"]).stdout.splitlines():
    words = line.split()
    if len(words) > 3 and words[0] in shipped and words[2] == "dimension":
        models[words[0]] = words[4] if words[3] == "parameter" else int(words[3])
check(set(models) == shipped, f"nonsep models lists every shipped plugin ({sorted(models)})")
for plugin, dimension in sorted(models.items()):
    parameters = {}  # name -> default value
    in_table = False
    report = run(["inspect", plugin]).stdout
    if "  parameters:  none" in report:
        print(f"{plugin} has no parameters to sweep")
        continue
    for line in report.splitlines():
        words = line.split()
        if line.startswith("  parameters:"):
            in_table = True
        elif in_table and line.startswith("    ") and words and words[0] != "name":
            parameters[words[0]] = json.loads(words[2])
        elif not line.startswith("    "):
            in_table = False
    if isinstance(dimension, str):
        dimension = int(parameters[dimension])
    check(bool(parameters), f"{plugin}: parameters read from nonsep inspect ({parameters})")
    job = {"model": {"plugin": plugin},
           "integrator": {"scheme": "mpe", "order": 4},
           "initial": [{"q": [0.3 + 0.05 * i + 0.1 * k for i in range(dimension)],
                        "p": [0.2 - 0.03 * i + 0.05 * k for i in range(dimension)]} for k in range(3)],
           "time": {"dt": 0.01, "steps": 40}, "output": {"every": 10}, "analysis": {"megno": True}}
    own, _ = run_job(f"{plugin}_alone", job, expected=None)
    for name, default in parameters.items():
        swept = dict(job, model={"plugin": plugin, "parameters": {name: [default]}})
        folder, _ = run_job(f"{plugin}_{name}", swept, expected=None)
        text = json.dumps(default) if isinstance(default, int) else repr(float(default))
        same_but_column(folder, own, name, text, f"{plugin}, a sweep of {name} = {text}")

# 3. Ranges.
fine = dict(base, model={"plugin": "paper2d", "parameters": {"coupling": {"from": 0.0, "to": 0.3, "count": 16}}},
            output={"every": 0}, time={"dt": 0.01, "steps": 10})
folder, _ = run_job("range_fine", fine)
table = folder / "trajectories.csv"
cells = [line.rsplit(",", 1)[1] for line in table.read_text().splitlines()[1:]] if table.exists() else []
check(len(cells) == 16 and cells[3] == "0.06" and cells[-1] == "0.3",
      f"0 to 0.3 in 16 values: 0.06 and 0.3 as written, accepted by a maximum of 0.3 ({cells})")
beyond = dict(fine, model={"plugin": "paper2d", "parameters": {"coupling": {"from": 0.0, "to": 0.4, "count": 9}}})
r = run(["validate", str(write_job("range_beyond", beyond))], expected=2)
check("value 7 of the range" in r.stderr and "value 8 of the range" in r.stderr and "value 6" not in r.stderr
      and "0.30000000000000004" not in r.stderr, f"0 to 0.4 in 9 values: 0.35 and 0.4 refused, 0.3 not: {r.stderr}")
one_point = {"model": {"plugin": "paper1d"}, "integrator": {"scheme": "triplet"},
             "initial": {"grid": {"q": [{"from": 2, "to": 3, "count": 1}], "p": [0]}},
             "time": {"dt": 0.01, "steps": 10}, "output": {"every": 0}}
folder, _ = run_job("axis_count_1", one_point)
table = folder / "trajectories.csv"
row = table.read_text().splitlines()[1].split(",") if table.exists() else []
check(row[1:2] == ["completed"], f"a grid axis of count 1 is its from (q0 = 2), not NaN: {row}")

# 4. A sweep that changes the dimension, refused before anything runs.
chain = {"model": {"plugin": "lattice_chain", "parameters": {"sites": [4, 64]}},
         "integrator": {"scheme": "mpe", "order": 4},
         "initial": {"q": [0.1, 0.2, 0.3, 0.4], "p": [0.1, 0.0, 0.0, 0.0]},
         "time": {"dt": 0.01, "steps": 10}}
shell = dict(chain, initial={"grid": {"q": [{"from": 0.1, "to": 0.3, "count": 3}, 0.2, 0.3, 0.4],
                                      "p": [0.0, 0.0, 0.0, 0.0]}, "energy": 2.0, "solve_for": "p0"})
for label, job in (("no shell", chain), ("energy shell", shell)):
    path = write_job(f"dimension_{label.replace(' ', '_')}", job)
    for command in ("validate", "run"):
        folder = work / f"dimension_{label.replace(' ', '_')}.out"
        r = run([command, *(["--output", str(folder)] if command == "run" else []), str(path)], expected=2)
        check("/model/parameters/sites" in r.stderr and "set 1 of the sweep" in r.stderr
              and "unexpected" not in r.stderr,
              f"{label}: {command} refuses a sweep of the dimension, naming the key and the set: {r.stderr}")
        check(not folder.exists() or not any(folder.iterdir()), f"{label}: {command} wrote nothing")

for failure in failures:
    print(f"FAIL {failure}", file=sys.stderr)
sys.exit(1 if failures else 0)
