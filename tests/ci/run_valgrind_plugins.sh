#!/usr/bin/env bash
# CI: valgrind memcheck of loading, using and unloading every shipped plugin through the `nonsep` executable:
# `nonsep inspect NAME --check` (load, metadata, create, every function at sample points, destroy, unload) and a
# short ensemble run with energies (every function again, through the runner, writing both outputs). Fails on any
# memcheck error and on definite, indirect or possible leaks. valgrind.supp lists the suppressed reports, each explained.
# A step of scripts/test.sh (CI).
# Usage: run_valgrind_plugins.sh NONSEP_EXECUTABLE SOURCE_DIR
set -euo pipefail
nonsep=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
memcheck=(valgrind --quiet --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect,possible
  --show-leak-kinds=definite,indirect,possible --suppressions="$source_dir/tests/ci/valgrind.supp")

# name, parameters, one state's q and p (each run has two copies of it: a batch of two)
plugins=(
  'paper1d|{}|[1.0]|[0.5]'
  'radial|{"dimension": 3}|[1.0, 0.5, -0.5]|[0.0, 0.5, 0.25]'
  'quadratic_kinetic|{"lambda": 0.7}|[1.0, 0.5]|[0.0, 0.5]'
  'tao_product|{}|[0.5]|[0.5]'
)
failed=0
for entry in "${plugins[@]}"; do
  IFS='|' read -r name parameters q p <<<"$entry"
  echo "valgrind: $name"
  if ! "${memcheck[@]}" "$nonsep" inspect "$name" --check >"$work/$name-inspect.txt"; then
    echo "valgrind: inspect $name --check FAILED (status $?)"; cat "$work/$name-inspect.txt"; failed=1
  fi
  cat >"$work/$name.json" <<JOB
{
  "model": { "plugin": "$name", "parameters": $parameters },
  "integrator": { "scheme": "mpe", "order": "2" },
  "initial": [{ "q": $q, "p": $p }, { "q": $q, "p": $p }],
  "time": { "dt": 0.01, "steps": 20 },
  "output": { "directory": "$work/$name.out", "every": 5 },
  "checkpoint": { "every_steps": 10 }
}
JOB
  if ! "${memcheck[@]}" "$nonsep" run --quiet "$work/$name.json"; then
    echo "valgrind: run of $name FAILED"; failed=1
  fi
done
exit $failed
