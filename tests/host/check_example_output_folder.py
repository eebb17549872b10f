"""`nonsep example NAME --output FILE` names the job's output folder after FILE (orbit.json -> orbit.out, as the
default output folder of a job file is), so the README's `nonsep example --output orbit.json && nonsep run orbit.json`
writes orbit.out and two copies of one example never share a folder; on standard output the example is unchanged.
Run by ctest as check_example_output_folder.py --nonsep PATH."""
import argparse
import json
import os
import subprocess
import sys
import tempfile


def nonsep(binary, folder, *args):
    return subprocess.run([binary, *args], cwd=folder, capture_output=True, text=True, timeout=120)


def directory(folder, name):
    with open(os.path.join(folder, name)) as file:
        return json.load(file)["output"]["directory"]


def expect(condition, message):
    if not condition:
        sys.exit(message)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--nonsep", required=True)
    binary = os.path.abspath(parser.parse_args().nonsep)
    with tempfile.TemporaryDirectory() as folder:
        for args, file, expected in [((), "orbit.json", "orbit.out"),
                                     (("figure1",), "fig$1 &.json", "fig$1 &.out"),
                                     (("figure1",), "figure1.json", "figure1.out")]:
            written = nonsep(binary, folder, "example", *args, "--output", file)
            expect(written.returncode == 0, f"nonsep example {args} --output {file}: {written.stderr}")
            found = directory(folder, file)
            expect(found == expected, f"{file}: output.directory is {found!r}, expected {expected!r}")
            validated = nonsep(binary, folder, "validate", file)
            expect(validated.returncode == 0, f"nonsep validate {file}: {validated.stderr}")
        printed = nonsep(binary, folder, "example")
        expect(printed.returncode == 0 and json.loads(printed.stdout)["output"]["directory"] == "quickstart.out",
               f"on standard output the quickstart should keep quickstart.out:\n{printed.stdout}{printed.stderr}")
        run = nonsep(binary, folder, "run", "orbit.json", "--quiet")
        expect(run.returncode == 0, f"nonsep run orbit.json: {run.returncode} {run.stderr}")
        expect(os.path.isfile(os.path.join(folder, "orbit.out", "summary.json")), "orbit.json did not write orbit.out")
        expect(not os.path.exists(os.path.join(folder, "quickstart.out")), "orbit.json wrote quickstart.out")
    print("nonsep example --output FILE names the output folder after FILE")


if __name__ == "__main__":
    main()
