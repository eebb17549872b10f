#!/usr/bin/env python3
"""MPI ranks (host/include/nonsep/host/cluster/distributed_run.hpp), run as a user runs them, with mpirun.

  1. `mpirun -n 2` (one and two threads a rank) writes every file byte for byte as one process with one thread
     (summary.json: all but wall_seconds and the output folder's name), on an ensemble with Poincare crossings,
     Lyapunov and MEGNO series, samples and mid-run energy retirements, cut into several work units.
  2. SIGTERM to the ranks mid-run (as Slurm's scancel sends it): exit 143, summary.json "interrupted", units/ kept; the run resumed by one process
     (no mpirun) ends byte for byte as an uninterrupted one; a fresh run in that folder is refused (exit 2).
  3. A plugin that cannot be loaded on rank 1 only: exit 2 on every rank, one message naming rank 1, no hang.
  4. An unreadable job under mpirun: exit 2, the message printed once.
  5. SIGUSR1 to mpirun (passed on to the ranks) once a unit has finished: exit 143; meanwhile a --force run into that
     unit's folder is refused; --resume with another job's units: exit 2, "cannot resume"; a finished unit cut short,
     and units/ replaced by a link out of the folder, are refused on two ranks (exit 2, nothing merged or written
     through the link); the run resumed on two ranks ends byte for byte as an uninterrupted one.
  6. output.format "hdf5" on two ranks: results.h5 holds the numbers and attributes of one process's.
  7. A rank that crashes (the blowup test plugin raises SIGSEGV in grad V): mpirun ends every rank, non-zero, no hang.
Usage: check_distributed_run.py NONSEP MPIEXEC JOB.json WORKDIR [BLOWUP_PLUGIN.so]
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

nonsep, mpiexec, job, work = sys.argv[1], sys.argv[2], Path(sys.argv[3]).resolve(), Path(sys.argv[4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
# When a rank exits with a non-zero status, mpirun signals the ranks it still counts as running and kills them
# odls_base_sigkill_timeout seconds later (1 by default): time for every rank to save its checkpoint. Only where
# signals are sent: mpirun then returns about twice that time after the ranks ended (docs/cluster.md).
signal_env = dict(env, OMPI_MCA_odls_base_sigkill_timeout="10")
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def run(args, timeout=300):
    return subprocess.run(args, env=env, capture_output=True, text=True, timeout=timeout)


def mpirun(ranks, args, timeout=300):
    return run([mpiexec, "-n", str(ranks), nonsep] + args, timeout)


def same_results(a, b, what):
    names = sorted(p.name for p in a.iterdir() if not p.name.startswith("."))
    other = sorted(p.name for p in b.iterdir() if not p.name.startswith("."))
    check(names == other, f"{what}: the same files ({names} / {other})")
    for name in names:
        if name == "summary.json":
            sa, sb = (json.loads((d / name).read_text()) for d in (a, b))
            for s in (sa, sb):
                s.pop("wall_seconds")
                s["output"].pop("directory")
            check(sa == sb, f"{what}: summary.json equal but for wall_seconds and the folder")
            text = [(d / name).read_text().splitlines() for d in (a, b)]
            keep = [[l for l in t if '"wall_seconds"' not in l and '"directory"' not in l] for t in text]
            check(keep[0] == keep[1], f"{what}: summary.json byte for byte but for those two lines")
        else:
            check((a / name).read_bytes() == (b / name).read_bytes(), f"{what}: {name} byte for byte")


# 1. one process against two ranks
single = work / "single"
r = run([nonsep, "run", "-q", "--threads", "1", str(job), "--output", str(single)])
check(r.returncode == 1, f"one process: exit 1 (some trajectories retire as inaccurate): {r.returncode} {r.stderr[-300:]}")
summary = json.loads((single / "summary.json").read_text())
check(summary["counts"]["inaccurate"] > 0 and summary["counts"]["completed"] > 0,
      "the job retires some trajectories mid-run and completes others")
check(summary["trajectories"] > 1024, "the job spans several work units of 256")
for threads in ("1", "2"):
    out = work / f"ranks2_threads{threads}"
    r = mpirun(2, ["run", "-q", "--threads", threads, str(job), "--output", str(out)])
    check(r.returncode == 1, f"2 ranks x {threads} threads: exit 1 as one process: {r.returncode} {r.stderr[-500:]}")
    check(r.stderr.count("nonsep: inaccurate:") == 1, "2 ranks: the completion line once")
    check(not (out / "units").exists(), "2 ranks: units/ removed after the merge")
    same_results(single, out, f"2 ranks x {threads} threads")

# 2. interrupted on two ranks, resumed by one process
long_job = work / "long.json"
document = json.loads(job.read_text())
document["time"]["steps"] = 2000
document["output"]["every"] = 500
document["analysis"].pop("max_relative_energy_error")
document["analysis"]["poincare"].pop("max_crossings")  # which would stop the orbits early
# SALI and GALI (a third vector, and their series) are compared above; here they would only make every run of this
# long job half again as long.
for key in ("sali", "gali"):
    document["analysis"].pop(key)
long_job.write_text(json.dumps(document))
reference = work / "long_single"
started = time.monotonic()
r = run([nonsep, "run", "-q", "--threads", "1", str(long_job), "--output", str(reference)], timeout=900)
single_seconds = time.monotonic() - started
long_status = r.returncode
check(long_status in (0, 1), f"long job, one process: exit 0 or 1 ({r.stderr[-300:]})")
interrupted = work / "long_interrupted"
process = subprocess.Popen([mpiexec, "-n", "2", nonsep, "run", "-q", "--threads", "1", str(long_job), "--output",
                            str(interrupted)], env=signal_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(max(1.0, 0.15 * single_seconds))
# As Slurm's scancel does: SIGTERM to every rank (mpirun's children here).
ranks = subprocess.run(["pgrep", "-P", str(process.pid)], capture_output=True, text=True).stdout.split()
check(len(ranks) == 2, f"two rank processes under mpirun: {ranks}")
for pid in ranks:
    os.kill(int(pid), signal.SIGTERM)
out, err = process.communicate(timeout=300)
check(process.returncode == 143, f"SIGTERM to the ranks: exit 143 ({process.returncode}; {err[-500:]})")
check(err.count("--resume` continues the work units") == 1, "the resume advice once")
state = json.loads((interrupted / "summary.json").read_text())
check(state["status"] == "interrupted" and state["distributed"]["units_done"] < state["distributed"]["units"],
      f"summary.json says interrupted with units left: {state.get('distributed')}")
check((interrupted / "units" / "plan.json").exists(), "units/plan.json kept")
r = run([nonsep, "run", "-q", str(long_job), "--output", str(interrupted)])
check(r.returncode == 2 and "--resume" in r.stderr, f"a fresh run there is refused: {r.returncode} {r.stderr[-300:]}")
r = run([nonsep, "run", "-q", "--threads", "1", str(long_job), "--output", str(interrupted), "--resume"], timeout=900)
check(r.returncode == long_status, f"resumed by one process: exit {long_status} ({r.returncode} {r.stderr[-500:]})")
same_results(reference, interrupted, "interrupted on 2 ranks, resumed on 1")

# 3. the plugin cannot be loaded on rank 1
broken = work / "broken_plugins"
broken.mkdir()
(broken / "paper2d.so").write_text("not a shared library\n")
r = run([mpiexec, "-n", "1", nonsep, "run", "-q", str(job), "--output", str(work / "broken"), ":", "-n", "1", "env",
         f"NONSEP_PLUGIN_PATH={broken}", nonsep, "run", "-q", str(job), "--output", str(work / "broken")], timeout=120)
check(r.returncode == 2, f"plugin broken on rank 1: exit 2 ({r.returncode})")
lines = [l for l in r.stderr.splitlines() if l.startswith("nonsep:")]
check(len(lines) == 1 and "rank 1:" in lines[0] and r.stderr.count("paper2d.so") >= 1,
      f"one message naming rank 1 and the plugin: {r.stderr[:600]}")

# 4. an unreadable job
r = mpirun(2, ["run", "-q", str(work / "missing.json")], timeout=120)
lines = [l for l in r.stderr.splitlines() if l.startswith("nonsep:")]
check(r.returncode == 2 and len(lines) == 1 and "missing.json" in lines[0],
      f"missing job under mpirun: exit 2, one message ({r.returncode}: {lines})")

# 5. SIGUSR1 to mpirun, which passes it on to every rank (SIGTERM and SIGINT it does not); the units refuse another
# job's --resume and are resumed on two ranks
other = work / "long_interrupted_twice"
process = subprocess.Popen([mpiexec, "-n", "2", nonsep, "run", "-q", "--threads", "1", str(long_job), "--output",
                            str(other)], env=signal_env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
deadline = time.monotonic() + 300
while not list((other / "units").glob("*/.nonsep-unit.json")) and time.monotonic() < deadline:
    time.sleep(0.01)  # until a unit is sealed (finished), so that the resume has a finished unit to verify
sealed = sorted(p.parent.name for p in (other / "units").glob("*/.nonsep-unit.json"))
check(len(sealed) > 0, "a unit finished while the run goes on")
# Another run cannot take a unit's folder over while the distributed run is active, --force or not.
quick = Path(__file__).resolve().parents[2] / "examples" / "jobs" / "quickstart.json"
r = run([nonsep, "run", "-q", "--force", str(quick), "--output", str(other / "units" / sealed[0])], timeout=120)
check(r.returncode == 2 and "work unit of a distributed run" in r.stderr,
      f"--force into a finished unit while the run is active: exit 2 ({r.returncode} {r.stderr[-300:]})")
process.send_signal(signal.SIGUSR1)
out, err = process.communicate(timeout=300)
check(process.returncode == 143 and "stopped by SIGUSR1" in err,
      f"SIGUSR1 to mpirun: exit 143 ({process.returncode}: {err[-300:]})")
check(json.loads((other / "summary.json").read_text())["status"] == "interrupted", "summary.json says interrupted")
other_job = work / "other.json"
document = json.loads(long_job.read_text())
document["time"]["steps"] = 200
other_job.write_text(json.dumps(document))
r = mpirun(2, ["run", "-q", str(other_job), "--output", str(other), "--resume"], timeout=120)
lines = [l for l in r.stderr.splitlines() if l.startswith("nonsep:")]
check(r.returncode == 2 and len(lines) == 1 and "cannot resume" in lines[0],
      f"resuming another job's units: exit 2, one message ({r.returncode}: {lines})")
# A finished unit cut short, or units/ replaced by a link out of the folder: the resume on two ranks refuses it, naming
# it, and writes nothing outside.
cut = work / "cut_unit"
shutil.copytree(other, cut, symlinks=True)
unit = cut / "units" / sealed[0]
size = (unit / "trajectory.csv").stat().st_size
os.truncate(unit / "trajectory.csv", min(50000, size // 2))
r = mpirun(2, ["run", "-q", "--threads", "1", str(long_job), "--output", str(cut), "--resume"], timeout=300)
check(r.returncode == 2 and f"work unit {unit}" in r.stderr and not (cut / "trajectory.csv").exists(),
      f"a finished unit cut short: exit 2 naming it, nothing merged ({r.returncode} {r.stderr[-400:]})")
linked = work / "linked_units"
shutil.copytree(other, linked, symlinks=True)
(linked / "units").rename(work / "outside_units")
(linked / "units").symlink_to(work / "outside_units")
before = sorted(str(p) for p in (work / "outside_units").rglob("*"))
r = mpirun(2, ["run", "-q", "--threads", "1", str(long_job), "--output", str(linked), "--resume"], timeout=300)
check(r.returncode == 2 and "is a symbolic link" in r.stderr,
      f"units/ a link out of the folder: exit 2 ({r.returncode} {r.stderr[-300:]})")
check(sorted(str(p) for p in (work / "outside_units").rglob("*")) == before, "nothing written through the link")
r = mpirun(2, ["run", "-q", "--threads", "1", str(long_job), "--output", str(other), "--resume"], timeout=900)
check(r.returncode == long_status, f"resumed on two ranks: exit {long_status} ({r.returncode})")
same_results(reference, other, "interrupted on 2 ranks, resumed on 2")

# 6. output.format "hdf5": the ranks write results.h5 together (MPI-IO); every dataset and attribute equals one
# process's (the summary attribute but for wall_seconds and the folder)
try:
    import h5py
    import numpy
except ImportError as missing:
    h5py = None
    check(False, f"h5py for the HDF5 checks: {missing}")
if h5py is not None:
    h5_job = work / "hdf5.json"
    document = json.loads(job.read_text())
    document["output"]["format"] = "hdf5"
    h5_job.write_text(json.dumps(document))
    one, two = work / "h5_single", work / "h5_ranks2"
    r1 = run([nonsep, "run", "-q", "--threads", "1", str(h5_job), "--output", str(one)])
    r2 = mpirun(2, ["run", "-q", "--threads", "1", str(h5_job), "--output", str(two)])
    check(r1.returncode == r2.returncode == 1, f"hdf5: exit 1 on one process and on 2 ranks ({r1.returncode}, {r2.returncode})")
    with h5py.File(one / "results.h5", "r") as a, h5py.File(two / "results.h5", "r") as b:
        names = []
        a.visititems(lambda name, item: names.append(name) if isinstance(item, h5py.Dataset) else None)
        check("samples/q" in names and "trajectories/status" in names and "poincare/t" in names,
              f"hdf5: samples and tables present ({len(names)} datasets)")
        for name in names:
            x, y = a[name][()], b[name][()]
            same = (numpy.array_equal(x, y, equal_nan=True) if x.dtype.kind == "f" else numpy.array_equal(x, y))
            if not same:
                check(False, f"hdf5: {name} equal on 2 ranks")
        check(all(numpy.array_equal(a[n][()], b[n][()], equal_nan=a[n].dtype.kind == "f") for n in names),
              "hdf5: every dataset equal on 2 ranks")
        check(numpy.isnan(b["samples/q"][()]).any() and not numpy.isnan(b["samples/q"][0]).any(),
              "hdf5: NaN after trajectories stopped, none at step 0")
        for key in a.attrs:
            if key != "summary":
                check(a.attrs[key] == b.attrs[key], f"hdf5: attribute {key} equal")
        sa, sb = json.loads(a.attrs["summary"]), json.loads(b.attrs["summary"])
        for s in (sa, sb):
            s.pop("wall_seconds")
            s["output"].pop("directory")
        check(sa == sb, "hdf5: summary attribute equal but for wall_seconds and the folder")

if len(sys.argv) > 5:
    crash_job = work / "crash.json"
    crash_job.write_text(json.dumps({
        "model": {"plugin": sys.argv[5], "parameters": {"crash_after": 2000, "crash_how": 1}},
        "integrator": {"scheme": "basic"},
        "initial": {"grid": {"q": [{"from": 0.1, "to": 1.0, "count": 600}], "p": [0.0]}},
        "time": {"dt": 0.001, "steps": 100000}, "output": {"every": 0}}))
    started = time.monotonic()
    r = mpirun(2, ["run", "-q", "--threads", "1", str(crash_job), "--output", str(work / "crash")], timeout=120)
    check(r.returncode != 0 and time.monotonic() - started < 100,
          f"a rank crashing: mpirun ends non-zero without hanging ({r.returncode}, {time.monotonic() - started:.1f} s)")

print(f"{len(failures)} failed")
sys.exit(1 if failures else 0)
