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
bad=()
for file in "${files[@]}"; do
  [ -f "$file" ] || continue
  "$clang_format" --dry-run --Werror "$file" >/dev/null 2>&1 || bad+=("$file")
done
if ((${#bad[@]})); then
  echo "check_format: ${#bad[@]} of ${#files[@]} files do not follow .clang-format; reformat them with:"
  printf '  %s -i %s\n' "$clang_format" "${bad[@]}"
  exit 1
fi
echo "check_format: ${#files[@]} files follow .clang-format"
