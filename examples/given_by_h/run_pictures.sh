#!/usr/bin/env bash
# Runs the examples of models given by H(q, p) and draws them: the Henon-Heiles Poincare portrait at H = 1/8, the
# Poincare section theta = pi/2 and the stability map over the field strength of a charged particle around a
# Schwarzschild black hole in a uniform magnetic field,
# and a charged particle in a magnetic bottle: its Poincare section z = 0 and its MEGNO chaos map
# (examples/dynamics/magnetic_bottle_chaos_map.json).
#
#   bash examples/given_by_h/run_pictures.sh [OUT_DIR] [BUILD_DIR] [--small]
#
# OUT_DIR (default build/given_by_h) receives one folder per job and given_by_h_*.png. BUILD_DIR (default build)
# holds bin/nonsep; the runs' messages are kept in OUT_DIR/messages.txt. --small runs the same jobs on coarser grids for a shorter time (the examples test, seconds): the
# job files are rewritten into OUT_DIR/jobs. docs/given_by_h_*.png are the full-size pictures. Exits non-zero if any
# step fails.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/given_by_h}"
build="${2:-$root/build}"
small="${3:-}"
python="${PYTHON:-/usr/bin/python3}"  # the system interpreter, which has python3-matplotlib

mkdir -p "$out/jobs"
: >"$out/messages.txt"
for job in given_by_h/henon_heiles_portrait given_by_h/schwarzschild_section given_by_h/schwarzschild_stability_map \
  given_by_h/magnetic_bottle_section dynamics/magnetic_bottle_chaos_map; do
  name=$(basename "$job")
  file="$root/examples/$job.json"
  if [ "$small" = "--small" ]; then
    "$python" - "$file" "$out/jobs/$name.json" "$root/schemas/job.schema.json" <<'PY'
import json, sys
job = json.load(open(sys.argv[1]))
job["$schema"] = sys.argv[3]
if "grid" in job["initial"]:
    for axis in job["initial"]["grid"]["q"] + job["initial"]["grid"]["p"]:
        if isinstance(axis, dict):
            axis["count"] = min(axis["count"], 4)
else:
    job["initial"] = job["initial"][::6]
job["time"]["t_end"] = job["time"]["t_end"] / 20
for parameter in job["model"].get("parameters", {}).values():
    if isinstance(parameter, dict):
        parameter["count"] = min(parameter["count"], 3)
if job["output"]["every"]:  # step 0 and the last step, as the full job
    job["output"]["every"] = round(job["time"]["t_end"] / job["time"]["dt"])
json.dump(job, open(sys.argv[2], "w"), indent=2)
PY
    file="$out/jobs/$name.json"
  fi
  "$build/bin/nonsep" run --quiet --force --output "$out/$name" "$file" 2> >(tee -a "$out/messages.txt" >&2)
done
"$python" "$here/plot_pictures.py" "$out"
