#!/usr/bin/env python3
"""MPI ranks with the comparators' tangent maps (tao: private state per trajectory, its copies and their tangents;
gauss): `mpirun -n 2` with one and two threads a rank writes trajectory.csv, trajectories.csv and lyapunov.csv byte
for byte as one process with one thread, on an ensemble cut into several work units where an energy bound retires
some orbits mid-run (a bound per scheme, set here); and gauss on a model given by H(q, p) itself (henon_heiles).

Usage: check_distributed_tangents.py NONSEP MPIEXEC JOB.json WORKDIR
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

nonsep, mpiexec, job_file, work = sys.argv[1], sys.argv[2], Path(sys.argv[3]).resolve(), Path(sys.argv[4])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
           OMPI_MCA_rmaps_base_oversubscribe="1")
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def run(args):
    return subprocess.run(args, env=env, capture_output=True, text=True, timeout=600)


# Each scheme with an energy bound that retires some of the orbits, not all, between the energy checks.
for scheme, bound in (({"scheme": "tao", "order": 4}, 2e-4), ({"scheme": "gauss", "stages": 3}, 1e-11)):
    name = scheme["scheme"]
    job = json.loads(job_file.read_text())
    job["integrator"] = scheme
    job["analysis"]["max_relative_energy_error"] = bound
    path = work / f"{name}.json"
    path.write_text(json.dumps(job, indent=2))
    one = work / f"{name}_one"
    r = run([nonsep, "run", "-q", "--threads", "1", "--output", str(one), str(path)])
    check(r.returncode in (0, 1), f"{name}, one process: exit 0 or 1 ({r.returncode} {r.stderr[-300:]})")
    one_status = r.returncode
    summary = json.loads((one / "summary.json").read_text())
    check(summary["trajectories"] > 64, f"{name}: the job spans several work units ({summary['trajectories']})")
    counts = summary["counts"]
    check(counts["inaccurate"] > 0 and counts["completed"] > 0, f"{name}: some orbits retire mid-run ({counts})")
    for threads in (1, 2):
        out = work / f"{name}_ranks_{threads}"
        r = run([mpiexec, "-n", "2", nonsep, "run", "-q", "--threads", str(threads), "--output", str(out), str(path)])
        check(r.returncode == one_status, f"{name}, 2 ranks x {threads} threads: exit {one_status} as one process "
                                          f"({r.returncode} {r.stderr[-300:]})")
        for file in ("trajectory.csv", "trajectories.csv", "lyapunov.csv"):
            check((out / file).read_bytes() == (one / file).read_bytes(),
                  f"{name}, 2 ranks x {threads} threads: {file} byte for byte")

# A model given by H(q, p) itself (henon_heiles) with gauss on its shell H = 1/8: the same files byte for byte.
job = json.loads(job_file.read_text())
job["model"] = {"plugin": "henon_heiles"}
job["integrator"] = {"scheme": "gauss", "stages": 3}
job["initial"] = {"grid": {"q": [0.0, {"from": -0.4, "to": 0.6, "count": 12}],
                           "p": [0.0, {"from": -0.4, "to": 0.4, "count": 12}]},
                  "energy": 0.125, "solve_for": "p0"}
del job["analysis"]["max_relative_energy_error"]
path = work / "general.json"
path.write_text(json.dumps(job, indent=2))
one = work / "general_one"
r = run([nonsep, "run", "-q", "--threads", "1", "--output", str(one), str(path)])
check(r.returncode == 0, f"model given by H, one process: exit 0 ({r.returncode} {r.stderr[-300:]})")
summary = json.loads((one / "summary.json").read_text())
check(summary["hamiltonian"] == "general" and summary["trajectories"] > 64,
      f"model given by H: several work units ({summary['trajectories']})")
out = work / "general_ranks"
r = run([mpiexec, "-n", "2", nonsep, "run", "-q", "--threads", "1", "--output", str(out), str(path)])
check(r.returncode == 0, f"model given by H, 2 ranks: exit 0 ({r.returncode} {r.stderr[-300:]})")
for file in ("trajectory.csv", "trajectories.csv", "lyapunov.csv"):
    check((out / file).read_bytes() == (one / file).read_bytes(), f"model given by H, 2 ranks: {file} byte for byte")

print(f"{len(failures)} failed" if failures else "all passed")
sys.exit(1 if failures else 0)
