#!/usr/bin/env bash
# make-doc-images.sh [--quick] [--pvs PVS] [OUT]: regenerates the pictures of README.md and docs/
# from the default scene (data/city.glb) with the quick start's bake, so that they show what the
# code does now. Writes into OUT (default docs/img):
#   cells_top.png       top view of the walkable view cells, coloured by PVS size
#   cell_set.png        top view of one cell's visible set (red) against the full scene (grey)
#   cell_frames.png     from that cell: full-scene frame | PVS frame | error heat map (pvs inspect --render)
#   near_far.png        a near-far frame of that cell (pvs view): near-far | without morph | full scene | heat map
#   bench_found_vs_seconds.png, bench_epsilon_vs_seconds.png   pvs bench plots on the centre crossing
# --quick: the same steps and pictures on a 3 x 3 cell bake at small resolutions (about 20 s; what
# ctest's DocImages.ScriptWritesEveryPictureDecodableAndNotFlat runs, into a temporary folder).
# Needs a built pvs (default build/cli/pvs) and /usr/bin/python3 with matplotlib
# (scripts/install-deps.sh installs both). Each PNG must stay under 300 KB. The full run takes
# about 4 minutes on 2 cores, most of it the bake (docs/images.md).
set -euo pipefail
cd "$(dirname "$0")/.."
PVS=build/cli/pvs
OUT=docs/img
QUICK=0
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) QUICK=1 ;;
    --pvs)
      [ $# -ge 2 ] || { echo "make-doc-images: --pvs needs a path" >&2; exit 2; }
      PVS=$2
      shift
      ;;
    -h | --help)
      sed -n '2,15p' "$0"
      exit 0
      ;;
    -*) echo "make-doc-images: unknown option '$1' (see --help)" >&2; exit 2 ;;
    *) OUT=$1 ;;
  esac
  shift
done
PY=/usr/bin/python3
[ -x "$PVS" ] || { echo "make-doc-images: $PVS not found (bash scripts/build.sh, or give --pvs)" >&2; exit 2; }
"$PY" -c "import matplotlib, numpy" 2> /dev/null ||
  { echo "make-doc-images: $PY lacks matplotlib or numpy (bash scripts/install-deps.sh)" >&2; exit 2; }
start=$(date +%s)
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
mkdir -p "$OUT"
SCENE=data/city.glb
AT=0,1.6,0
if [ "$QUICK" = 1 ]; then
  BOX=-36,-1,-36,36,1,36 RES=32 FRAME=96x72 VIEW_FRAME=120x80 BENCH="--res 32 --views 2 --frame 64x48 --max-point-runs 200"
else
  # The quick start's bake (scripts/quickstart.sh) and small frames.
  BOX=-120,-1,-120,120,1,120 RES=128 FRAME=320x240 VIEW_FRAME=480x320 BENCH="--res 128 --views 4 --frame 320x240 --max-point-runs 2000"
fi
step() { echo "== $* ($(($(date +%s) - start)) s)"; }
step "bake data/city.glb (walkable cells of 24 m over $BOX, --res $RES)"
"$PVS" bake "$SCENE" --walkable --cell-size 24 --box "$BOX" --res "$RES" --runs 1 -q -o "$W/city.pvs"
"$PVS" export "$SCENE" -q -o "$W/city.obj"
"$PVS" inspect "$W/city.pvs" --json > "$W/summary.json"
step "the cell at $AT: its set, frames and heat map"
"$PVS" inspect "$W/city.pvs" --scene "$SCENE" --at "$AT" --json -q --frame "$FRAME" --render "$W/render" > "$W/at.json"
step "near-far frame"
"$PVS" view "$W/city.pvs" --scene "$SCENE" --at "$AT" --look 30,1.6,0 --frame "$VIEW_FRAME" -q \
  -o "$W/view/frame.png" --json "$W/view.json"
step "bench (small settings)"
# shellcheck disable=SC2086
"$PVS" bench "$SCENE" --box -4,1.6,-4,4,1.6,4 $BENCH --no-frames -q --out "$W/bench"
step "pictures"
"$PY" scripts/doc_images.py "$W" "$OUT"
cp "$W/bench/found_vs_seconds.png" "$OUT/bench_found_vs_seconds.png"
cp "$W/bench/epsilon_vs_seconds.png" "$OUT/bench_epsilon_vs_seconds.png"
total=0
for name in cells_top cell_set cell_frames near_far bench_found_vs_seconds bench_epsilon_vs_seconds; do
  f=$OUT/$name.png
  [ -s "$f" ] || { echo "make-doc-images: $f was not written" >&2; exit 1; }
  size=$(stat -c %s "$f")
  [ "$size" -lt 307200 ] || { echo "make-doc-images: $f is $size bytes (limit 300 KB)" >&2; exit 1; }
  total=$((total + size))
  echo "  $f ($size bytes)"
done
echo "make-doc-images: 6 pictures, $total bytes, in $(($(date +%s) - start)) s"
