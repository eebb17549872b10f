"""Work against precision on ensembles: `nonsep run` with scheme auto (what a user runs) and Gauss 16 at a ladder of
steps, against Boost.Odeint's explicit adaptive methods (dopri5, fehlberg78, bulirsch_stoer), each a process timed
alike (CPU time of the process, one thread: timed_run.py). The table of docs/performance-peers.md ("Ensembles").

Usage: /usr/bin/python3 bench/ensemble_work_precision.py BUILD_BIN WORK_FOLDER [--repeats 3] [--problems paper1d,paper2d]
  BUILD_BIN: the folder with nonsep and nonsep_bench_ensemble_peer (cmake -DNONSEP_BUILD_BENCHMARKS=ON).

Ensembles (1024 states each, written to WORK_FOLDER as CSV and read by both programs):
  paper1d  q0 = 0.2 + 1.8 j / 1024, p0 = 0, to t = 10;
  paper2d  (coupling 0.2) q = (0, 0), p = (0.5 + 0.08 j / 1024, 2), to t = 100: regular orbits (starts 1e-15 and 1e-13
           apart in tolerance stay within 1e-6 of each other at t = 100; the orbits beyond p1 = 0.59 separate more).
The error of a run is the largest phase-space distance at t_end over the ensemble from the reference, Odeint's
fehlberg78 at tolerance 1e-15; the reference is checked against nonsep's Gauss 16 at dt = t_end / 5000 (another
method, another program), and that distance is printed: errors near it are the reference's, not the run's.
For each target error (1e-6, 1e-8, 1e-10): auto at that tolerance (its actual error, its CPU time), and the cheapest
run of each peer's tolerance ladder (10^(-k/2)) and of Gauss 16's step ladder that meets the target. Prints the
markdown table and writes WORK_FOLDER/ensemble_work_precision.json with every run.
"""
import argparse
import csv
import json
import math
import statistics
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timed_run import timed_command, timed_run  # noqa: E402

PROBLEMS = {
    "paper1d": {"model": {"plugin": "paper1d"}, "t_end": 10.0, "n": 1,
                "states": [([0.2 + 1.8 * j / 1024], [0.0]) for j in range(1024)],
                "gauss16_steps": [64, 70, 80, 100, 128, 160]},
    "paper2d": {"model": {"plugin": "paper2d"}, "t_end": 100.0, "n": 2,
                "states": [([0.0, 0.0], [0.5 + 0.08 * j / 1024, 2.0]) for j in range(1024)],
                "gauss16_steps": [400, 500, 640, 800, 1000, 1280, 1600]},
}
PEERS = ["dopri5", "fehlberg78", "bulirsch_stoer"]
PEER_TOLERANCES = [10.0 ** (-k / 2) for k in range(10, 29)]  # 1e-5 .. 1e-14
TARGETS = [1e-6, 1e-8, 1e-10]


def read_states(path, n):
    rows = list(csv.DictReader(open(path)))
    return [[float(r[f"q{i}"]) for i in range(n)] + [float(r[f"p{i}"]) for i in range(n)] for r in rows]


def largest_distance(a, b):
    return max(math.dist(x, y) for x, y in zip(a, b))


def median_cpu(run, repeats):
    times = [run() for _ in range(repeats)]
    return statistics.median(times), min(times), max(times)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("bin", type=Path)
    parser.add_argument("work", type=Path)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--problems", default="paper1d,paper2d")
    args = parser.parse_args()
    nonsep, peer = args.bin / "nonsep", args.bin / "nonsep_bench_ensemble_peer"
    args.work.mkdir(parents=True, exist_ok=True)
    results = {}
    lines = ["| problem | target | auto: scheme, steps | actual | auto CPU s | fastest peer meeting it | its error | "
             "peer CPU s | auto / peer | Gauss 16, cheapest run meeting it | its CPU s |", "|" + "---|" * 11]
    for name in args.problems.split(","):
        problem = PROBLEMS[name]
        n, t_end = problem["n"], problem["t_end"]
        folder = args.work / name
        folder.mkdir(exist_ok=True)
        states = folder / "states.csv"
        with open(states, "w") as out:
            out.write(",".join([f"q{i}" for i in range(n)] + [f"p{i}" for i in range(n)]) + "\n")
            for q, p in problem["states"]:
                out.write(",".join(repr(v) for v in q + p) + "\n")

        def nonsep_job(integrator, dt, label):
            job = {"model": problem["model"], "integrator": integrator, "initial": {"file": str(states.resolve())},
                   "time": {"dt": dt, "t_end": t_end}, "output": {"every": 0}}
            path = folder / f"{label}.json"
            path.write_text(json.dumps(job))
            return path

        reference = folder / "reference.csv"
        timed_command([peer, name, "fehlberg78", 1e-15, t_end, states, reference])
        exact = read_states(reference, n)
        check_job = nonsep_job({"scheme": "gauss", "stages": 8}, t_end / 5000, "reference_check")
        timed_run(nonsep, check_job, folder / "reference_check", threads=2)
        reference_check = largest_distance(exact, read_states(folder / "reference_check" / "trajectories.csv", n))
        print(f"{name}: reference (fehlberg78 1e-15) against Gauss 16 at dt = t_end / 5000: {reference_check:.1e}",
              file=sys.stderr)
        runs = []

        def run_nonsep(label, integrator, dt):
            job = nonsep_job(integrator, dt, label)
            out = folder / label
            try:
                cpu = median_cpu(lambda: timed_run(nonsep, job, out)[0], args.repeats)
            except subprocess.CalledProcessError:  # a step too large for the implicit iteration: it meets nothing
                print(f"{name} {label}: failed", file=sys.stderr)
                return None
            ended = read_states(out / "trajectories.csv", n)
            summary = json.loads((out / "summary.json").read_text())
            choice = summary.get("scheme_choice") or {}
            run = {"who": "nonsep", "label": label, "integrator": integrator, "error": largest_distance(exact, ended),
                   "cpu": cpu, "chosen": choice.get("chosen"), "steps": choice.get("subdivision")}  # dt = t_end
            runs.append(run)
            print(f"{name} {label}: error {run['error']:.2e}, CPU {cpu[0]:.3f} s", file=sys.stderr)
            return run

        for target in TARGETS:
            run_nonsep(f"auto_{target:g}", {"scheme": "auto", "tolerance": target}, t_end)
        for steps in problem["gauss16_steps"]:
            run_nonsep(f"gauss16_{steps}", {"scheme": "gauss", "stages": 8}, t_end / steps)
        for method in PEERS:
            for tolerance in PEER_TOLERANCES:
                out = folder / f"{method}_{tolerance:.3g}.csv"
                cpu = median_cpu(lambda: timed_command([peer, name, method, tolerance, t_end, states, out])[0],
                                 args.repeats)
                error = largest_distance(exact, read_states(out, n))
                runs.append({"who": "odeint", "label": f"{method} tol={tolerance:.3g}", "error": error, "cpu": cpu})
                print(f"{name} {method} {tolerance:.3g}: error {error:.2e}, CPU {cpu[0]:.3f} s", file=sys.stderr)
        results[name] = {"reference_check": reference_check, "runs": runs}

        def cheapest(candidates, target):
            meeting = [r for r in candidates if r["error"] <= target]
            return min(meeting, key=lambda r: r["cpu"][0]) if meeting else None

        for target in TARGETS:
            auto = next(r for r in runs if r["label"] == f"auto_{target:g}")
            best_peer = cheapest([r for r in runs if r["who"] == "odeint"], target)
            best_gauss = cheapest([r for r in runs if r["label"].startswith("gauss16_")], target)

            def cpu_text(r):
                return f"{r['cpu'][0]:.3f} ({r['cpu'][1]:.3f}-{r['cpu'][2]:.3f})" if r else "-"
            lines.append(
                f"| {name} | {target:.0e} | {auto['chosen']}, {auto['steps']} | {auto['error']:.1e} | {cpu_text(auto)} | "
                f"{best_peer['label'] if best_peer else 'none'} | {best_peer['error']:.1e} | {cpu_text(best_peer)} | "
                f"{auto['cpu'][0] / best_peer['cpu'][0]:.1f} | "
                f"{best_gauss['label'].split('_')[1] + ' steps' if best_gauss else 'none'} | {cpu_text(best_gauss)} |"
                if best_peer else
                f"| {name} | {target:.0e} | {auto['chosen']}, {auto['steps']} | {auto['error']:.1e} | {cpu_text(auto)} | "
                f"none | - | - | - | - | - |")
    (args.work / "ensemble_work_precision.json").write_text(json.dumps(results, indent=1))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
