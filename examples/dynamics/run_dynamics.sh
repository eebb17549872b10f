#!/usr/bin/env bash
# Runs the dynamics examples of paper2d and draws them: a Poincare phase portrait, a MEGNO chaos map on one energy
# shell, a stability map (MEGNO over the coupling, a parameter sweep, and q0 on that shell), on the shell H = 8
# the stability map over the coupling from 0 to 0.3 and the fraction of chaotic orbits against the coupling, and a
# frequency map of the Henon-Heiles system (the fundamental frequencies by NAFF, coloured by the diffusion index)
# with its diffusion map.
#
#   bash examples/dynamics/run_dynamics.sh [OUT_DIR] [BUILD_DIR] [--small]
#
# OUT_DIR (default build/dynamics) receives one folder per job (poincare_portrait/, chaos_map/, stability_map/,
# stability_map_shell8/, chaotic_fraction/, frequency_map/), what each run printed on stderr (JOB.stderr: empty when
# nothing went
# wrong), what plot_dynamics.py printed (plot_dynamics.txt: the chaotic fractions), and dynamics_poincare,
# dynamics_chaos_map, dynamics_stability_map, dynamics_stability_map_shell8, dynamics_chaotic_fraction and
# dynamics_frequency_map as .png
# and .pdf. BUILD_DIR (default build) holds bin/nonsep. --small runs the same jobs
# on coarser grids for a shorter time (the examples test; seconds): the job files are rewritten into OUT_DIR/jobs.
# docs/dynamics_*.png are the full-size pictures. Exits non-zero if any step fails.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/dynamics}"
build="${2:-$root/build}"
small="${3:-}"
python="${PYTHON:-/usr/bin/python3}"  # the system interpreter, which has python3-matplotlib

mkdir -p "$out/jobs"
for job in poincare_portrait chaos_map stability_map stability_map_shell8 chaotic_fraction frequency_map; do
  file="$here/$job.json"
  if [ "$small" = "--small" ]; then
    file="$out/jobs/$job.json"
    "$python" - "$here/$job.json" "$file" "$root/schemas/job.schema.json" "$job" <<'PY'
import json, sys
job = json.load(open(sys.argv[1]))
job["$schema"] = sys.argv[3]
grid = job["initial"]["grid"]
# Per job: the swept couplings, the grid's counts (q0, then p0 where it is a range) and t_end of the small run.
small = {"poincare_portrait": (None, (9, 9), 100), "chaos_map": (None, (15, 15), 40),
         "stability_map": (9, (15,), 40), "stability_map_shell8": (5, (9,), 40),
         "chaotic_fraction": (4, (6, 6), 30), "frequency_map": (None, (15, 15), 400)}
couplings, counts, t_end = small[sys.argv[4]]
if couplings:
    job["model"]["parameters"]["coupling"]["count"] = couplings
for axis, count in zip(("q", "p"), counts):  # the axis's range, whichever component it is
    next(value for value in grid[axis] if isinstance(value, dict))["count"] = count
job["time"]["t_end"] = t_end
if job["output"]["every"]:  # the number of steps: the initial states and the last step
    job["output"]["every"] = round(t_end / job["time"]["dt"])
json.dump(job, open(sys.argv[2], "w"), indent=2)
PY
  fi
  "$build/bin/nonsep" run --quiet --force --output "$out/$job" "$file" 2> "$out/$job.stderr" || {
    cat "$out/$job.stderr" >&2
    exit 1
  }
done
"$python" "$here/plot_dynamics.py" "$out" | tee "$out/plot_dynamics.txt"
