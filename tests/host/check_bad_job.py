#!/usr/bin/env python3
"""One bad job file: `nonsep validate` and `nonsep run` must both exit 2 and name every expected JSON path in
stderr; with --schema, schemas/job.schema.json must reject the file too (files the schema cannot judge, such as
JSON syntax errors or a plugin's parameters, are run without --schema)."""
import argparse
import json
import re
import subprocess
import sys
import tempfile

import jsonschema


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--nonsep", required=True)
    parser.add_argument("--job", required=True)
    parser.add_argument("--path", action="append", default=[], help="a JSON path the message must name")
    parser.add_argument("--schema", help="the job schema, which must reject the file")
    args = parser.parse_args()
    failures = []

    for command in (["validate", args.job], ["run", "--quiet", "--output", tempfile.mkdtemp(), args.job]):
        result = subprocess.run([args.nonsep, *command], capture_output=True, text=True, timeout=60)
        if result.returncode != 2:
            failures.append(f"`nonsep {command[0]}` exited {result.returncode}, expected 2")
        for path in args.path:
            # Issues are printed as "  <path>: found ...", the whole document as "(document)".
            shown = path if path else "(document)"
            # An issue runs from its "  <path>: found" line to the next issue (a plugin's search list spans lines).
            starts = [m.start() for m in re.finditer(r"^  \S*: found", result.stderr, re.MULTILINE)] + [None]
            issues = [result.stderr[a:b] for a, b in zip(starts, starts[1:])]
            named = [issue for issue in issues if issue.startswith(f"  {shown}: found")]
            if not named:
                failures.append(f"`nonsep {command[0]}` did not name {shown!r}")
            elif not all("; allowed: " in line for line in named):
                failures.append(f"`nonsep {command[0]}` did not say what is allowed at {shown!r}")
        if not args.path:
            failures.append("no expected path given")
        if failures:
            failures.append(f"stderr of `nonsep {command[0]}`:\n{result.stderr}")
            break

    if args.schema:
        with open(args.schema) as file:
            schema = json.load(file)
        with open(args.job) as file:
            job = json.load(file)
        errors = list(jsonschema.Draft202012Validator(schema).iter_errors(job))
        if not errors:
            failures.append("the schema accepts this bad job")

    for failure in failures:
        print(f"FAIL {args.job}: {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
