#!/usr/bin/env python3
"""Two threads of one run against two processes (docs/performance.md, "Two threads against two processes").

One job, 1024 paper1d trajectories (q = 0.1 ... 2, p = 0), basic step, dt = 1e-4, 2*10^5 steps, run by `nonsep run`
three ways, interleaved, REPEATS times: one thread; two threads; and two processes of one thread each started
together (the wall time until both end). Prints per repetition and as medians (with ranges):
  threads    one thread's wall time / two threads' (the speed-up of one run);
  processes  2 x one thread's / the pair's (what two independent processes get out of the machine);
  serial     the wall time of the same job with 1 step: the run's part that two threads do not share out.

    python3 bench/thread_scaling.py build/bin/nonsep [REPEATS] [--busy]

--busy: a process spinning on one core for the whole measurement (the machine's other user).
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def wall(commands, folder):
    start = time.perf_counter()
    processes = [subprocess.Popen(command, cwd=folder) for command in commands]
    for process in processes:
        if process.wait() != 0:
            sys.exit(f"{' '.join(processes[0].args)} failed with exit status {process.returncode}")
    return time.perf_counter() - start


def main():
    arguments = [a for a in sys.argv[1:] if a != "--busy"]
    if not arguments:
        sys.exit(__doc__)
    nonsep = str(Path(arguments[0]).resolve())
    repeats = int(arguments[1]) if len(arguments) > 1 else 7
    folder = Path(tempfile.mkdtemp(prefix="thread_scaling."))
    initial = [{"q": [0.1 + 1.9 * b / 1023], "p": [0.0]} for b in range(1024)]
    job = {"model": {"plugin": "paper1d"}, "integrator": {"scheme": "basic"}, "initial": initial,
           "time": {"dt": 1e-4, "steps": 200000}, "output": {"every": 0}}
    (folder / "job.json").write_text(json.dumps(job))
    job["time"]["steps"] = 1
    (folder / "one_step.json").write_text(json.dumps(job))

    def run(threads, output, name="job.json"):
        return [nonsep, "run", "--quiet", "--force", "--threads", str(threads), "--output", output, name]

    busy = subprocess.Popen([sys.executable, "-c", "while True: pass"]) if "--busy" in sys.argv else None
    threads, processes, serial = [], [], []
    try:
        for r in range(repeats):
            one = wall([run(1, "one")], folder)
            two = wall([run(2, "two")], folder)
            pair = wall([run(1, "a"), run(1, "b")], folder)
            serial.append(wall([run(1, "serial", "one_step.json")], folder))
            threads.append(one / two)
            processes.append(2 * one / pair)
            print(f"{r + 1}: one thread {one:.3f} s, two threads {two:.3f} s, two processes {pair:.3f} s: "
                  f"threads {threads[-1]:.3f}, processes {processes[-1]:.3f}, serial {serial[-1] * 1e3:.1f} ms",
                  flush=True)
    finally:
        if busy:
            busy.kill()
    for name, values in (("threads", threads), ("processes", processes)):
        print(f"{name}: median {statistics.median(values):.3f} (range {min(values):.3f}-{max(values):.3f})")
    print(f"serial: median {statistics.median(serial) * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
