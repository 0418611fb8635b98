#!/usr/bin/env bash
# Fails when a C++ source differs from clang-format's layout (.clang-format). --fix rewrites.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
mapfile -t files < <(git ls-files '*.cpp' '*.h' '*.cu' '*.cuh' 2>/dev/null | grep -v '^shaders/.*\.comp$' || true)
[ ${#files[@]} -gt 0 ] || exit 0
if [ "${1:-}" = --fix ]; then
  clang-format -i "${files[@]}"
else
  clang-format --dry-run --Werror "${files[@]}"
  echo "format check: ${#files[@]} files OK"
fi
