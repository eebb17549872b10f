#!/usr/bin/env python3
"""Which scheme for a MEGNO map (docs/dynamics.md, "Which scheme for a map"): paper2d on the shell H = 8, 16
couplings from 0 to 0.3 x a 9 x 9 grid of (q0, p0) on the section q1 = 0 (p1 >= 0 solved; 602 orbits reach the
shell), MEGNO to t = 100, run with each scheme and step of SCHEMES on one thread. Prints per run its CPU time (user +
system of the nonsep process), the orbits that diverged (in all, and at coupling >= 0.24), the largest |dH/H0| of
the completed orbits at couplings <= 0.2 and above, and how many completed orbits it classifies (<Y> > 2.5 or not)
as Gauss-Legendre 3 stages at dt = 0.02, the first run, does; then the chaotic fraction per coupling of each run.

    /usr/bin/python3 bench/indicators/map_schemes.py build/bin/nonsep /tmp/map_schemes   (about 6 minutes of CPU)
"""
import json
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "python"))
import nonsep  # noqa: E402

SCHEMES = [("gauss 3 stages", {"scheme": "gauss", "stages": 3}, 0.02),
           ("gauss 2 stages", {"scheme": "gauss", "stages": 2}, 0.02),
           ("gauss 3 stages", {"scheme": "gauss", "stages": 3}, 0.04),
           ("mpe 4", {"scheme": "mpe", "order": 4}, 0.005),
           ("mpe 4", {"scheme": "mpe", "order": 4}, 0.0025),
           ("auto, tolerance 1e-6 on |dH/H0| (dt: the output grid)",
            {"scheme": "auto", "tolerance": 1e-6, "measure": "energy"}, 0.04)]
THRESHOLD = 2.5


def job(integrator, dt, t_end=100.0):
    return {"model": {"plugin": "paper2d", "parameters": {"coupling": {"from": 0.0, "to": 0.3, "count": 16}}},
            "integrator": integrator,
            "initial": {"grid": {"q": [{"from": -2.0, "to": 2.0, "count": 9}, 0.0],
                                 "p": [{"from": -2.0, "to": 2.0, "count": 9}, 0.0]},
                        "energy": 8.0, "solve_for": "p1"},
            "time": {"dt": dt, "t_end": t_end}, "output": {"every": round(t_end / dt)},
            "analysis": {"lyapunov": {"vectors": 1, "renormalize_every": 10}, "megno": True}}


def run(nonsep_path, work, name, integrator, dt):
    path = work / f"{name}.json"
    path.write_text(json.dumps(job(integrator, dt)))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    done = subprocess.run([nonsep_path, "run", "--quiet", "--force", "--threads", "1", "--output",
                           str(work / name), str(path)], capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode not in (0, 1):  # 1: some orbits diverged
        raise SystemExit(f"{name}: exit {done.returncode}\n{done.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return nonsep.load(work / name), cpu


def main():
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    work = Path(sys.argv[2])
    work.mkdir(parents=True, exist_ok=True)
    runs = []
    for label, integrator, dt in SCHEMES:
        name = f"{integrator['scheme']}{integrator.get('stages', integrator.get('order', ''))}_{dt:g}"
        result, cpu = run(sys.argv[1], work, name, integrator, dt)
        runs.append((f"{label}, dt = {dt:g}", result, cpu))
    reference = runs[0][1].trajectories
    print("run | CPU s | diverged (at coupling >= 0.24) | largest |dH/H0| completed, coupling <= 0.2 / > 0.2 | "
          f"classified (<Y> > {THRESHOLD:g}) as {runs[0][0]}")
    for label, result, cpu in runs:
        table = result.trajectories
        done = table["status"] == "completed"
        strong = table["coupling"] > 0.2 + 1e-9
        error = table["max_abs_relative_energy_error"]
        agree = done & ((table["mean_megno"] > THRESHOLD) == (reference["mean_megno"] > THRESHOLD))
        print(f"{label} | {cpu:.1f} | {np.sum(~done)} of {len(table)} ({np.sum(~done & (table['coupling'] >= 0.24))}) | "
              f"{np.max(error[done & ~strong]):.1e} / {np.max(error[done & strong]):.1e} | "
              f"{np.sum(agree)} of {np.sum(done)}")
    choice = runs[-1][1].summary["scheme_choice"]
    print(f"auto chose {choice['chosen']} with {choice['subdivision']} steps per dt = 0.04 (pilots: "
          f"{choice['pilot_cost']['wall_seconds']:.1f} s); measured largest |dH/H0| {choice['measured_error']:.1e}; "
          + "; ".join(f"{c['scheme']} {c['order']}: {c['excluded']}" for c in choice["candidates"] if c.get("excluded")))
    for label, result, _ in runs:
        counts = result.chaotic_fraction(threshold=THRESHOLD)
        print(f"{label}: chaotic of completed per coupling: "
              + ", ".join(f"{v:g}: {c}/{n}" for v, c, n in zip(counts.values, counts.chaotic, counts.orbits)))


if __name__ == "__main__":
    main()
