#!/usr/bin/env bash
# Checks that every C++ source is formatted as .clang-format says (clang-format 14, Debian
# bookworm's): lists the files that are not and exits 1. To format them:
#   git ls-files '*.cpp' '*.h' | xargs clang-format-14 -i
set -euo pipefail
cd "$(dirname "$0")/.."
command -v clang-format-14 >/dev/null || bash scripts/setup.sh clang-format-14
mapfile -t files < <(git ls-files '*.cpp' '*.h')
bad=()
for f in "${files[@]}"; do
  clang-format-14 --dry-run -Werror "$f" >/dev/null 2>&1 || bad+=("$f")
done
if [ ${#bad[@]} -gt 0 ]; then
  echo "format: ${#bad[@]} of ${#files[@]} sources differ from .clang-format: ${bad[*]}"
  echo "format: run: git ls-files '*.cpp' '*.h' | xargs clang-format-14 -i"
  exit 1
fi
echo "format: all ${#files[@]} sources as .clang-format says"
