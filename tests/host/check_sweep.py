#!/usr/bin/env python3
"""Parameter sweeps (/model/parameters given as several values), run as a user runs them:

  1. A sweep of 31 couplings x 31 states of paper2d on the energy shell H = 7 (placed per coupling), with samples,
     Poincare crossings, Lyapunov and MEGNO series, closest returns and an energy bound, writes every file byte for byte with one and
     two threads; each coupling's rows of trajectories.csv, trajectory.csv, poincare.csv and lyapunov.csv equal
     byte for byte those of the separate run with that coupling (the trajectory number shifted, the coupling column
     dropped); killed (SIGKILL) after a checkpoint and resumed, it writes the same files as uninterrupted.
  2. With MPIEXEC: `mpirun -n 2` writes the same files as one process (summary.json but for wall_seconds and the
     output folder).
  3. Every scheme of the catalogue (`nonsep schema`): a small sweep of two parameters equals its separate runs.
  4. `nonsep validate` names the trajectories a sweep makes; a swept value outside the plugin's range is refused
     (exit 2) naming the value and where it is; a sweep in a study is refused.
Usage: check_sweep.py NONSEP WORKDIR [MPIEXEC]
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

nonsep, work = sys.argv[1], Path(sys.argv[2])
mpiexec = sys.argv[3] if len(sys.argv) > 3 else None
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
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
    r = subprocess.run([*prefix, nonsep, *args], env=env, capture_output=True, text=True, timeout=600)
    check(expected is None or r.returncode == expected, f"nonsep {' '.join(args[:2])}...: exit {r.returncode} (expected {expected}) "
          f"{r.stderr[-400:]}")
    return r


def same_files(a, b, what, other_job=False):
    def files(folder):
        return sorted(p.name for p in folder.iterdir() if p.is_file() and p.name[0] != "." and p.name != "checkpoint.json")
    names, other = files(a), files(b)
    check(names == other, f"{what}: the same files ({names} / {other})")
    for name in names:
        if name == "summary.json":
            skip = ('"wall_seconds"', '"directory"') + (('"job"',) if other_job else ())
            text = [[line for line in (d / name).read_text().splitlines() if not any(s in line for s in skip)]
                    for d in (a, b)]
            check(text[0] == text[1], f"{what}: summary.json byte for byte but for {', '.join(skip)}")
        else:
            check((a / name).read_bytes() == (b / name).read_bytes(), f"{what}: {name} byte for byte")


def rows(path):
    lines = path.read_text().splitlines()
    return lines[0], lines[1:]


def split_index(line):
    index, rest = line.split(",", 1)
    return int(index), rest


# 1. The sweep of 31 x 31 against the separate runs, threads, and a kill.
COUPLINGS = {"from": -0.1, "to": 0.3, "count": 31}
big = {
    "model": {"plugin": "paper2d", "parameters": {"coupling": COUPLINGS}},
    "integrator": {"scheme": "mpe", "order": 4},
    "initial": {"grid": {"q": [{"from": -1.5, "to": 1.5, "count": 31}, 0.0], "p": [0.0, 0.0]},
                "energy": 7.0, "solve_for": "p1"},
    "time": {"dt": 0.01, "steps": 300},
    "output": {"every": 100, "energy_every": 50},
    "analysis": {"poincare": {"component": "q1", "value": 0.0, "direction": "+", "max_crossings": 4},
                 "lyapunov": {"vectors": 2, "renormalize_every": 10, "every": 100}, "megno": True,
                 "max_relative_energy_error": 1e-4, "closest_return_after": 1.0},
}
sweep_file = write_job("sweep", big)
r = run(["validate", str(sweep_file)])
check("31 parameter sets x 31 states" in r.stdout and "coupling (31 values)" in r.stdout,
      f"validate names the sweep: {r.stdout}")
one = work / "one_thread"
start = time.monotonic()
r = run(["run", "-q", "--threads", "1", "--output", str(one), str(sweep_file)], expected=None)
seconds = time.monotonic() - start
summary = json.loads((one / "summary.json").read_text())
check(r.returncode in (0, 1), f"the sweep ran: exit {r.returncode} {r.stderr[-300:]}")
couplings = summary["model"]["parameters"]["coupling"]
check(len(couplings) == 31 and summary["sweep"]["parameter_sets"] == 31, "summary.json says what was swept")
print(f"the sweep of {summary['trajectories']} trajectories took {seconds:.2f} s on one thread")

# 2. MPI ranks (only this with MPIEXEC).
if mpiexec:
    ranks = work / "ranks"
    run(["run", "-q", "--output", str(ranks), str(sweep_file)], expected=r.returncode, prefix=(mpiexec, "-n", "2"))
    same_files(one, ranks, "two MPI ranks / one process")
    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    sys.exit(1 if failures else 0)

two = work / "two_threads"
run(["run", "-q", "--threads", "2", "--output", str(two), str(sweep_file)], expected=r.returncode)
same_files(one, two, "one thread / two threads")

header, sweep_rows = rows(one / "trajectories.csv")
check(header.endswith(",coupling"), f"trajectories.csv has the coupling as its last column: {header}")
offset = 0
for k, coupling in enumerate(couplings):
    single = dict(big, model={"plugin": "paper2d", "parameters": {"coupling": coupling}})
    folder = work / f"separate{k}"
    run(["run", "-q", "--output", str(folder), str(write_job(f"separate{k}", single))], expected=None)
    own_header, own = rows(folder / "trajectories.csv")
    count = len(own)
    mine = sweep_rows[offset:offset + count]
    ok = own_header + ",coupling" == header and len(mine) == count
    for line, own_line in zip(mine, own):
        index, rest = split_index(line)
        own_index, own_rest = split_index(own_line)
        cells, value = rest.rsplit(",", 1)
        ok = ok and index == offset + own_index and cells == own_rest and float(value) == coupling
    for name in ("trajectory.csv", "poincare.csv", "lyapunov.csv"):
        _, theirs = rows(folder / name)
        _, all_rows = rows(one / name)
        shifted = [f"{i + offset},{rest}" for i, rest in map(split_index, theirs)]
        ok = ok and [line for line in all_rows if offset <= split_index(line)[0] < offset + count] == shifted
    check(ok, f"coupling {coupling}: the sweep's {count} rows equal the separate run's in every file")
    offset += count
check(offset == len(sweep_rows), f"the separate runs account for every trajectory ({offset} of {len(sweep_rows)})")

killed = work / "killed"
checkpointed = dict(big, checkpoint={"every_steps": 10, "every_seconds": 0})
checkpoint_file = write_job("checkpointed", checkpointed)
process = subprocess.Popen([nonsep, "run", "-q", "--threads", "2", "--output", str(killed), str(checkpoint_file)],
                           env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
step = None
deadline = time.monotonic() + 120
while time.monotonic() < deadline and process.poll() is None:
    try:
        step = json.loads((killed / "checkpoint.json").read_text())["step"]
        if step >= 20:
            break
    except (OSError, ValueError, KeyError):
        pass
    time.sleep(0.01)
process.send_signal(signal.SIGKILL)
process.wait()
check(process.returncode == -signal.SIGKILL and step is not None and step < 300,
      f"killed mid-run (exit {process.returncode}, checkpoint at step {step})")
run(["run", "-q", "--resume", "--threads", "1", "--output", str(killed), str(checkpoint_file)], expected=r.returncode)
same_files(one, killed, "killed and resumed / uninterrupted", other_job=True)


# 3. Every scheme: a sweep of three couplings (a list) over four states equals the three separate runs.
schema = json.loads(run(["schema"]).stdout)
# "auto" chooses its scheme from pilot runs of each job's own states, so a sweep and the separate runs need not
# choose alike: it is left out here.
schemes = [name for name in schema["$defs"]["integrator"]["properties"]["scheme"]["enum"] if name != "auto"]
for scheme in schemes:
    job = {"model": {"plugin": "paper2d", "parameters": {"coupling": [0.0, 0.15, 0.3]}},
           "integrator": {"scheme": scheme},
           "initial": [{"q": [0.5, 0.1 * k], "p": [0.2, -0.1]} for k in range(4)],
           "time": {"dt": 0.01, "steps": 20}, "output": {"every": 10}}
    folder = work / f"scheme_{scheme}"
    run(["run", "-q", "--output", str(folder), str(write_job(f"scheme_{scheme}", job))])
    _, swept = rows(folder / "trajectories.csv")
    ok = len(swept) == 12
    for k, coupling in enumerate((0.0, 0.15, 0.3)):
        alone = dict(job, model={"plugin": "paper2d", "parameters": {"coupling": coupling}})
        separate = work / f"scheme_{scheme}_{k}"
        run(["run", "-q", "--output", str(separate), str(write_job(f"scheme_{scheme}_{k}", alone))])
        _, own = rows(separate / "trajectories.csv")
        ok = ok and [split_index(line)[1].rsplit(",", 1)[0] for line in swept[4 * k:4 * k + 4]] == \
            [split_index(line)[1] for line in own]
    check(ok, f"scheme {scheme}: the sweep's rows equal the separate runs'")

# Two parameters: their product by name (the last varying fastest), one column each; and a formula model's parameter.
def product_sweep(name, model, sets, states):
    job = {"model": model, "integrator": {"scheme": "triplet", "order": 2},
           "initial": [{"q": [0.3 * (k + 1)], "p": [0.1]} for k in range(states)],
           "time": {"dt": 0.01, "steps": 40}, "output": {"every": 20}}
    folder = work / name
    run(["run", "-q", "--output", str(folder), str(write_job(name, job))])
    header, swept = rows(folder / "trajectories.csv")
    names = list(sets[0])
    ok = header.endswith("," + ",".join(names)) and len(swept) == len(sets) * states
    for k, values in enumerate(sets):
        alone = dict(job, model=dict(model, parameters=values))
        separate = work / f"{name}_{k}"
        run(["run", "-q", "--output", str(separate), str(write_job(f"{name}_{k}", alone))])
        _, own = rows(separate / "trajectories.csv")
        for line, own_line in zip(swept[states * k:states * (k + 1)], own):
            cells = split_index(line)[1].rsplit(",", len(names))
            ok = ok and cells[0] == split_index(own_line)[1] and [float(c) for c in cells[1:]] == list(values.values())
    check(ok, f"{name}: {len(sets)} parameter sets in product order, each equal to its separate run")


product_sweep("two_parameters",
              {"plugin": "mathews_lakshmanan", "parameters": {"lambda": [0.0, 0.5], "alpha": {"values": [0.5, 1, 2]}}},
              [{"alpha": alpha, "lambda": lam} for alpha in (0.5, 1.0, 2.0) for lam in (0.0, 0.5)], 2)
env["NONSEP_CACHE_DIR"] = str(work / "formula_cache")
product_sweep("formula", {"formula": {"T": "p0^2/2", "V": "q0^2/2 + lambda*q0^4/12", "parameters": {"lambda": 1}},
                          "parameters": {"lambda": {"from": 0.0, "to": 1.0, "count": 3}}},
              [{"lambda": lam} for lam in (0.0, 0.5, 1.0)], 3)

# results.h5 (a build with HDF5): the swept column in /trajectories, read with h5ls where it is installed.
hdf5 = dict(big, output={"every": 100, "format": "hdf5"}, time={"dt": 0.01, "steps": 100})
r = run(["run", "-q", "--output", str(work / "hdf5"), str(write_job("hdf5", hdf5))], expected=None)
if "no HDF5" not in r.stderr and shutil.which("h5ls"):
    listing = subprocess.run(["h5ls", "-r", str(work / "hdf5" / "results.h5")], capture_output=True, text=True).stdout
    check("/trajectories/coupling" in listing and "Dataset {961}" in listing, f"results.h5 has the coupling: {listing}")

# 4. Bad input and studies.
outside = dict(big, model={"plugin": "paper2d", "parameters": {"coupling": [0.1, 0.35]}})
r = run(["validate", str(write_job("outside", outside))], expected=2)
check("/model/parameters/coupling/1" in r.stderr and "0.35" in r.stderr, f"a value out of range is named: {r.stderr}")
outside_range = dict(big, model={"plugin": "paper2d", "parameters": {"coupling": {"from": 0.0, "to": 0.4, "count": 5}}})
r = run(["validate", str(write_job("outside_range", outside_range))], expected=2)
check("0.4" in r.stderr and "value 4 of the range" in r.stderr, f"a range's value out of range is named: {r.stderr}")
study = {"model": {"plugin": "paper2d", "parameters": {"coupling": [0.1, 0.2]}},
         "initial": {"q": [0.5, 0.0], "p": [0.0, 0.0]}, "time": {"t_end": 0.1},
         "study": {"integrators": [{"scheme": "triplet"}], "steps": [10, 20]}}
r = run(["validate", str(write_job("study", study))], expected=2)
check("/model/parameters/coupling" in r.stderr and "one study per value" in r.stderr,
      f"a sweep in a study is refused: {r.stderr}")

for failure in failures:
    print(f"FAIL {failure}", file=sys.stderr)
sys.exit(1 if failures else 0)
