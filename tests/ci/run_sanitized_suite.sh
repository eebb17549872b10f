#!/usr/bin/env bash
# CI: the whole test suite, plugins included, built by clang with AddressSanitizer and UndefinedBehaviorSanitizer
# (the `sanitize` preset of CMakePresets.json, in SOURCE_DIR/build-sanitize; the same build holds the libFuzzer
# harnesses that tests/fuzz/run_fuzz_smoke.sh runs next). Every sanitizer report fails its test: ASan aborts on the
# first error, UBSan is built with -fno-sanitize-recover, and LeakSanitizer reports leaks at exit. Tests labelled
# slow are left out (an install and a rebuild, MPI). Benchmarks are not built. Under clang the SDK plugins carry
# the baseline stepping kernel only (plugins/sdk/include/nonsep/sdk/kernels.hpp); the wider ones are GCC's and are
# tested in the release build. Prints the time each phase took. A step of scripts/test.sh (CI).
# Usage: run_sanitized_suite.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
cd "$source_dir"
start=$SECONDS
cmake --preset sanitize >/dev/null
cmake --build --preset sanitize
built=$SECONDS
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
status=0
ctest --test-dir build-sanitize --output-on-failure -j2 -LE slow || status=$?
echo "run_sanitized_suite: build $((built - start)) s, tests $((SECONDS - built)) s"
exit "$status"
