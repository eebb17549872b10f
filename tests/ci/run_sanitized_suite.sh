#!/usr/bin/env bash
# CI: the test suite, plugins included, built by clang with AddressSanitizer and UndefinedBehaviorSanitizer (the
# `sanitize` preset of CMakePresets.json, in SOURCE_DIR/build-sanitize; the same build holds the libFuzzer harnesses
# that tests/fuzz/run_fuzz_smoke.sh runs next). Every sanitizer report fails its test: ASan aborts on the first
# error, UBSan is built with -fno-sanitize-recover, and LeakSanitizer reports leaks at exit. Under clang the SDK
# plugins carry the baseline stepping kernel only (plugins/sdk/include/nonsep/sdk/kernels.hpp); the wider ones are
# GCC's and are tested in the release build. Benchmarks are not built. Prints the time each phase took.
# Left out here, and run by the release suite (ctest in build/), to keep CI under its time budget:
#   - tests labelled slow (an install and a rebuild, mpirun), examples (whole example studies, the notebook) and
#     python (the Python package driving the executable the host tests drive);
#   - the tests below, each over 30 s under the sanitizers on two cores (measured: 30 s to over 300 s; the
#     examples over 300 s), most of them integrating large ensembles or a run killed and resumed: the code they run
#     is the code the other tests run on small jobs, and checkpoint reading is also fuzzed (tests/fuzz).
# A step of scripts/test.sh (CI).
# Usage: run_sanitized_suite.sh SOURCE_DIR
set -euo pipefail
source_dir=$1
cd "$source_dir"
long_runs=(
  '^a distributed run on one rank writes the files of an ordinary run'
  '^a distributed resume verifies every finished unit'
  '^a distributed resume follows no link'
  '^killed and resumed: poincare.csv, lyapunov.csv and trajectories.csv bit for bit'
  '^kernel path: a run killed and resumed gives'
  '^a Tao run killed and resumed continues its copies'
  '^resume after SIGKILL and after SIGINT'
  '^resume on the'
  '^a separable model killed and resumed'
  '^max_initial_values applies to every kind of initial state'
  '^paper2d, chaotic orbit: the long-time exponent'
  '^MEGNO: <Y> -> 2 within 5%'
  '^chaotic orbit: SALI below 1e-8 by t = 50'
  '^regular orbits: SALI stays above 1e-5 to t = 200'
  '^comparators with tangent vectors: killed and resumed'
  '^host.sweep$'
  '^formula commands: formulas at the length limit compile'
  '^killed after the first tenth and resumed: the runaway warnings'
  '^a model given by H: killed and resumed'
  '^no output depends on where chunks end'
  '^no runaway warning for paper2d.s bounded orbits on the compact shell'
  '^comparators with tangent vectors: --threads 1 and 2 write the same files'
  '^scheme auto: a phase tolerance on a chaotic orbit is not promised'
  '^--threads 1 and 2 write the same poincare.csv, lyapunov.csv and trajectories.csv'
)
# Left out as well: host.run_memory, which runs nonsep under an RLIMIT_AS (ulimit -v) of 8 GiB, less than the
# address space AddressSanitizer reserves for its shadow memory at start.
long_runs+=('^host.run_memory$')
exclude=$(IFS='|'; echo "${long_runs[*]}")
start=$SECONDS
cmake --preset sanitize >/dev/null
cmake --build --preset sanitize
built=$SECONDS
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# LeakSanitizer (clang 14) with glibc 2.36 misreads the dynamic TLS of a dlopen'ed plugin that uses thread_local
# (the SDK's per-thread scratch of the differentiated gradient templates): its tracer dies at exit with "Tracer
# caught signal 11" on a DTLS range starting near address 0, and the process exits 1 though nothing leaked (seen
# with `nonsep inspect lattice_chain --check`, depending on the environment's size). Not scanning TLS avoids the
# crash; memory reachable only from TLS would then be reported as a leak, not hidden.
export LSAN_OPTIONS=use_tls=0
status=0
ctest --test-dir build-sanitize --output-on-failure -j2 -LE "slow|examples|python" -E "$exclude" || status=$?
echo "run_sanitized_suite: build $((built - start)) s, tests $((SECONDS - built)) s"
exit "$status"
