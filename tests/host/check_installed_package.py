"""The installed package is self-contained and relocatable: `cmake --install` of the build into a temporary
prefix, which is then moved to another folder under another name; the moved copy, with NONSEP_PLUGIN_PATH unset,
finds its own plugins, names its own manual in --help, writes example jobs that validate against its plugins,
and its executable holds no path of the build tree (a byte search of the whole file, which finds everything
`strings` would).

    check_installed_package.py --cmake CMAKE --build BUILD_DIR
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--cmake", required=True)
    parser.add_argument("--build", required=True, type=Path)
    arguments = parser.parse_args()
    problems = []

    def expect(condition, message):
        if not condition:
            problems.append(message)

    with tempfile.TemporaryDirectory(prefix="nonsep-installed-") as folder:
        folder = Path(folder)
        prefix = folder / "prefix"
        subprocess.run([arguments.cmake, "--install", str(arguments.build), "--prefix", str(prefix)], check=True,
                       stdout=subprocess.DEVNULL)
        moved = folder / "elsewhere" / "nonsep-copy"
        moved.parent.mkdir()
        shutil.move(str(prefix), str(moved))
        share = moved / "share" / "nonsep"
        for relative in ["README.md", "docs/performance.md", "schemas/job.schema.json", "examples/jobs/quickstart.json",
                         "examples/jobs/ensemble.json", "examples/paper/figure1.json"]:
            expect((share / relative).is_file(), f"the install lacks share/nonsep/{relative}")
        expect(not list(share.glob("examples/*/*.out")), "the install holds outputs of example runs (*.out)")

        executable = moved / "bin" / "nonsep"
        environment = {k: v for k, v in os.environ.items() if k != "NONSEP_PLUGIN_PATH"}
        work = folder / "work"
        work.mkdir()

        def nonsep(*args):
            return subprocess.run([str(executable), *args], cwd=work, env=environment, capture_output=True, text=True)

        models = nonsep("models")
        plugins = moved / "lib" / "nonsep" / "plugins"
        expect(models.returncode == 0, f"nonsep models: exit {models.returncode}: {models.stderr}")
        for name in ["paper1d", "radial", "quadratic_kinetic", "tao_product", "paper2d"]:
            expect(f"{plugins / name}.so" in models.stdout, f"nonsep models does not list {plugins / name}.so:\n"
                   f"{models.stdout}{models.stderr}")
        expect(str(arguments.build) not in models.stdout + models.stderr,
               f"nonsep models mentions the build tree:\n{models.stdout}{models.stderr}")

        help_text = nonsep("--help")
        expect(str(share / "README.md") in help_text.stdout,
               f"nonsep --help does not name the installed manual {share / 'README.md'}:\n{help_text.stdout}")

        job = work / "start.json"
        written = nonsep("example", "--output", str(job))
        expect(written.returncode == 0, f"nonsep example: exit {written.returncode}: {written.stderr}")
        if job.exists():
            expect(json.loads(job.read_text())["$schema"] == str(share / "schemas" / "job.schema.json"),
                   "the example's $schema is not the installed schema")
            validated = nonsep("validate", str(job))
            expect(validated.returncode == 0, f"nonsep validate start.json: {validated.stderr}")
            expect(str(plugins / "paper1d.so") in validated.stdout,
                   f"the example did not use the installed paper1d:\n{validated.stdout}")
        for example in ["examples/jobs/ensemble.json", "examples/paper/figure1.json"]:
            validated = nonsep("validate", str(share / example))
            expect(validated.returncode == 0, f"nonsep validate {example}: {validated.stderr}")

        binary = executable.read_bytes()
        for tree in sorted({arguments.build.resolve(), arguments.build.absolute()}):
            expect(str(tree).encode() not in binary, f"bin/nonsep holds the build tree's path {tree}")

    for problem in problems:
        print("FAILED:", problem)
    print(f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
