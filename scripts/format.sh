#!/usr/bin/env bash
# The code's format (.clang-format) over the tracked C++ files (apps, include, src, tests),
# with clang-format 14 (scripts/deps.sh installs it; another version formats differently).
#   scripts/format.sh --check [FILE...]   lists the files that differ; exit 1 if any (CI: .ci/run)
#   scripts/format.sh --fix [FILE...]     rewrites them in place
# Without FILEs: every tracked *.cpp and *.h. scripts/hooks/pre-commit runs the check on the
# staged files.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-}
[ "$mode" = --check ] || [ "$mode" = --fix ] || { echo "usage: scripts/format.sh --check|--fix [FILE...]" >&2; exit 2; }
shift
CLANG_FORMAT=${CLANG_FORMAT:-clang-format-14}
command -v "$CLANG_FORMAT" >/dev/null || { echo "format.sh: $CLANG_FORMAT not found (scripts/deps.sh)" >&2; exit 2; }
if [ $# -gt 0 ]; then
  files=("$@")
else
  mapfile -t files < <(git ls-files -- '*.cpp' '*.h' ':!:third_party/*')
fi
if [ "$mode" = --fix ]; then
  [ ${#files[@]} -eq 0 ] || "$CLANG_FORMAT" -i --style=file "${files[@]}"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! "$CLANG_FORMAT" --style=file "$f" | cmp -s - "$f"; then
    echo "format.sh: $f is not formatted (scripts/format.sh --fix $f)"
    bad=$((bad + 1))
  fi
done
if [ "$bad" -gt 0 ]; then
  echo "format.sh: $bad of ${#files[@]} file(s) differ from .clang-format" >&2
  exit 1
fi
echo "format.sh: ${#files[@]} file(s) formatted"
