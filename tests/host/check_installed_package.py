"""The installed package is self-contained and relocatable: `cmake --install` of the build into a temporary
prefix, which is then moved to another folder under another name; the moved copy, with NONSEP_PLUGIN_PATH unset,
finds its own plugins, names its own manual in --help, writes example jobs that validate against its plugins,
its executable holds no path of the build tree (a byte search of the whole file, which finds everything
`strings` would), and a formula model compiled by the build tree's nonsep is found in the cache by the installed
one (the cache key is what determines the plugin, not where the headers are; a stand-in compiler that copies the
installed paper1d.so keeps the check fast).

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


def check_shared_formula_cache(build_nonsep, installed_nonsep, plugin, folder, environment, expect):
    fake = folder / "fake-c++"
    log = folder / "compiles.log"
    fake.write_text("#!/bin/sh\n"
                    "if [ \"$1\" = --version ]; then echo 'fake compiler 1'; exit 0; fi\n"
                    f"echo call >> '{log}'\n"
                    "out=''; previous=''\n"
                    "for a in \"$@\"; do [ \"$previous\" = -o ] && out=\"$a\"; previous=\"$a\"; done\n"
                    f"cp '{plugin}' \"$out\"\n")
    fake.chmod(0o700)
    cache_environment = dict(environment, NONSEP_CXX=str(fake), NONSEP_CACHE_DIR=str(folder / "formula-cache"))
    job = folder / "formula.json"
    job.write_text(json.dumps({
        "model": {"formula": {"name": "paper1d", "T": "p0 + p0^3/6", "V": "q0^2/2 + q0^4/12"}},
        "integrator": {"scheme": "triplet", "order": "4/3", "t2": -2.0},
        "initial": {"q": [0.5], "p": [0.25]}, "time": {"dt": 0.01, "steps": 10}, "output": {"every": 0}}))
    for executable, output in ((build_nonsep, "by-build"), (installed_nonsep, "by-install")):
        result = subprocess.run([str(executable), "run", "--quiet", "-o", str(folder / output), str(job)],
                                cwd=folder, env=cache_environment, capture_output=True, text=True)
        expect(result.returncode == 0, f"{executable} run formula.json: exit {result.returncode}: {result.stderr}")
    calls = log.read_text().count("call") if log.exists() else 0
    expect(calls == 1, f"the formula was compiled {calls} times by the build tree's and the installed nonsep, "
           "expected once (one cache entry for both)")


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

        check_shared_formula_cache(arguments.build / "bin" / "nonsep", executable, plugins / "paper1d.so", folder,
                                   environment, expect)

        binary = executable.read_bytes()
        for tree in sorted({arguments.build.resolve(), arguments.build.absolute()}):
            expect(str(tree).encode() not in binary, f"bin/nonsep holds the build tree's path {tree}")

    for problem in problems:
        print("FAILED:", problem)
    print(f"{len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
