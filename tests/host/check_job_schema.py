#!/usr/bin/env python3
"""Keeps schemas/job.schema.json true: it is exactly what `nonsep schema` prints (the schema generated from the job
reader's key tables and the scheme catalogue); it is valid draft 2020-12; every example job validates against it
and passes `nonsep validate`; every bad job file is listed in tests/host/jobs/bad_jobs.json (each one is then
checked by its own test, check_bad_job.py, which for the files in bad/ also requires the schema to reject it)."""
import argparse
import glob
import json
import os
import subprocess
import sys

import jsonschema


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--schema", required=True, help="schemas/job.schema.json")
    parser.add_argument("--examples", required=True, action="append", help="a folder of example job files (repeatable)")
    parser.add_argument("--jobs", required=True, help="tests/host/jobs")
    args = parser.parse_args()
    failures = []

    generated = subprocess.run([args.nonsep, "schema"], capture_output=True, text=True, timeout=60)
    if generated.returncode != 0:
        failures.append(f"`nonsep schema` exited {generated.returncode}:\n{generated.stderr}")
    with open(args.schema) as file:
        kept = file.read()
    if generated.stdout != kept:
        failures.append(f"{args.schema} differs from the output of `nonsep schema`; regenerate it with "
                        f"`build/bin/nonsep schema > schemas/job.schema.json`")
    schema = json.loads(generated.stdout)
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

    for failure in failures:
        print(f"FAIL {failure}", file=sys.stderr)
    print(f"schema matches `nonsep schema`: {generated.stdout == kept}; {len(examples)} examples, "
          f"{len(on_disk)} bad jobs listed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
