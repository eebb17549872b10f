"""nonsep's Gauss-Legendre path against its hand-written limit (nonsep_bench_gauss_limit, bench/gauss_limit.cpp: the
same tableau, starting values, stopping rule and compensated sum, paper1d's grad H inline, one state at a time).

Usage: /usr/bin/python3 bench/gauss_limit.py BUILD_BIN [--repeats 5] [--stages 3] [--dt 0.01] [--steps 2000]
  BUILD_BIN: the folder with nonsep and nonsep_bench_gauss_limit (cmake -DNONSEP_BUILD_BENCHMARKS=ON).

1024 paper1d orbits, q0 = 0.2 + 1.8 j / 1024, p0 = 0, one thread, each program a process timed alike (CPU time of
the process, timed_run.py), alternately. Prints per state and step: the medians (and ranges) of both, their ratio,
the iterations per step of each (nonsep's from summary.json's grad_H / stages), and the largest distance between
their end states (round-off: the two sum grad H in different orders).
"""
import argparse
import csv
import json
import math
import statistics
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timed_run import timed_command, timed_run  # noqa: E402


def read_states(path):
    return [(float(r["q0"]), float(r["p0"])) for r in csv.DictReader(open(path))]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("bin", type=Path)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--stages", type=int, default=3)
    parser.add_argument("--dt", type=float, default=0.01)
    parser.add_argument("--steps", type=int, default=2000)
    args = parser.parse_args()
    count = 1024
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        states = folder / "states.csv"
        states.write_text("q0,p0\n" + "".join(f"{0.2 + 1.8 * j / count!r},0\n" for j in range(count)))
        job = folder / "job.json"
        job.write_text(json.dumps({"model": {"plugin": "paper1d"},
                                   "integrator": {"scheme": "gauss", "stages": args.stages},
                                   "initial": {"file": str(states)},
                                   "time": {"dt": args.dt, "steps": args.steps}, "output": {"every": 0}}))
        limit_out = folder / "limit.csv"
        host, limit = [], []
        for _ in range(args.repeats):
            host.append(timed_run(args.bin / "nonsep", job, folder / "out")[0])
            cpu, _, printed = timed_command([args.bin / "nonsep_bench_gauss_limit", args.stages, args.dt, args.steps,
                                             states, limit_out])
            limit.append(cpu)
            limit_iterations = float(printed.split()[0])
        summary = json.loads((folder / "out" / "summary.json").read_text())
        host_iterations = summary["evaluations"]["grad_H"] / args.stages / count / args.steps
        ended = [(float(r["q0"]), float(r["p0"])) for r in csv.DictReader(open(folder / "out" / "trajectories.csv"))]
        distance = max(math.dist(a, b) for a, b in zip(ended, read_states(limit_out)))
    per = count * args.steps * 1e-9

    def text(times):
        return f"{statistics.median(times) / per:.1f} ns ({min(times) / per:.1f}-{max(times) / per:.1f})"
    print(f"paper1d, {count} orbits, gauss {args.stages} stages, dt {args.dt}, {args.steps} steps, one thread, "
          f"{args.repeats} alternate runs, CPU time of each process per state and step")
    print(f"nonsep run: {text(host)}, {host_iterations:.3f} iterations per step")
    print(f"hand-written limit: {text(limit)}, {limit_iterations:.3f} iterations per step")
    print(f"ratio: {statistics.median(host) / statistics.median(limit):.2f} "
          f"(pairwise {min(h / l for h, l in zip(host, limit)):.2f}-{max(h / l for h, l in zip(host, limit)):.2f}); "
          f"end states within {distance:.1e}")


if __name__ == "__main__":
    main()
