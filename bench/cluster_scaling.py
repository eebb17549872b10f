#!/usr/bin/env python3
"""How much faster is an ensemble on 2 MPI ranks than on one process? (docs/cluster.md, docs/performance.md)

Run by hand, on a machine with MPI (`nonsep --version` says "MPI: ..."):

  python3 bench/cluster_scaling.py [--nonsep build/bin/nonsep] [--mpirun mpirun] [--repeats 3]
                                   [--steps 19200] [--grid 128] [--work /tmp/nonsep_cluster_scaling]

It writes one job (paper2d on the energy shell H = 7, a grid of GRID x GRID points of which about 11000 lie on the
shell, STEPS steps of dt 0.01, a sample every STEPS/4 steps, no analysis; about 20 s on one core of a 2020s x86
machine), then measures, REPEATS times and interleaved (a b c d e, a b c d e, ...), the wall time of:

  a  nonsep run --threads 1                                     one process, one thread (the reference)
  b  mpirun -n 2 nonsep run --threads 1                         2 ranks x 1 thread
  c  mpirun -n 1 nonsep run --threads 2                         1 rank x 2 threads, mpirun's default binding
  c' mpirun -n 1 --bind-to none nonsep run --threads 2          1 rank x 2 threads, not bound to one core
  d  mpirun -n 2 nonsep run --threads 1, one core kept busy     2 ranks while a Python busy loop runs

Wall time is that of the whole command (mpirun's start, the units, rank 0's merge). It prints the median and the
spread (min-max) of each, the ratios a/x, the CPU seconds other processes used during each run (/proc/stat's
busy time minus this script's children's: the busy loop of d counts as ours), and checks that every run wrote
the files of (a) byte for byte (summary.json but for wall_seconds and the output folder). Print `uptime` before and after: other work on the
machine shows in the numbers. Exit status 1 when an output differs.

Running as root, it sets OMPI_ALLOW_RUN_AS_ROOT(_CONFIRM); it also sets OMPI_MCA_rmaps_base_oversubscribe=1 so that
2 ranks start on a machine with fewer than 2 cores free.
"""
import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
root = Path(__file__).resolve().parent.parent
parser.add_argument("--nonsep", default=str(root / "build" / "bin" / "nonsep"))
parser.add_argument("--mpirun", default="mpirun")
parser.add_argument("--repeats", type=int, default=3)
parser.add_argument("--steps", type=int, default=19200)
parser.add_argument("--grid", type=int, default=128)
parser.add_argument("--work", default="/tmp/nonsep_cluster_scaling")
args = parser.parse_args()

work = Path(args.work)
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
job = work / "job.json"
job.write_text(json.dumps({
    "description": "bench/cluster_scaling.py: paper2d orbits on the shell H = 7, no analysis",
    "model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
    "integrator": {"scheme": "mpe", "order": 4},
    "initial": {
        "grid": {"q": [{"from": -1.6, "to": 1.6, "count": args.grid}, 0.0],
                 "p": [{"from": -1.8, "to": 1.8, "count": args.grid}, 0.0]},
        "energy": 7.0, "solve_for": "p1"},
    "time": {"dt": 0.01, "steps": args.steps},
    "output": {"every": max(1, args.steps // 4)},
}, indent=2))

nonsep = args.nonsep
cases = {
    "a": ("1 process x 1 thread", lambda out: [nonsep, "run", "-q", "--threads", "1", str(job), "--output", out]),
    "b": ("mpirun -n 2 x 1 thread",
          lambda out: [args.mpirun, "-n", "2", nonsep, "run", "-q", "--threads", "1", str(job), "--output", out]),
    "c": ("mpirun -n 1 x 2 threads",
          lambda out: [args.mpirun, "-n", "1", nonsep, "run", "-q", "--threads", "2", str(job), "--output", out]),
    "c'": ("mpirun -n 1 --bind-to none x 2 thr",
           lambda out: [args.mpirun, "-n", "1", "--bind-to", "none", nonsep, "run", "-q", "--threads", "2", str(job),
                        "--output", out]),
    "d": ("mpirun -n 2 x 1 thread + busy core",
          lambda out: [args.mpirun, "-n", "2", nonsep, "run", "-q", "--threads", "1", str(job), "--output", out]),
}


def busy_cpu_seconds():
    """CPU seconds the whole machine has spent busy since boot (/proc/stat; Linux)."""
    fields = [int(x) for x in open("/proc/stat").readline().split()[1:]]
    return (sum(fields[:8]) - fields[3] - fields[4]) / os.sysconf("SC_CLK_TCK")  # all but idle and iowait


def children_cpu_seconds():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def uptime():
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def same_results(a, b):
    """The differences between output folders a and b (an empty list when b holds a's files byte for byte)."""
    problems = []
    names, other = ([p.name for p in sorted(d.iterdir()) if not p.name.startswith(".")] for d in (a, b))
    if names != other:
        return [f"files {names} / {other}"]
    for name in names:
        if name == "summary.json":
            text = [[l for l in (d / name).read_text().splitlines()
                     if '"wall_seconds"' not in l and '"directory"' not in l] for d in (a, b)]
            if text[0] != text[1]:
                problems.append(name)
        elif (a / name).read_bytes() != (b / name).read_bytes():
            problems.append(name)
    return problems


print("before:", uptime(), flush=True)
print(f"job: {job} ({args.grid}x{args.grid} grid on the shell, {args.steps} steps)", flush=True)
times = {key: [] for key in cases}
others = {key: [] for key in cases}  # CPU seconds used by processes not started here, during each run
statuses = set()
differences = []
reference = None
for repeat in range(args.repeats):
    for key, (what, command) in cases.items():
        out = work / f"{key.replace(chr(39), 'p')}_{repeat}"
        busy = None
        machine, ours = busy_cpu_seconds(), children_cpu_seconds()
        if key == "d":
            busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
            time.sleep(0.5)
        started = time.monotonic()
        r = subprocess.run(command(str(out)), env=env, capture_output=True, text=True)
        seconds = time.monotonic() - started
        if busy is not None:
            busy.kill()
            busy.wait()
        foreign = max(0.0, (busy_cpu_seconds() - machine) - (children_cpu_seconds() - ours))
        others[key].append(foreign)
        statuses.add(r.returncode)
        if r.returncode not in (0, 1):
            sys.exit(f"{key} ({what}) failed with exit status {r.returncode}: {r.stderr[-800:]}")
        times[key].append(seconds)
        print(f"  repeat {repeat + 1} {key:2} {what:36} {seconds:7.2f} s   others' CPU {foreign:6.1f} s", flush=True)
        if reference is None:
            reference = out
        else:
            problems = same_results(reference, out)
            if problems:
                differences.append(f"{key} repeat {repeat + 1}: {problems}")
            shutil.rmtree(out)
print("after: ", uptime(), flush=True)
trajectories = json.loads((reference / "summary.json").read_text())["trajectories"]

median_a = statistics.median(times["a"])
print(f"\n{trajectories} trajectories x {args.steps} steps, {args.repeats} repeats, wall seconds of the command\n")
print("| case | run | median s | min-max s | 1 process / this | others' CPU s (max) |")
print("|---|---|---|---|---|---|")
for key, (what, _) in cases.items():
    t = times[key]
    print(f"| {key} | {what} | {statistics.median(t):.2f} | {min(t):.2f}-{max(t):.2f} | "
          f"{median_a / statistics.median(t):.2f}x | {max(others[key]):.1f} |")
print()
if differences:
    print("FAILED: outputs differ from one process's:", *differences, sep="\n  ")
    sys.exit(1)
print(f"ok: every run wrote the files of (a) byte for byte (summary.json but for wall_seconds and the folder); "
      f"exit statuses {sorted(statuses)}")
