"""scripts/job_file_reference.py does what docs.job_file_reference relies on: --check exits 1 when the reference
differs from what the schema gives (and 0 when it is the same), and the script exits 2, naming what it would
leave out, for a schema with a key or a description the reference would not show.
Usage: check_job_file_reference.py SOURCE_DIR"""
import json
import pathlib
import subprocess
import sys
import tempfile

root = pathlib.Path(sys.argv[1])
script = root / "scripts" / "job_file_reference.py"
schema = json.loads((root / "schemas" / "job.schema.json").read_text(encoding="utf-8"))
failures = []


def run(*arguments):
    return subprocess.run([sys.executable, str(script), *map(str, arguments)], capture_output=True, text=True)


with tempfile.TemporaryDirectory() as folder:
    folder = pathlib.Path(folder)
    schema_file, reference = folder / "job.schema.json", folder / "job-file.md"
    schema_file.write_text(json.dumps(schema), encoding="utf-8")
    written = run("--schema", schema_file, "--output", reference)
    if written.returncode != 0:
        failures.append(f"writing the reference of the shipped schema: exit {written.returncode}, {written.stderr}")
    elif run("--schema", schema_file, "--output", reference, "--check").returncode != 0:
        failures.append("--check fails on the reference just written")
    else:
        reference.write_text(reference.read_text(encoding="utf-8").replace("Momenta, as many as q.", "Momenta."))
        if run("--schema", schema_file, "--output", reference, "--check").returncode != 1:
            failures.append("--check does not exit 1 for a reference that differs from the schema")
    schema["$defs"]["unreferenced"] = {"type": "object",
                                      "properties": {"ghost": {"type": "number", "description": "never shown"}}}
    schema_file.write_text(json.dumps(schema), encoding="utf-8")
    refused = run("--schema", schema_file, "--output", folder / "ghost.md")
    if refused.returncode != 2 or "key ghost" not in refused.stderr or "never shown" not in refused.stderr:
        failures.append(f"a key the reference would not show: exit {refused.returncode}, {refused.stderr!r}")
for failure in failures:
    print(f"job_file_reference: {failure}")
sys.exit(1 if failures else 0)
