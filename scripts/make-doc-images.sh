#!/usr/bin/env bash
# make-doc-images.sh [PVS]: regenerates docs/img/ from the default scene (data/city.glb) with the
# quick start's bake, so the pictures in README.md and docs/ always show what the code does now:
#   cells_top.png       top view of the walkable view cells, coloured by PVS size
#   cell_set.png        top view of one cell's visible set (red) against the full scene (grey)
#   cell_frames.png     from that cell: full-scene frame | PVS frame | error heat map (pvs inspect --render)
#   near_far.png        a near-far frame of that cell (pvs view)
#   bench_found_vs_seconds.png, bench_epsilon_vs_seconds.png   pvs bench plots on the centre crossing
# Needs a built pvs (default build/cli/pvs) and /usr/bin/python3 with matplotlib. Each PNG is
# checked to be under 300 KB. Takes a few minutes on 2 cores (the bake is the quick start's).
set -euo pipefail
cd "$(dirname "$0")/.."
PVS=${1:-build/cli/pvs}
PY=/usr/bin/python3
[ -x "$PVS" ] || { echo "make-doc-images: $PVS not found (bash scripts/build.sh)" >&2; exit 2; }
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
OUT=docs/img
mkdir -p "$OUT"
SCENE=data/city.glb
AT=0,1.6,0
echo "== bake (the quick start's)"
"$PVS" bake "$SCENE" --walkable --cell-size 24 --box -120,-1,-120,120,1,120 --res 128 --runs 1 -q -o "$W/city.pvs"
"$PVS" export "$SCENE" -o "$W/city.obj" > /dev/null
"$PVS" inspect "$W/city.pvs" --json > "$W/summary.json"
n=$("$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))['cells'])" "$W/summary.json")
for ((c = 0; c < n; c++)); do "$PVS" inspect "$W/city.pvs" --cell "$c" --json > "$W/cell$c.json"; done
echo "== the cell at $AT: its set, frames, heat map"
"$PVS" inspect "$W/city.pvs" --scene "$SCENE" --at "$AT" --json --frame 320x240 --render "$W/render" > "$W/at.json"
echo "== near-far frame"
"$PVS" view "$W/city.pvs" --scene "$SCENE" --at "$AT" --look 30,1.6,0 --frame 480x320 -o "$W/view/frame.png" \
  --json "$W/view.json" > /dev/null
echo "== bench (small settings)"
"$PVS" bench "$SCENE" --box -4,1.6,-4,4,1.6,4 --res 128 --views 4 --frame 320x240 --max-point-runs 2000 \
  --no-frames --out "$W/bench" > /dev/null
"$PY" scripts/doc_images.py "$W" "$OUT"
cp "$W/view/frame.png" "$OUT/near_far.png"
cp "$W/bench/found_vs_seconds.png" "$OUT/bench_found_vs_seconds.png"
cp "$W/bench/epsilon_vs_seconds.png" "$OUT/bench_epsilon_vs_seconds.png"
for f in "$OUT"/*.png; do
  size=$(stat -c %s "$f")
  [ "$size" -lt 307200 ] || { echo "make-doc-images: $f is $size bytes (limit 300 KB)" >&2; exit 1; }
  echo "  $f ($size bytes)"
done
