#!/usr/bin/env bash
# A short fuzzing pass for CI (a step of scripts/test.sh): configures the `sanitize` preset of CMakePresets.json
# (clang with libFuzzer, ASan and UBSan, in SOURCE_DIR/build-sanitize: after tests/ci/run_sanitized_suite.sh the
# harnesses are already built), builds only the harnesses, and fuzzes job-file reading for SECONDS seconds starting from the kept
# corpus (corpus/ and corpus_minimized.tar.xz; neither is modified: the archive is unpacked into, and new inputs go
# to, a scratch folder), then checkpoint reading for SECONDS seconds from checkpoint_corpus/, then initial-state files
# (.npy and CSV) for SECONDS seconds from initial_file_corpus/. Fails on any crash, leak, timeout or sanitizer report.
# Usage: run_fuzz_smoke.sh SOURCE_DIR [SECONDS]
set -euo pipefail
source_dir=$1
seconds=${2:-30}
build_dir=$source_dir/build-sanitize
(cd "$source_dir" && cmake --preset sanitize >/dev/null && cmake --build --preset sanitize --target fuzz_job_reader fuzz_checkpoint fuzz_initial_file)
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
mkdir "$scratch/new" "$scratch/minimized" "$scratch/checkpoints" "$scratch/initial"
(cd "$scratch/minimized" && cmake -E tar xf "$source_dir/tests/fuzz/corpus_minimized.tar.xz")
cd "$scratch"
"$build_dir/bin/fuzz_job_reader" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -dict="$source_dir/tests/fuzz/job.dict" -print_final_stats=1 "$scratch/new" "$source_dir/tests/fuzz/corpus" \
  "$scratch/minimized"
"$build_dir/bin/fuzz_checkpoint" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=16384 \
  -print_final_stats=1 "$scratch/checkpoints" "$source_dir/tests/fuzz/checkpoint_corpus"
# -max_len reaches past the .npy header's limit (64 KiB); -rss_limit_mb catches memory that grows with the file.
"$build_dir/bin/fuzz_initial_file" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=70000 \
  -print_final_stats=1 "$scratch/initial" "$source_dir/tests/fuzz/initial_file_corpus"
