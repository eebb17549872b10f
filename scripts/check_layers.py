#!/usr/bin/env python3
"""Checks the layers of core/ and host/ on the include graph: no file includes a file of a higher layer.

Usage: scripts/check_layers.py [--list] [--root DIR]

The layers, lowest first, are the LAYERS table below: each part of core/ and host/ is a folder (of
core/include/nonsep/core/ and core/src/, or of host/include/nonsep/host/ and host/src/) or a top-level header, and
belongs to one layer. A part may include its own layer and the layers below it. Every `#include "nonsep/..."` and
every relative `#include "..."` of every .hpp, .h and .cpp file under core/ and host/ is read (as text) and mapped
to the part of the file it names. Prints one line per include that runs upward (the file, its line, the include,
both layers) and a summary; `--list` also prints the arrows counted between parts.

Public headers (core/include/nonsep/core/, host/include/nonsep/host/: what other parts, the tests and an installed
package build on) are held to the layers like every file, and to one rule more: they include no private file (one of
core/src/ or host/src/), which a user of the headers does not have; such an include is reported with its file and
line. Exit status 1 when any include runs upward, a public header includes a private file, or a file belongs to no
part, 0 otherwise.
"""
import argparse
import collections
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent  # --root DIR checks another tree (the script's own test)

# (tree, layers from the lowest): a layer is a list of parts. A part is a folder name or a top-level header's name.
LAYERS = {
    "core": [
        ["base"],  # the model concept, batches, errors, fractions, derivative products
        ["kernel"],  # the stepping kernels compiled into every plugin (its headers and base only)
        ["schemes"],  # Chin's schemes, the comparators, the catalogue and the runtime Integrator
        ["tangent"],  # the tangent map of every scheme
        ["runtime"],  # the list of shipped schemes, the catalogue, the Integrator and TangentIntegrator over it
        ["analysis"],  # what watches a trajectory: energy, crossings, Lyapunov exponents, MEGNO, SALI/GALI
    ],
    "host": [
        # utilities and the readers' lowest layer: file formats, the platform, JSON issues, numbers, exit statuses
        ["platform", "output", "json", "number_format.hpp", "exit_status.hpp", "time_grid.hpp", "plugin_loader.hpp"],
        ["formula"],  # formula models: parse, differentiate, generate, compile, cache
        ["job", "job.hpp", "job_schema.hpp"],  # a job file read and checked
        ["run"],  # the ensemble driver, blocks, the observer interface
        ["observers", "checkpoint"],  # what watches a run, and what saves it
        ["launch"],  # one run from a job to its files
        ["study", "cluster", "inspect"],  # studies, distributed runs, plugin reports
        ["cli", "command_line.hpp", "main.cpp"],  # the command line
    ],
}
# Where the parts' files are, per tree: the roots whose first path component (or file name) is the part.
ROOTS = {
    "core": ["core/include/nonsep/core", "core/src"],
    "host": ["host/include/nonsep/host", "host/src"],
}
# Headers the host includes from outside host/ (the plugin loader library, host/loader): their part.
OUTSIDE = {"nonsep/host/plugin_loader.hpp": "plugin_loader.hpp"}

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def part_of(tree, path):
    """The part of `path` (relative to the repository), or None."""
    for root in ROOTS[tree]:
        try:
            rest = path.relative_to(root)
        except ValueError:
            continue
        return rest.parts[0]
    return None


def is_public(tree, path):
    """Whether `path` (relative to the repository) is one of the tree's public headers (its first root)."""
    try:
        path.relative_to(ROOTS[tree][0])
        return True
    except ValueError:
        return False


def layer_of(tree, part):
    for index, parts in enumerate(LAYERS[tree]):
        if part in parts:
            return index
    return None


def target_of(tree, source, name):
    """The repository path an include names, when it is one of this tree's files; None for others."""
    if name in OUTSIDE:
        return OUTSIDE[name]
    prefix = "nonsep/" + tree + "/"
    if name.startswith(prefix):
        return pathlib.Path(ROOTS[tree][0]) / name[len(prefix):]
    relative = (ROOT / source).parent / name
    if relative.exists():
        return relative.resolve().relative_to(ROOT)
    for root in ROOTS[tree]:  # "run/block.hpp" from host/src/...: relative to a source root
        candidate = ROOT / root / name
        if candidate.exists():
            return candidate.relative_to(ROOT)
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--list", action="store_true", help="also print the arrows between parts")
    parser.add_argument("--root", type=pathlib.Path, help="the repository to check (default: this one)")
    arguments = parser.parse_args()
    global ROOT
    if arguments.root:
        ROOT = arguments.root.resolve()
    upward, unplaced, arrows = [], [], collections.Counter()
    private = []
    for tree in LAYERS:
        for root in ROOTS[tree]:
            if not (ROOT / root).is_dir():
                continue
            for file in sorted((ROOT / root).rglob("*")):
                if file.suffix not in (".hpp", ".h", ".cpp") or not file.is_file():
                    continue
                source = file.relative_to(ROOT)
                part = part_of(tree, source)
                level = layer_of(tree, part)
                if level is None:
                    unplaced.append(f"{source}: part {part!r} is in no layer of {tree}")
                    continue
                for number, line in enumerate(file.read_text(errors="replace").splitlines(), 1):
                    match = INCLUDE.match(line)
                    if not match:
                        continue
                    target = target_of(tree, source, match.group(1))
                    if target is None:
                        continue
                    if is_public(tree, source) and not isinstance(target, str) and not is_public(tree, target):
                        private.append(f"{source}:{number}: includes {match.group(1)}: a public header includes "
                                       f"the private file {target}")
                    target_part = target if isinstance(target, str) else part_of(tree, target)
                    target_level = layer_of(tree, target_part)
                    if target_level is None:
                        unplaced.append(f"{source}:{number}: includes {match.group(1)}, in no layer of {tree}")
                        continue
                    if target_part != part:
                        arrows[(tree, part, target_part)] += 1
                    if target_level > level:
                        upward.append(f"{source}:{number}: includes {match.group(1)}: {tree} layer {level} ({part}) "
                                      f"-> layer {target_level} ({target_part})")
    if arguments.list:
        for (tree, a, b), count in sorted(arrows.items()):
            print(f"{tree}: {a} -> {b}: {count}")
    for line in unplaced + upward + private:
        print(line)
    print(f"check_layers: {sum(arrows.values())} includes between parts, {len(upward)} upward, "
          f"{len(private)} from public headers to private files, {len(unplaced)} outside the layers")
    return 1 if upward or private or unplaced else 0


if __name__ == "__main__":
    sys.exit(main())
