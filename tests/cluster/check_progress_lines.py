#!/usr/bin/env python3
"""Progress lines of a distributed run (docs/cluster.md, "Progress in a batch log"): `mpirun -n 2` with stderr a
pipe writes plain progress lines from every rank, each labelled with its rank and work unit, at most about one per
rank per interval; -q writes none; the lines change no result (trajectories.csv byte for byte) and cost no CPU time
worth the name (the runs with and without lines alternate, three each; their CPU times are printed).

Usage: check_progress_lines.py NONSEP MPIEXEC JOB.json WORKDIR
"""
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

nonsep, mpiexec, job_file, work = sys.argv[1], sys.argv[2], Path(sys.argv[3]).resolve(), Path(sys.argv[4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
failures = []
interval = 0.2


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


# The grid job's orbits (several work units), stepped longer and without the analyses, so that each rank steps for
# several intervals.
job = json.loads(job_file.read_text())
del job["analysis"]
job["time"] = {"dt": 0.01, "steps": 10000}
job["output"] = {"every": 1000, "energy_every": 40}
path = work / "job.json"
path.write_text(json.dumps(job, indent=2))


def run(name, quiet):
    """Runs the job on two ranks; returns (exit status, stderr, wall seconds, CPU seconds of mpirun and its ranks)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    args = [mpiexec, "-n", "2", nonsep, "run", "--threads", "1", "--output", str(work / name), str(path)]
    r = subprocess.run(args + (["-q"] if quiet else ["--progress-every", str(interval)]), env=env,
                       capture_output=True, text=True, timeout=600)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime
    return r.returncode, r.stderr, wall, cpu


line = re.compile(r"^nonsep: progress: rank (\d+) of 2, unit (\d{6}) of (\d+): t = \S+ of 100 \(\S+%\), "
                  r"step \d+/10000, \d+ active(, max \|dH/H0\| \S+)?, ETA \d+ s$")
cpu = {"lines": [], "quiet": []}
for attempt in range(3):
    for kind in ("lines", "quiet"):
        name = f"{kind}_{attempt}"
        status, stderr, wall, seconds = run(name, kind == "quiet")
        cpu[kind].append(seconds)
        check(status == 0, f"{name}: exit 0 ({status} {stderr[-300:]})")
        progress = [text for text in stderr.splitlines() if text.startswith("nonsep: progress:")]
        if kind == "quiet":
            check(not progress, f"{name}: -q writes no progress line ({progress[:2]})")
            continue
        matches = [line.match(text) for text in progress]
        check(all(matches), f"{name}: every progress line is labelled with its rank and unit "
                            f"({[t for t, m in zip(progress, matches) if not m][:2]})")
        ranks = {int(m.group(1)) for m in matches if m}
        check(ranks == {0, 1}, f"{name}: both ranks write progress lines (ranks {sorted(ranks)}, {len(progress)} lines)")
        trajectories = json.loads((work / name / "summary.json").read_text())["trajectories"]
        units = (trajectories + 255) // 256  # units of 256 trajectories (docs/cluster.md)
        check(units > 2 and all(int(m.group(3)) == units and int(m.group(2)) < units for m in matches if m),
              f"{name}: the lines name units 0 to {units - 1} of the run's {units} ({trajectories} trajectories)")
        for rank in (0, 1):
            count = sum(1 for m in matches if m and int(m.group(1)) == rank)
            check(count <= wall / interval + 2,
                  f"{name}: rank {rank} writes at most one line per interval ({count} lines in {wall:.1f} s)")
        if attempt == 0:
            print("\n".join(progress[:4]))
for attempt in range(3):
    check((work / f"lines_{attempt}" / "trajectories.csv").read_bytes() ==
          (work / f"quiet_{attempt}" / "trajectories.csv").read_bytes(),
          f"run {attempt}: trajectories.csv the same with and without progress lines")
print("CPU seconds (mpirun and both ranks), progress lines every %g s: %s; -q: %s" %
      (interval, " ".join(f"{s:.2f}" for s in cpu["lines"]), " ".join(f"{s:.2f}" for s in cpu["quiet"])))
# Not a benchmark (the machine may be shared): a guard against progress that costs as much as the stepping.
check(min(cpu["lines"]) <= 1.5 * min(cpu["quiet"]) + 1.0,
      f"progress lines cost little CPU time (best {min(cpu['lines']):.2f} s against {min(cpu['quiet']):.2f} s)")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
