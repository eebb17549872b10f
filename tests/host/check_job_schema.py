#!/usr/bin/env python3
"""Keeps schemas/job.schema.json true: the schema is valid draft 2020-12; every example job validates against it
and passes `nonsep validate`; every bad job file is listed in tests/host/jobs/bad_jobs.json (each one is then
checked by its own test, check_bad_job.py); the integrator part of the schema matches `nonsep --help`'s scheme
catalogue (names and defaults)."""
import argparse
import glob
import json
import os
import re
import subprocess
import sys

import jsonschema


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--schema", required=True)
    parser.add_argument("--examples", required=True, action="append", help="a folder of example job files (repeatable)")
    parser.add_argument("--jobs", required=True, help="tests/host/jobs")
    args = parser.parse_args()
    failures = []

    with open(args.schema) as file:
        schema = json.load(file)
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)

    examples = sorted(path for folder in args.examples for path in glob.glob(os.path.join(folder, "*.json")))
    if len(examples) < 3:
        failures.append(f"expected at least 3 example jobs in {args.examples}, found {len(examples)}")
    for example in examples:
        with open(example) as file:
            job = json.load(file)
        for error in validator.iter_errors(job):
            failures.append(f"{example}: schema: {error.json_path}: {error.message}")
        result = subprocess.run([args.nonsep, "validate", example], capture_output=True, text=True, timeout=60)
        if result.returncode != 0:
            failures.append(f"{example}: `nonsep validate` exited {result.returncode}:\n{result.stderr}")

    with open(os.path.join(args.jobs, "bad_jobs.json")) as file:
        manifest = json.load(file)["jobs"]
    on_disk = {os.path.relpath(path, args.jobs).replace(os.sep, "/")
               for folder in ("bad", "bad_host_only") for path in glob.glob(os.path.join(args.jobs, folder, "*.json"))}
    for missing in sorted(on_disk - set(manifest)):
        failures.append(f"{missing} is not listed in bad_jobs.json, so no test checks it")
    for extra in sorted(set(manifest) - on_disk):
        failures.append(f"bad_jobs.json lists {extra}, which does not exist")

    # The schema's integrator options against the catalogue as `nonsep --help` prints it:
    #   "  <scheme>: ..." then "      <option> (default <text>): ...".
    help_text = subprocess.run([args.nonsep, "--help"], capture_output=True, text=True, timeout=60).stdout
    catalogue = {}
    current = None
    for line in help_text.split("Exit status:")[0].splitlines():
        if m := re.match(r"^  (\w+): ", line):
            current = catalogue.setdefault(m.group(1), {})
        elif (m := re.match(r"^      (\w+) \((?:default (\S+)|required)\): ", line)) and current is not None:
            current[m.group(1)] = m.group(2)
    # A run's /integrator and a study's integrators (which add label, steps and dt) both follow the catalogue.
    for where, integrator, own_keys in (("/integrator", schema["properties"]["integrator"], {"scheme"}),
                                        ("study integrators", schema["$defs"]["study_integrator"],
                                         {"scheme", "label", "steps", "dt"})):
        schema_schemes = integrator["properties"]["scheme"]["enum"]
        if sorted(schema_schemes) != sorted(catalogue):
            failures.append(f"{where}: schema schemes {schema_schemes} differ from the catalogue's {sorted(catalogue)}")
        for branch in integrator["allOf"]:
            name = branch["if"]["properties"]["scheme"]["const"]
            options = {key: value for key, value in branch["then"]["properties"].items() if key not in own_keys}
            expected = catalogue.get(name, {})
            if sorted(options) != sorted(expected):
                failures.append(f"{where}: schema options of {name} {sorted(options)} differ from the catalogue's {sorted(expected)}")
            for option, default_text in expected.items():
                default = options.get(option, {}).get("default")
                if default is None or (default != default_text and not (isinstance(default, float) and default == float(default_text))):
                    failures.append(f"{where}: schema default of {name}.{option} is {default!r}, the catalogue's is {default_text}")

    # The keys of /analysis and of its objects: the reader's (as `nonsep validate` lists them for an unknown key)
    # against the schema's properties.
    base = {"model": {"plugin": "paper2d"}, "integrator": {"scheme": "basic"},
            "initial": {"q": [0.25, 0.3], "p": [-1.5, 0.2]}, "time": {"dt": 0.01, "steps": 1}}
    analysis_schema = schema["properties"]["analysis"]
    for where, analysis, properties in (
            ("/analysis", {"unknown_key": 1}, analysis_schema["properties"]),
            ("/analysis/poincare", {"poincare": {"component": "q0", "unknown_key": 1}},
             analysis_schema["properties"]["poincare"]["properties"]),
            ("/analysis/lyapunov", {"lyapunov": {"unknown_key": 1}},
             analysis_schema["properties"]["lyapunov"]["properties"])):
        job_path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"nonsep_schema_keys_{os.getpid()}.json")
        with open(job_path, "w") as file:
            json.dump(dict(base, analysis=analysis), file)
        result = subprocess.run([args.nonsep, "validate", job_path], capture_output=True, text=True, timeout=60)
        os.remove(job_path)
        match = re.search(re.escape(where) + r"/unknown_key: .*allowed: only the keys? (.*)", result.stderr)
        if not match:
            failures.append(f"{where}: `nonsep validate` did not list the allowed keys:\n{result.stderr}")
            continue
        reader_keys = sorted(key.strip() for key in match.group(1).split(","))
        if reader_keys != sorted(properties):
            failures.append(f"{where}: the reader accepts {reader_keys}, the schema {sorted(properties)}")

    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    print(f"{len(examples)} examples, {len(on_disk)} bad jobs listed, {len(catalogue)} schemes checked")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
