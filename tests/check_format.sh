#!/usr/bin/env bash
# Fails when a C or C++ source file of the project does not follow .clang-format (names each such file).
# The layout is clang-format 14's (Debian 12); other versions format some constructs differently.
# Usage: bash tests/check_format.sh ROOT [CLANG_FORMAT]
set -uo pipefail
root=${1:?usage: check_format.sh ROOT [CLANG_FORMAT]}
clang_format=${2:-clang-format-14}
cd "$root" || exit 2
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc')
else
  mapfile -t files < <(find core host plugins tests bench examples reference \
    \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cc' \) -not -path '*/build*' | sort)
fi
existing=()
for file in "${files[@]}"; do
  [ -f "$file" ] && existing+=("$file")
done
# One clang-format process for every file (one per file took a minute); each file it would change is named in an
# error "FILE:LINE:COLUMN: error: code should be clang-formatted".
output=$("$clang_format" --dry-run --Werror "${existing[@]}" 2>&1)
status=$?
mapfile -t bad < <(printf '%s\n' "$output" | sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
if ((status != 0 && ${#bad[@]} == 0)); then
  echo "check_format: $clang_format failed (status $status):"
  printf '%s\n' "$output" | head -20
  exit 2
fi
if ((${#bad[@]})); then
  echo "check_format: ${#bad[@]} of ${#files[@]} files do not follow .clang-format; reformat them with:"
  for file in "${bad[@]}"; do printf '  %s -i %s\n' "$clang_format" "$file"; done
  exit 1
fi
echo "check_format: ${#files[@]} files follow .clang-format"
