"""`nonsep validate` on a grid put on an energy shell says how many of the grid's states were left out, so that a
grid of 9 points validating as fewer states does not look like a mistake in the grid; a plain grid says nothing of a
shell. Run by ctest as check_validate_energy_shell.py --nonsep PATH."""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def validate(nonsep, folder, job):
    path = os.path.join(folder, "job.json")
    with open(path, "w") as file:
        json.dump(job, file)
    done = subprocess.run([nonsep, "validate", path], capture_output=True, text=True, timeout=60)
    if done.returncode != 0:
        sys.exit(f"nonsep validate exited with {done.returncode}:\n{done.stderr}")
    lines = [line for line in done.stdout.splitlines() if line.strip().startswith("initial:")]
    if len(lines) != 1:
        sys.exit(f"no single 'initial:' line in:\n{done.stdout}")
    return lines[0].split(":", 1)[1].strip()


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--nonsep", required=True)
    args = parser.parse_args()
    # paper2d at coupling 0.2 has H >= 2 + |p|^2 + 0.4 |q|^2 (docs/writing-models.md, shipped models), so on the shell H = 3 the
    # 6 grid points with |q0| = 2 (H >= 3.6 at p1 = 0) are left out and the 3 with q0 = 0 (H about 2) are kept.
    job = {
        "model": {"plugin": "paper2d", "parameters": {"coupling": 0.2}},
        "integrator": {"scheme": "mpe", "order": 4},
        "initial": {"grid": {"q": [{"values": [-2.0, 0.0, 2.0]}, 0.0], "p": [{"values": [-0.1, 0.0, 0.1]}, 0.0]},
                    "energy": 3.0, "solve_for": "p1"},
        "time": {"dt": 0.01, "steps": 10},
    }
    with tempfile.TemporaryDirectory() as folder:
        shell = validate(args.nonsep, folder, job)
        kept = int(shell.split()[0])
        expected = (f"{kept} states (grid on the energy shell H = 3, p1 solved for; {9 - kept} of its 9 states "
                    "cannot reach it and are left out)")
        if kept != 3 or shell != expected:
            sys.exit(f"expected 3 states kept: {expected!r}, found {shell!r}")
        del job["initial"]["energy"], job["initial"]["solve_for"]
        plain = validate(args.nonsep, folder, job)
        if plain != "9 states (grid)":
            sys.exit(f"expected '9 states (grid)' without a shell, found {plain!r}")
    print(f"validate: {shell}; without a shell: {plain}")


if __name__ == "__main__":
    main()
