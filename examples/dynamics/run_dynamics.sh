#!/usr/bin/env bash
# Runs the dynamics examples of paper2d and draws them: a Poincare phase portrait, a MEGNO chaos map on one energy
# shell, and a stability map (MEGNO over the coupling, a parameter sweep, and q0 on that shell).
#
#   bash examples/dynamics/run_dynamics.sh [OUT_DIR] [BUILD_DIR] [--small]
#
# OUT_DIR (default build/dynamics) receives one folder per job (poincare_portrait/, chaos_map/, stability_map/) and
# dynamics_poincare, dynamics_chaos_map and dynamics_stability_map as .png and .pdf. BUILD_DIR (default build) holds bin/nonsep.
# --small runs the same jobs on coarser grids for a shorter time (the examples test; a few seconds): the job files
# are rewritten into OUT_DIR/jobs. docs/dynamics_*.png are the full-size pictures. Exits non-zero if any step fails.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/dynamics}"
build="${2:-$root/build}"
small="${3:-}"
python="${PYTHON:-/usr/bin/python3}"  # the system interpreter, which has python3-matplotlib

mkdir -p "$out/jobs"
for job in poincare_portrait chaos_map stability_map; do
  file="$here/$job.json"
  if [ "$small" = "--small" ]; then
    file="$out/jobs/$job.json"
    "$python" - "$here/$job.json" "$file" "$root/schemas/job.schema.json" <<'PY'
import json, sys
job = json.load(open(sys.argv[1]))
job["$schema"] = sys.argv[3]
grid = job["initial"]["grid"]
if "poincare" in job["analysis"]:
    grid["q"][0]["count"] = grid["p"][0]["count"] = 9
elif isinstance(grid["p"][0], dict):
    grid["q"][0]["count"] = grid["p"][0]["count"] = 15
else:  # the stability map: 9 couplings x 15 starting points
    job["model"]["parameters"]["coupling"]["count"] = 9
    grid["q"][0]["count"] = 15
job["time"]["t_end"] = 100 if "poincare" in job["analysis"] else 40
json.dump(job, open(sys.argv[2], "w"), indent=2)
PY
  fi
  "$build/bin/nonsep" run --quiet --force --output "$out/$job" "$file"
done
"$python" "$here/plot_dynamics.py" "$out"
