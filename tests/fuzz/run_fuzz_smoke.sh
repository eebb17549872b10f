#!/usr/bin/env bash
# A short fuzzing pass for CI (a step of scripts/test.sh): configures a clang build with libFuzzer, ASan and UBSan
# in BUILD_DIR, builds only the harnesses, and fuzzes job-file reading for SECONDS seconds starting from the kept
# corpus (corpus/ and corpus_minimized.tar.xz; neither is modified: the archive is unpacked into, and new inputs go
# to, a scratch folder), then checkpoint reading for SECONDS seconds from checkpoint_corpus/. Fails on any crash,
# leak, timeout or sanitizer report.
# Usage: run_fuzz_smoke.sh SOURCE_DIR BUILD_DIR [SECONDS]
set -euo pipefail
source_dir=$1
build_dir=$2
seconds=${3:-30}
CC=clang CXX=clang++ cmake -S "$source_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" \
  -DNONSEP_FUZZ=ON -DNONSEP_SANITIZE=ON -DNONSEP_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build_dir" -j2 --target fuzz_job_reader fuzz_checkpoint
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir "$scratch/new" "$scratch/minimized" "$scratch/checkpoints"
(cd "$scratch/minimized" && cmake -E tar xf "$source_dir/tests/fuzz/corpus_minimized.tar.xz")
cd "$scratch"
"$build_dir/bin/fuzz_job_reader" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -dict="$source_dir/tests/fuzz/job.dict" -print_final_stats=1 "$scratch/new" "$source_dir/tests/fuzz/corpus" \
  "$scratch/minimized"
"$build_dir/bin/fuzz_checkpoint" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -print_final_stats=1 "$scratch/checkpoints" "$source_dir/tests/fuzz/checkpoint_corpus"
