#!/usr/bin/env bash
# Reproduces the paper's three figures: the exact references, the jobs of this folder, and the plots.
#
#   bash examples/paper/run_figures.sh [OUT_DIR] [BUILD_DIR]
#
# OUT_DIR (default build/paper-figures) receives reference/ (nonsep_paper_reference), one folder per job
# (figure1/, figure2_paper_circle/, ..., figure3/) and figure1, figure2 and figure3, each as .png (150 dpi) and
# .pdf. BUILD_DIR (default build) holds bin/nonsep and bin/nonsep_paper_reference. Exits non-zero if any step
# fails.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:-$root/build/paper-figures}"
build="${2:-$root/build}"
python="${PYTHON:-/usr/bin/python3}"  # the system interpreter, which has python3-matplotlib

mkdir -p "$out"
"$build/bin/nonsep_paper_reference" "$out/reference" >/dev/null
for job in figure1 figure2_paper_circle figure2_paper_triangle figure2_paper_twisted figure2_accurate \
           figure2_corrected figure3; do
  "$build/bin/nonsep" run --quiet --output "$out/$job" "$here/$job.json"
done
"$python" "$here/plot_figures.py" "$out"
