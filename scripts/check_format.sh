#!/usr/bin/env bash
# Fails when a tracked C++ file (*.h, *.cc) differs from what clang-format makes of it with the
# repository's .clang-format; prints the files and how to fix them.
#   scripts/check_format.sh [ROOT]   (default: the repository root; needs git and clang-format)
set -euo pipefail
root="$(cd "${1:-$(dirname "${BASH_SOURCE[0]}")/..}" && pwd)"
cd "${root}"
if ! command -v clang-format > /dev/null; then
  echo "error: clang-format not found; run scripts/install_deps.sh (package clang-format)" >&2
  exit 2
fi
files=()
while IFS= read -r -d '' f; do files+=("${f}"); done < <(git ls-files -z '*.h' '*.cc')
if ((${#files[@]} == 0)); then
  echo "error: no tracked C++ files under ${root}" >&2
  exit 2
fi
unformatted=()
for f in "${files[@]}"; do
  clang-format --style=file "${f}" | cmp -s - "${f}" || unformatted+=("${f}")
done
if ((${#unformatted[@]} > 0)); then
  printf 'not formatted: %s\n' "${unformatted[@]}" >&2
  echo "error: ${#unformatted[@]} of ${#files[@]} files differ from .clang-format;" \
    "fix with: git ls-files '*.h' '*.cc' | xargs clang-format -i --style=file" >&2
  exit 1
fi
echo "==> ${#files[@]} C++ files match .clang-format ($(clang-format --version | head -n 1))"
