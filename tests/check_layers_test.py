#!/usr/bin/env python3
"""scripts/check_layers.py on this repository (no include runs up a layer, no public header includes a private file)
and on small trees made here: an include from core's base/ to schemes/, one from host's output/ to launch/ and one
from a public header of host's output/ to launch/ are each reported with their file and line and exit status 1; so is
a public header that includes a private file (host/src/...) of a lower layer; the same tree without them passes; a
file in no layer's folder fails.
Usage: check_layers_test.py REPOSITORY"""
import pathlib
import subprocess
import sys
import tempfile

repository = pathlib.Path(sys.argv[1]).resolve()
script = repository / "scripts" / "check_layers.py"
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def run(root=None):
    return subprocess.run([sys.executable, str(script)] + (["--root", str(root)] if root else []),
                          capture_output=True, text=True)


r = run()
check(r.returncode == 0 and " 0 upward" in r.stdout and " 0 from public headers" in r.stdout,
      f"this repository: no include runs up, none from a public header to a private file ({r.stdout[-400:]})")

with tempfile.TemporaryDirectory() as folder:
    root = pathlib.Path(folder)
    def write(path, text):
        (root / path).parent.mkdir(parents=True, exist_ok=True)
        (root / path).write_text(text)
    write("core/include/nonsep/core/schemes/b.hpp", '#include "nonsep/core/base/a.hpp"\n')
    write("core/include/nonsep/core/base/a.hpp", "#pragma once\n")
    write("host/include/nonsep/host/launch/run.hpp", '#include "nonsep/host/output/csv.hpp"\n')
    write("host/include/nonsep/host/output/csv.hpp", "#pragma once\n")
    r = run(root)
    check(r.returncode == 0, f"downward includes only: exit 0 ({r.returncode} {r.stdout})")
    write("core/include/nonsep/core/base/a.hpp", '#pragma once\n#include "nonsep/core/schemes/b.hpp"\n')
    write("host/src/output/csv.cpp", '// writes\n\n#include "nonsep/host/launch/run.hpp"\n')
    r = run(root)
    check(r.returncode == 1, f"upward includes: exit 1 ({r.returncode})")
    check("core/include/nonsep/core/base/a.hpp:2: includes nonsep/core/schemes/b.hpp" in r.stdout,
          f"the core include named with its line ({r.stdout})")
    check("host/src/output/csv.cpp:3: includes nonsep/host/launch/run.hpp" in r.stdout,
          "the host include named with its line")
    write("core/include/nonsep/core/base/a.hpp", "#pragma once\n")
    write("host/src/output/csv.cpp", "// writes\n")
    r = run(root)
    check(r.returncode == 0, f"the upward includes taken out: exit 0 ({r.returncode} {r.stdout})")
    # From a public header: upward, and to a private file of a lower layer.
    write("host/include/nonsep/host/output/table.hpp", '#pragma once\n#include "nonsep/host/launch/run.hpp"\n')
    r = run(root)
    check(r.returncode == 1 and "host/include/nonsep/host/output/table.hpp:2: includes nonsep/host/launch/run.hpp"
          in r.stdout, f"an upward include from a public header: exit 1, named with its line ({r.stdout})")
    write("host/src/output/detail.hpp", "#pragma once\n")
    write("host/include/nonsep/host/output/table.hpp", '#pragma once\n#include "output/detail.hpp"\n')
    write("host/include/nonsep/host/launch/run.hpp", '#pragma once\n\n#include "output/detail.hpp"\n')
    r = run(root)
    check(r.returncode == 1 and "host/include/nonsep/host/output/table.hpp:2: includes output/detail.hpp: a public "
          "header includes the private file host/src/output/detail.hpp" in r.stdout
          and "host/include/nonsep/host/launch/run.hpp:3:" in r.stdout,
          f"a public header including a private file, of its own part or a lower one: exit 1 ({r.stdout})")
    write("host/include/nonsep/host/output/table.hpp", "#pragma once\n")
    write("host/include/nonsep/host/launch/run.hpp", "#pragma once\n")
    write("core/include/nonsep/core/loose.hpp", "#pragma once\n")
    r = run(root)
    check(r.returncode == 1 and "in no layer" in r.stdout, f"a file outside every layer: exit 1 ({r.stdout})")

print(f"{len(failures)} failed")
sys.exit(1 if failures else 0)
