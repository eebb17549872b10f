#!/usr/bin/env bash
# CI: the whole test suite, plugins included, built with AddressSanitizer and UndefinedBehaviorSanitizer (the
# `sanitize` preset of CMakePresets.json, in SOURCE_DIR/build-sanitize). Every sanitizer report fails its test:
# ASan aborts on the first error, UBSan is built with -fno-sanitize-recover, and LeakSanitizer reports leaks at exit.
# Tests labelled slow are left out (an install and a rebuild). Benchmarks are not built. Prints the time each phase
# took. A step of scripts/test.sh (CI).
# Usage: run_sanitized_suite.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
cd "$source_dir"
start=$SECONDS
cmake --preset sanitize -DNONSEP_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build --preset sanitize
built=$SECONDS
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-sanitize --output-on-failure -j2 -LE slow
echo "run_sanitized_suite: build $((built - start)) s, tests $((SECONDS - built)) s"
