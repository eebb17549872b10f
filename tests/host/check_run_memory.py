"""A run's memory is estimated before anything runs (nonsep::host::memory_issue): the attack's job, Lyapunov
exponents with 32 tangent vectors of 16 states on a lattice_chain of 2^20 sites, is refused by `nonsep validate` and
by `nonsep run` with exit status 2, the figures and the keys of its largest parts, at once, instead of passing
validation and dying of std::bad_alloc at its first checkpoint. The memory available is made the same on every
machine by RLIMIT_AS (ulimit -v, one of the limits the estimate is compared with); a small job runs under the same
limit.

    check_run_memory.py --nonsep NONSEP
"""
import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

LIMIT = 8 << 30  # bytes of address space: far below the job's need on every machine, far above a small run's


def limited():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--nonsep", required=True)
    arguments = parser.parse_args()
    problems = []
    sites = 1 << 20
    with tempfile.TemporaryDirectory(prefix="nonsep-run-memory-") as folder:
        folder = Path(folder)
        job = {
            "model": {"plugin": "lattice_chain", "parameters": {"sites": sites}},
            "integrator": {"scheme": "basic"},
            "initial": {"grid": {"q": [{"values": [0.01 * i for i in range(16)]}] + [0.0] * (sites - 1),
                                 "p": [0.0] * sites}},
            "time": {"dt": 0.01, "steps": 10},
            "output": {"directory": "out", "every": 0},
            "analysis": {"lyapunov": {"vectors": 32}},
        }
        (folder / "lattice.json").write_text(json.dumps(job))
        for command in (["validate"], ["run", "--quiet"]):
            start = time.monotonic()
            result = subprocess.run([arguments.nonsep, *command, str(folder / "lattice.json")], cwd=folder,
                                    capture_output=True, text=True, timeout=300, preexec_fn=limited)
            seconds = time.monotonic() - start
            expected = ["found a run that needs about", "GiB of memory", "(/analysis/lyapunov)", "available ("]
            if result.returncode != 2 or any(text not in result.stderr for text in expected):
                problems.append(f"nonsep {command[0]} of the Lyapunov job: exit {result.returncode}, expected 2 and "
                                f"{expected}:\n{result.stderr[-3000:]}")
            print(f"nonsep {command[0]}: exit {result.returncode} in {seconds:.1f} s")
        if (folder / "out").exists():
            problems.append("the refused run made its output folder")
        quickstart_job = Path(__file__).resolve().parents[2] / "examples/jobs/quickstart.json"
        quickstart = subprocess.run([arguments.nonsep, "run", "--quiet", "--threads", "2", "--output",
                                     str(folder / "quick"), str(quickstart_job)],
                                    capture_output=True, text=True, timeout=300, preexec_fn=limited)
        if quickstart.returncode != 0:
            problems.append(f"the quickstart under the same limit: exit {quickstart.returncode}:\n"
                            f"{quickstart.stderr[-3000:]}")
    for problem in problems:
        print("FAILED:", problem)
    print(f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
