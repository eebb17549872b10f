#!/usr/bin/env python3
"""A distributed run whose ranks are all killed hard (SIGKILL, as a node failure or an out-of-memory killer does) is
resumed from units/ alone, with any number of ranks, and ends byte for byte as one uninterrupted process.

The job: paper2d on a 32 x 32 grid (four work units of 256), the triplet scheme of order 4/3, on the stepping the
processor offers by default (the widest instruction set of the plugin's kernel: printed). Every rank of
`mpirun -n 2` gets SIGKILL at a moment given by what the run has written, never after a fixed time:
  1. units/plan.json written, no unit checkpointed yet;
  2. the first checkpoint of a unit;
  3. the first unit sealed (finished);
  4. a checkpoint of a unit of the second round (units 2 and 3 start when 0 and 1 are done).
No summary.json is left; `nonsep run --resume` continues on 2 ranks, 3 ranks or one process without mpirun (with
HDF5 output after the second moment, each checkpointed unit's results.h5 is damaged first: such a unit runs again from
its start, with a warning), and
trajectory.csv, trajectories.csv and summary.json (but for wall_seconds and the folder) equal the uninterrupted
run's (but for wall_seconds, the folder, kernel calls and evaluation counts); with output.format "hdf5", so do
results.h5's /samples (h5py, when installed).
Usage: check_killed_ranks.py NONSEP MPIEXEC WORKDIR
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

nonsep, mpiexec, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
env.pop("NONSEP_INSTRUCTION_SET", None)  # the default: the widest set this processor runs
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what, flush=True)
    if not condition:
        failures.append(what)


def job_file(name, hdf5=False):
    document = {
        "model": {"plugin": "paper2d"},
        "integrator": {"scheme": "triplet", "order": "4/3"},
        "initial": {"grid": {"q": [{"from": -0.5, "to": 0.5, "count": 32}, 0.1],
                             "p": [{"from": -0.3, "to": 0.3, "count": 32}, 0.2]}},
        "time": {"dt": 0.002, "steps": 30000},
        "output": {"every": 2500},
        "checkpoint": {"every_steps": 2500, "every_seconds": 0},
    }
    if hdf5:
        document["output"]["format"] = "hdf5"
    path = work / name
    path.write_text(json.dumps(document))
    return path


def comparable_summary(folder):
    """summary.json but for what a resume changes by design (docs/outputs.md): wall_seconds, the folder and the
    evaluation counts (a resumed unit evaluates the first gradient again)."""
    summary = json.loads((folder / "summary.json").read_text())
    summary.pop("wall_seconds")
    summary.pop("evaluations")
    summary["output"].pop("directory")
    return summary


def same_results(reference, folder, what):
    for name in ("trajectory.csv", "trajectories.csv"):
        if (reference / name).exists():
            check((folder / name).exists() and (folder / name).read_bytes() == (reference / name).read_bytes(),
                  f"{what}: {name} byte for byte")
    check(comparable_summary(folder) == comparable_summary(reference),
          f"{what}: summary.json equal but for wall_seconds, the folder, kernel calls and evaluation counts")
    if (reference / "results.h5").exists():
        try:
            import h5py
            import numpy
        except ImportError as missing:
            check(False, f"h5py for the HDF5 checks: {missing}")
            return
        with h5py.File(reference / "results.h5", "r") as a, h5py.File(folder / "results.h5", "r") as b:
            for name in ("samples/q", "samples/p", "samples/t", "samples/step"):
                x, y = a[name][()], b[name][()]
                check(x.shape == y.shape and x.tobytes() == y.tobytes(), f"{what}: results.h5 {name} bit for bit")


def units(folder, pattern):
    return list((folder / "units").glob(pattern))


moments = [
    ("units/plan.json written", lambda out: (out / "units" / "plan.json").exists()),
    ("a unit's first checkpoint", lambda out: len(units(out, "*/checkpoint.json")) > 0),
    ("a unit sealed", lambda out: len(units(out, "*/.nonsep-unit.json")) > 0),
    ("a checkpoint of the second round", lambda out: len(units(out, "00000[23]/checkpoint.json")) > 0),
]


def kill_every_rank_when(job, out, moment):
    """Starts `mpirun -n 2 nonsep run`, SIGKILLs both ranks once `moment(out)` holds; whether it held in time."""
    process = subprocess.Popen([mpiexec, "-n", "2", nonsep, "run", "-q", "--threads", "1", str(job), "--output",
                                str(out)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 600
    while not moment(out) and process.poll() is None and time.monotonic() < deadline:
        time.sleep(0.002)
    held = process.poll() is None and moment(out)
    ranks = subprocess.run(["pgrep", "-P", str(process.pid)], capture_output=True, text=True).stdout.split()
    for pid in ranks:
        os.kill(int(pid), signal.SIGKILL)
    process.communicate(timeout=120)
    return held and len(ranks) == 2


def resume(job, out, ranks):
    args = [nonsep, "run", "-q", "--threads", "1", str(job), "--output", str(out), "--resume"]
    if ranks > 1:
        args = [mpiexec, "-n", str(ranks)] + args
    return subprocess.run(args, env=env, capture_output=True, text=True, timeout=900)


for hdf5 in (False, True):
    kind = "hdf5" if hdf5 else "csv"
    job = job_file(f"job_{kind}.json", hdf5)
    reference = work / f"reference_{kind}"
    r = subprocess.run([nonsep, "run", "-q", "--threads", "1", str(job), "--output", str(reference)], env=env,
                       capture_output=True, text=True, timeout=900)
    check(r.returncode == 0, f"{kind}: the uninterrupted run in one process: exit 0 ({r.stderr[-300:]})")
    stepping = json.loads((reference / "summary.json").read_text())["stepping"]
    print(f"{kind}: stepping {stepping['path']}, instruction set {stepping['instruction_set']} "
          f"(the plugin has {stepping['plugin_kernels']})", flush=True)
    # CSV at every moment; HDF5 at the second and the last.
    for index, (what, moment) in enumerate(moments):
        if hdf5 and index not in (1, 3):
            continue
        ranks = (2, 1, 3, 2)[index]
        out = work / f"killed_{kind}_{index}"
        held = kill_every_rank_when(job, out, moment)
        check(held, f"{kind}: both ranks killed at '{what}'")
        if not held:
            continue
        check(not (out / "summary.json").exists() and (out / "units" / "plan.json").exists(),
              f"{kind}, killed at '{what}': units/ left, no summary.json")
        damaged = []
        if hdf5 and index == 1:
            # A kill can land while HDF5 rewrites a deflated chunk in place, leaving results.h5 unreadable past the
            # checkpoint: damaged here on purpose (the second half of each checkpointed unit's file zeroed), such a
            # unit runs again from its start, with a warning, and the results are the same.
            for unit in units(out, "*/checkpoint.json"):
                if (unit.parent / ".nonsep-unit.json").exists() or not (unit.parent / "results.h5").exists():
                    continue
                data = bytearray((unit.parent / "results.h5").read_bytes())
                data[len(data) // 2:] = bytes(len(data) - len(data) // 2)
                (unit.parent / "results.h5").write_bytes(bytes(data))
                damaged.append(unit.parent.name)
            check(len(damaged) > 0, f"{kind}, killed at '{what}': a checkpointed unit's results.h5 damaged")
        r = resume(job, out, ranks)
        check(r.returncode == 0, f"{kind}, killed at '{what}', resumed on {ranks} rank(s): exit 0 "
                                 f"({r.returncode}: {r.stderr[-400:]})")
        for name in damaged:
            check(f"{name}: cannot resume" in r.stderr and "running it again from its start" in r.stderr,
                  f"{kind}, killed at '{what}': unit {name} with a damaged results.h5 run again, with a warning")
        if r.returncode == 0:
            same_results(reference, out, f"{kind}, killed at '{what}', resumed on {ranks} rank(s)")
            check(not (out / "units").exists(), f"{kind}, killed at '{what}': units/ removed after the merge")

print(f"{len(failures)} failed")
sys.exit(1 if failures else 0)
