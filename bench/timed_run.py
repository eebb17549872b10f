"""One `nonsep run` timed as the benchmark scripts beside this file time it: the CPU time (user + system) of the
process and its children, process start and plugin loading included, which a machine shared with other work inflates
less than the wall time, and the wall time. `timed_command` times any other program the same way."""
import resource
import subprocess
import time


def timed_command(argv):
    """Runs argv (its standard output captured); returns (CPU seconds, wall seconds, standard output)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run([str(a) for a in argv], check=True, stdout=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime, wall, done.stdout


def timed_run(nonsep, job, out, threads=1):
    """Runs `nonsep run -q --force --threads THREADS --output OUT JOB`; returns (CPU seconds, wall seconds)."""
    cpu, wall, _ = timed_command([nonsep, "run", "-q", "--force", "--threads", threads, "--output", out, job])
    return cpu, wall
