"""Executes examples/tutorial.ipynb headless, as its first cell tells a user to (Debian's nbconvert and ipykernel),
and checks what it shows: every code cell ran without an error, its three pictures were written by the notebook
(tutorial_energy.png, tutorial_poincare.png, tutorial_chaos_map.png in the tutorial folder, each a PNG written during
this run) and appear in the executed notebook as images, and the plugin it builds passed `nonsep inspect --check`.

Usage: /usr/bin/python3 check_tutorial.py NOTEBOOK BUILD_DIR OUT_DIR
"""
import os
import subprocess
import sys
import time
from pathlib import Path

import nbformat

PICTURES = ("tutorial_energy.png", "tutorial_poincare.png", "tutorial_chaos_map.png")


def main():
    notebook, build, out = (Path(arg).resolve() for arg in sys.argv[1:4])
    out.mkdir(parents=True, exist_ok=True)
    for picture in PICTURES:
        (out / picture).unlink(missing_ok=True)
    started = time.time()
    environment = dict(os.environ, NONSEP_BUILD_DIR=str(build), NONSEP_TUTORIAL_DIR=str(out))
    for variable in ("NONSEP_EXECUTABLE", "NONSEP_PLUGIN_PATH", "PYTHONPATH"):  # the notebook's own installation
        environment.pop(variable, None)
    subprocess.run([sys.executable, "-m", "nbconvert", "--to", "notebook", "--execute", str(notebook),
                    "--output-dir", str(out), "--output", "tutorial.executed.ipynb"], env=environment, check=True)
    executed = nbformat.read(out / "tutorial.executed.ipynb", as_version=4)
    failures = []
    images = 0
    for index, cell in enumerate(executed.cells):
        if cell.cell_type != "code":
            continue
        for output in cell.outputs:
            if output.output_type == "error":
                failures.append(f"cell {index}: {output.ename}: {output.evalue}")
            if "image/png" in output.get("data", {}):
                images += 1
    text = "".join(o.get("text", "") for c in executed.cells if c.cell_type == "code" for o in c.outputs)
    if "derivative check passed" not in text:
        failures.append("the tutorial's plugin did not pass `nonsep inspect --check`")
    if images < len(PICTURES):
        failures.append(f"the executed notebook shows {images} images, expected at least {len(PICTURES)}")
    for picture in PICTURES:
        path = out / picture
        if not path.is_file() or path.stat().st_mtime < started - 1:
            failures.append(f"{path} was not written by the notebook")
        elif path.read_bytes()[:8] != b"\x89PNG\r\n\x1a\n":
            failures.append(f"{path} is not a PNG")
    for failure in failures:
        print("check_tutorial:", failure)
    if failures:
        sys.exit(1)
    print(f"check_tutorial: the tutorial ran; {images} images, pictures in {out}")


if __name__ == "__main__":
    main()
