#!/usr/bin/env bash
# CI: the whole test suite, plugins included, built with AddressSanitizer and UndefinedBehaviorSanitizer (the
# `sanitize` preset of CMakePresets.json, in SOURCE_DIR/build-sanitize). Every sanitizer report fails its test:
# ASan aborts on the first error, UBSan is built with -fno-sanitize-recover, and LeakSanitizer reports leaks at exit.
# Tests labelled slow, fuzz, sanitize or valgrind are left out (the first is an install and a rebuild; the others are
# CI passes of their own). Benchmarks are not built. Prints the time each phase took.
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
ctest --test-dir build-sanitize --output-on-failure -j2 -LE 'slow|fuzz|sanitize|valgrind'
echo "run_sanitized_suite: build $((built - start)) s, tests $((SECONDS - built)) s"
