#!/usr/bin/env python3
"""The progress bar of `nonsep run`: drawn on stderr when stderr is a terminal (here a pseudo-terminal) and the run
takes longer than a second, cleared when the run ends; never drawn with --quiet, nor when stderr is not a terminal.

Each run is a job of 10^9 steps stopped with SIGINT (exit 130) once the bar has appeared, or after 2 s, so the test
takes a few seconds whatever the build's speed.
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


def run(nonsep, job, quiet, terminal, wait_for_bar):
    master, slave = pty.openpty()
    args = [nonsep, "run", job] + (["--quiet"] if quiet else [])
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL,
                               stderr=slave if terminal else subprocess.PIPE, close_fds=True)
    os.close(slave)
    seen = b""
    deadline = time.monotonic() + (30 if wait_for_bar else 2)
    while time.monotonic() < deadline and process.poll() is None:
        seen += read_available(master, 0.05) if terminal else b""
        if not terminal:
            time.sleep(0.05)
        if wait_for_bar and b"\r[" in seen and b"active" in seen.split(b"\r[")[-1]:
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
                   "output": {"every": 0}, "checkpoint": {"every_seconds": 0}}, file)
    failures = []

    status, shown = run(nonsep, job, quiet=False, terminal=True, wait_for_bar=True)
    bars = shown.split("\r[")[1:]
    if status != 130:
        failures.append(f"terminal: exit status {status}, expected 130 (SIGINT)")
    if not bars:
        failures.append("terminal: no progress bar drawn")
    else:
        bar = bars[0]
        for part in ("%", "step ", "/1000000000", "t = ", "1 active", "s left"):
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

    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    if failures:
        print(f"last stderr:\n{shown!r}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
