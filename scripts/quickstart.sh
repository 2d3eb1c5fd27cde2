#!/usr/bin/env bash
# README Quick start (a): install what is missing, build, and run the main job on the default
# scene shipped in data/: its statistics, then from-region visibility of a street-level view
# rectangle (the PVS bake, issue 5, will replace the second step).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
mkdir -p out
echo "== pvs info data/city.glb"
build/cli/pvs info data/city.glb
echo "== pvs region data/city.glb (view rectangle at eye height; see docs/cli.md)"
build/cli/pvs region data/city.glb --box -3,1.7,-20,3,1.7,20 --runs 2 --res 256 --json out/region.json
echo "wrote out/region.json"
