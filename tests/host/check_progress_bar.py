#!/usr/bin/env python3
"""The progress of `nonsep run`: a bar drawn on stderr when stderr is a terminal (here a pseudo-terminal) and the run
takes longer than a second, cleared when the run ends; never drawn with --quiet, nor when stderr is not a terminal.
When stderr is a file, plain progress lines every --progress-every seconds instead (none with 0, nor with --quiet).

Each run is a job of 10^9 steps stopped with SIGINT (exit 130) once the bar has appeared or, where no bar may
appear, once the run has written its first checkpoint, which it does after 2 s of its own wall time (past the bar's
one second): the test waits on what it needs to see, never a fixed time.
"""
import argparse
import json
import os
import pty
import select
import signal
import subprocess
import sys
import tempfile
import time


def read_available(master, wait):
    """What the pseudo-terminal has to read within `wait` seconds (b"" if nothing, or once the child has closed it)."""
    try:
        if select.select([master], [], [], wait)[0]:
            return os.read(master, 65536)
    except OSError:  # EIO: every writer has gone
        pass
    return b""


def run(nonsep, job, quiet, terminal, wait_for_bar, extra=(), stderr_file=None):
    """Runs the job until the bar has appeared (wait_for_bar) or its first checkpoint exists, then sends SIGINT;
    returns the exit status and what was shown on stderr. Gives up waiting after 30 s (the checks then fail)."""
    checkpoint = os.path.splitext(job)[0] + ".out/checkpoint.json"
    if os.path.exists(checkpoint):
        os.remove(checkpoint)
    master, slave = pty.openpty()
    # --force: each run starts over in the folder the previous, interrupted one left with a checkpoint.
    args = [nonsep, "run", job, "--force"] + (["--quiet"] if quiet else []) + list(extra)
    log = open(stderr_file, "wb") if stderr_file else None
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL,
                               stderr=slave if terminal else log or subprocess.PIPE, close_fds=True)
    os.close(slave)
    seen = b""
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and process.poll() is None:
        if terminal:
            seen += read_available(master, 0.05)
        else:
            select.select([], [], [], 0.01)  # polling interval: the loop ends on the condition below
        if wait_for_bar and b"\r[" in seen and b"active" in seen.split(b"\r[")[-1]:
            break
        if not wait_for_bar and os.path.exists(checkpoint):
            break
    process.send_signal(signal.SIGINT)
    if terminal:
        deadline = time.monotonic() + 30
        while process.poll() is None and time.monotonic() < deadline:
            seen += read_available(master, 0.05)
        status = process.wait(timeout=30)
        while chunk := read_available(master, 0.1):
            seen += chunk
    else:
        _, seen = process.communicate(timeout=30)
        status = process.returncode
    if log:
        log.close()
        with open(stderr_file, "rb") as file:
            seen = file.read()
    os.close(master)
    return status, seen.decode(errors="replace")


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--nonsep", required=True)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        return check(args.nonsep, os.path.join(folder, "long.json"))


def check(nonsep, job):
    with open(job, "w") as file:
        json.dump({"model": {"plugin": "paper1d"}, "integrator": {"scheme": "basic"},
                   "initial": {"q": [1.0], "p": [0.0]}, "time": {"dt": 1e-6, "steps": 1000000000},
                   "output": {"every": 0, "energy_every": 100000}, "checkpoint": {"every_steps": 0, "every_seconds": 2}}, file)
    failures = []

    status, shown = run(nonsep, job, quiet=False, terminal=True, wait_for_bar=True)
    bars = shown.split("\r[")[1:]
    if status != 130:
        failures.append(f"terminal: exit status {status}, expected 130 (SIGINT)")
    if not bars:
        failures.append("terminal: no progress bar drawn")
    else:
        bar = bars[0]
        for part in ("%", "step ", "/1000000000", "t = ", "1 active", "max |dH/H0| ", "s left"):
            if part not in bar:
                failures.append(f"terminal: the bar {bar[:120]!r} lacks {part!r}")
        if "\r\x1b[K" not in shown.split("\r[")[-1]:
            failures.append("terminal: the bar was not cleared when the run ended")
    if "stopped by SIGINT" not in shown:
        failures.append("terminal: no 'stopped by SIGINT' message")

    status, shown = run(nonsep, job, quiet=True, terminal=True, wait_for_bar=False)
    drawn = "\r[" in shown
    if status != 130 or drawn:
        failures.append(f"--quiet: exit status {status}, bar drawn: {drawn}")

    status, shown = run(nonsep, job, quiet=False, terminal=False, wait_for_bar=False)
    drawn = "\r[" in shown
    if status != 130 or drawn:
        failures.append(f"stderr not a terminal: exit status {status}, bar drawn: {drawn}")

    # stderr to a file: a progress line every 0.5 s; the run lasts past its first checkpoint (2 s), so several.
    log = os.path.join(os.path.dirname(job), "stderr.log")
    status, shown = run(nonsep, job, quiet=False, terminal=False, wait_for_bar=False,
                        extra=["--progress-every", "0.5"], stderr_file=log)
    lines = [line for line in shown.splitlines() if line.startswith("nonsep: progress: ")]
    escapes = "\r" in shown or "\x1b" in shown
    if status != 130 or len(lines) < 2 or escapes:
        failures.append(f"stderr to a file: exit status {status}, {len(lines)} progress lines, escapes: {escapes}")
    for line in lines[:1]:
        for part in ("t = ", " of 1000", "%)", "step ", "/1000000000", "1 active", "max |dH/H0| ", "ETA ", " s"):
            if part not in line:
                failures.append(f"stderr to a file: the line {line!r} lacks {part!r}")
    status, shown = run(nonsep, job, quiet=False, terminal=False, wait_for_bar=False,
                        extra=["--progress-every", "0"], stderr_file=log)
    if status != 130 or "progress" in shown:
        failures.append(f"--progress-every 0: exit status {status}, progress shown: {'progress' in shown}")
    status, shown = run(nonsep, job, quiet=True, terminal=False, wait_for_bar=False,
                        extra=["--progress-every", "0.5"], stderr_file=log)
    if status != 130 or "progress" in shown:
        failures.append(f"--quiet, stderr to a file: exit status {status}, progress shown: {'progress' in shown}")

    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    if failures:
        print(f"last stderr:\n{shown!r}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
