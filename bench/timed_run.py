"""One `nonsep run` timed as the benchmark scripts beside this file time it: the CPU time (user + system) of the
process and its children, process start and plugin loading included, which a machine shared with other work inflates
less than the wall time, and the wall time."""
import resource
import subprocess
import time


def timed_run(nonsep, job, out, threads=1):
    """Runs `nonsep run -q --force --threads THREADS --output OUT JOB`; returns (CPU seconds, wall seconds)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([str(nonsep), "run", "-q", "--force", "--threads", str(threads), "--output", str(out), str(job)],
                   check=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, wall
