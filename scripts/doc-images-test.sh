#!/usr/bin/env bash
# doc-images-test.sh PVS: ctest's DocImages.ScriptWritesEveryPictureDecodableAndNotFlat. Runs
# scripts/make-doc-images.sh --quick into a temporary folder (never docs/img), then checks that each
# picture the docs show exists, decodes (OpenImageIO's iinfo, not the matplotlib that wrote it), is
# at least 100 x 60 pixels and is not one flat colour (iinfo --stats: not constant, and some
# channel with a standard deviation of at least 2 of 255). Exit 77 (ctest: skipped) when
# /usr/bin/python3 lacks matplotlib or numpy, or iinfo is missing (scripts/install-deps.sh
# installs them).
set -euo pipefail
PVS=${1:?usage: doc-images-test.sh PVS}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
if ! /usr/bin/python3 -c "import matplotlib, numpy" 2> /dev/null || ! command -v iinfo > /dev/null; then
  echo "doc-images-test: skipped: needs /usr/bin/python3 with matplotlib and numpy, and iinfo (bash scripts/install-deps.sh)"
  exit 77
fi
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
bash "$ROOT/scripts/make-doc-images.sh" --quick --pvs "$PVS" "$OUT/img"
fail=0
for name in cells_top cell_set cell_frames near_far bench_found_vs_seconds bench_epsilon_vs_seconds; do
  f=$OUT/img/$name.png
  if [ ! -s "$f" ]; then
    echo "FAIL $name.png: missing or empty"
    fail=1
    continue
  fi
  if ! stats=$(iinfo --stats "$f" 2>&1) || ! grep -q "Stats Max" <<< "$stats"; then
    echo "FAIL $name.png: does not decode: $stats"
    fail=1
    continue
  fi
  read -r w h < <(sed -n '1s/.*: *\([0-9]*\) x *\([0-9]*\),.*/\1 \2/p' <<< "$stats")
  sd=$(sed -n 's/^ *Stats StdDev: //p' <<< "$stats" | tr ' ' '\n' | grep -E '^[0-9.]+$' | sort -g | tail -1)
  if [ -z "${w:-}" ] || [ "$w" -lt 100 ] || [ "$h" -lt 60 ]; then
    echo "FAIL $name.png: ${w:-?} x ${h:-?} pixels (expected at least 100 x 60)"
    fail=1
  elif grep -q "Constant: Yes" <<< "$stats" || awk -v s="$sd" 'BEGIN { exit !(s < 2) }'; then
    echo "FAIL $name.png: one flat colour (largest channel standard deviation ${sd:-?})"
    fail=1
  else
    echo "ok   $name.png: $w x $h, largest channel standard deviation $sd"
  fi
done
exit $fail
