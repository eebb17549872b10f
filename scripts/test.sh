#!/usr/bin/env bash
# The whole test suite, exactly as CI runs it (.ci/run) and README.md shows it, from a fresh Debian 12 machine:
#   1. setup    scripts/setup.sh: the Debian packages, configure and build build/ (Release) with the test suites
#               (-DBUILD_TESTING=ON); the benchmarks are not built here, for CI's time budget (bench/ and
#               docs/performance.md build them with -DNONSEP_BUILD_BENCHMARKS=ON, with their smoke tests);
#   2. ctest    every ctest test of build/ (labels core, plugins, host, examples, python, slow);
#   3. sanitize the C++ suites again, built by clang with ASan + UBSan in build-sanitize/, less the longest runs
#               (tests/ci/run_sanitized_suite.sh);
#   4. fuzz     20 s of libFuzzer each on reading job files, checkpoints and initial-state files, from the kept
#               corpora, with the harnesses of that same build (tests/fuzz/run_fuzz_smoke.sh);
#   5. valgrind memcheck of loading, using and unloading every shipped plugin (tests/ci/run_valgrind_plugins.sh).
# Steps 2 to 5 each run even when an earlier one failed; a failed setup stops everything (nothing to test).
# Output: each step's own output, a line "test.sh: STEP passed|failed (N s)" after it; when ctest failed, the
# names of its failed tests and the end of each one's output again; and as the last line "N passed, N failed" over
# steps 2 to 5. Exit status 0 when all passed, 1 otherwise.
# Usage: bash scripts/test.sh
set -uo pipefail
cd "$(dirname "$0")/.." || exit 1
root=$PWD

if ! bash scripts/setup.sh -DBUILD_TESTING=ON -DNONSEP_BUILD_BENCHMARKS=OFF; then
  echo "test.sh: setup failed"
  echo "0 passed, 1 failed"
  exit 1
fi
echo "test.sh: setup passed ($SECONDS s)"

passed=0
failed=0
failed_steps=()
step() {
  local name=$1
  shift
  local start=$SECONDS
  echo "test.sh: $name"
  if "$@"; then
    passed=$((passed + 1))
    echo "test.sh: $name passed ($((SECONDS - start)) s)"
  else
    failed=$((failed + 1))
    failed_steps+=("$name")
    echo "test.sh: $name failed ($((SECONDS - start)) s)"
  fi
}

rm -f build/Testing/Temporary/LastTestsFailed.log  # ctest leaves it in place when every test passes
step ctest ctest --test-dir build --output-on-failure -j2
step sanitize bash tests/ci/run_sanitized_suite.sh "$root"
step fuzz bash tests/fuzz/run_fuzz_smoke.sh "$root" 20
step valgrind bash tests/ci/run_valgrind_plugins.sh "$root/build/bin/nonsep" "$root"

# CI shows only the end of this output: name the failed ctest tests again here, with the end of what each printed.
failed_tests=build/Testing/Temporary/LastTestsFailed.log
if [[ " ${failed_steps[*]:-} " == *" ctest "* && -s $failed_tests ]]; then
  echo "test.sh: ctest tests that failed:"
  sed 's/^/  /' "$failed_tests"
  while IFS=: read -r _ name; do
    echo "test.sh: the end of what '$name' printed:"
    awk -v start="Testing: $name" -v end="\"$name\" end time" '
      $0 ~ /^[0-9]+\/[0-9]+ Testing: / && substr($0, index($0, " ") + 1) == start { keep = 1 }
      keep { print }
      keep && index($0, end) == 1 { exit }' build/Testing/Temporary/LastTest.log | tail -n 40
  done < "$failed_tests"
fi
((failed == 0)) || echo "test.sh: failed steps: ${failed_steps[*]}"
echo "$passed passed, $failed failed"
((failed == 0))
