#!/usr/bin/env bash
# Fails (exit 1) when a tracked C/C++ file differs from what clang-format makes of it with the
# committed .clang-format, listing the files and the first lines of the diff. Fix with:
#   git ls-files '*.h' '*.cpp' '*.c' | xargs clang-format -i
set -euo pipefail
cd "$(dirname "$0")/.."
CLANG_FORMAT=${CLANG_FORMAT:-clang-format}
command -v "$CLANG_FORMAT" > /dev/null || { echo "check-format: $CLANG_FORMAT not found (apt-get install clang-format)"; exit 1; }
bad=0
while IFS= read -r f; do
  if ! diff -u "$f" <("$CLANG_FORMAT" --style=file "$f") > /tmp/check-format.$$ 2>&1; then
    echo "check-format: $f is not clang-formatted:"
    head -20 /tmp/check-format.$$
    bad=1
  fi
done < <(git ls-files '*.h' '*.hpp' '*.cpp' '*.cc' '*.c')
rm -f /tmp/check-format.$$
[ $bad = 0 ] && echo "check-format: every C/C++ file is clang-formatted ($("$CLANG_FORMAT" --version))"
exit $bad
