#!/usr/bin/env bash
# README Quick start (a): install what is missing, build, and run the main job on the default
# scene shipped in data/: bake its PVS (walkable view cells over the streets around the centre),
# then summarise the file and inspect one cell, with frames of the full scene against the cell's
# visible set (ε, PSNR, SSIM) in out/render/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
# The web client (web/): emscripten, chromium, node + npm when missing, then its bundle.
bash scripts/install-web-deps.sh
bash scripts/build-web.sh
mkdir -p out
PVS=build/cli/pvs
echo "== pvs info data/city.glb"
$PVS info data/city.glb
echo "== pvs bake data/city.glb -> out/city.pvs"
# Cells of 12 m from -66: the one at the centre crossing, [-6, 6] in x and z, lies inside the 14 m
# streets (data/README.md), so the cell the script inspects below straddles no building; cells
# are kept only on floor a walker reaches from the crossing (no roofs).
$PVS bake data/city.glb --walkable --walkable-from 0,0,0 --cell-size 12 --box -66,-1,-66,66,1,66 \
  --res 128 --runs 1 \
  --json out/city.bake.json -o out/city.pvs
echo "== pvs inspect out/city.pvs"
$PVS inspect out/city.pvs
echo "== pvs inspect out/city.pvs --at 0,1.6,0 (the cell at the centre crossing)"
$PVS inspect out/city.pvs --scene data/city.glb --at 0,1.6,0 --max-ids 20 --render out/render \
  --export-gltf out/cell.glb
echo "Done: out/city.pvs (the PVS), out/render/ (frames and heat maps), out/cell.glb (the cell's visible set)."
echo "Walk through it in a browser: bash scripts/view.sh (prints the URL)."
