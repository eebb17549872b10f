#!/usr/bin/env bash
# The accuracy table of docs/dynamics.md ("Which scheme"): halving ladders of gauss 3 stages, MPE 4, tao 4 and the
# implicit midpoint on paper2d's chaotic orbit q = (0.5, 0), p = (0, 2.5) to t = 10, four vectors renormalised every
# 10 steps, MEGNO, lyapunov.csv rows every 2.5; then the relative errors of lambda_1(10) against the 32-digit truth
# (python3 reference_mp.py 0.01 8 32 prints it: lambda_1(10) = 1.2308274074) with the observed orders.
# Usage: bench/indicators/ladder.sh NONSEP WORK_FOLDER   (about 30 minutes of one core; the finest MPE and
# implicit-midpoint steps take most of it)
set -euo pipefail
nonsep=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$2/jobs" "$2/runs"
cd "$2"
S="0.5 0 0 2.5"
ladder() {  # prefix scheme order dt...
  local prefix=$1 scheme=$2 order=$3
  shift 3
  for dt in "$@"; do
    python3 "$here/mkjob.py" "${prefix}_$dt" "$scheme" "$order" "$dt" 10 $S --megno --every-t 2.5
    "$nonsep" run --quiet --force --threads 1 --output "runs/${prefix}_$dt" "jobs/${prefix}_$dt.json" || true
  done
}
ladder g3 gauss 3 0.01 0.005 0.0025 0.00125 0.000625 0.0003125
ladder mpe4 mpe 4 0.001 0.0005 0.00025 0.000125 0.0000625 0.00003125 0.000015625 0.0000078125
ladder tao4 tao 4 0.002 0.001 0.0005 0.00025 0.000125 0.0000625
ladder im implicit_midpoint 2 0.001 0.0005 0.00025 0.000125 0.0000625 0.00003125 0.000015625 0.0000078125
for prefix in g3 mpe4 tao4 im; do
  echo "$prefix"
  python3 "$here/analyze.py" "$prefix" 10 lyapunov0 1.2308274074
done
