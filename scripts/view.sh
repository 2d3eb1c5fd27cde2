#!/usr/bin/env bash
# Opens the web client on a bake: serves the scene and its PVS over HTTP (with range requests)
# and prints the local URL to open in a browser. Ctrl-C stops it.
# Usage: view.sh [SCENE [PVS]]  (default: data/city.glb and out/city.pvs, the quick start's bake)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
scene=${1:-$root/data/city.glb}
pvs=${2:-$root/out/city.pvs}
source "$root/scripts/web_stage.sh"
trap web_unstage EXIT
WEB_PORT=${WEB_PORT:-8035} web_stage "$scene" "$pvs" centres  # near-far: pvs view's centres
echo "Open $PAGE&at=0,1.6,0&prefetch=0"
echo "  with near-far (Eq. 1 morph within 15-40 m, the far region from the cell's cube map) and"
echo "  CloVR's progressive near region: $PAGE&at=0,1.6,0&prefetch=0&nearfar=15,40&clovr=1"
echo "(WASD to walk, drag to look; the server logs each request to $SERVER_LOG; Ctrl-C stops)"
wait "$SERVER_PID"
