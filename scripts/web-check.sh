#!/usr/bin/env bash
# The web client headless, for tests and for users' CI: serves SCENE (exported in id order) and
# PVS with the range server, opens the page in Debian's chromium headless (WebGL2 through
# SwiftShader) driven by puppeteer-core, replays the path and writes per frame the cell found,
# triangles drawn, ms per frame and PVS bytes fetched (and what the server sent) to OUT.
#
# Usage: web-check.sh SCENE PVS --path "x,y,z[@lx,ly,lz];..." --json OUT
#                     [--png DIR --png-frames 0,4,9] [--size WxH] [--fov DEG] [--bare]
#                     [--shading reference|materials] [--popping K] [--near-far r1,r2 [--centre x,y,z] [--env-size N]
#                      [--lookup eye|cylinder] [--clovr]] [--prefetch MARGIN]
# --popping K: the popping meter every K frames (popping_pixels per measured frame).
# --clovr: the near region grows by the CloVR scheduler on entering a cell (per frame: clovr).
# --bare: the frames without the overlays (to compare with pvs inspect --render's frames).
# --shading: the page's shading (default here `reference`, the CPU renderer's, which the frame
# comparisons need, with the near-far colour map at the nearest texel; `materials`: the page's
# own default, the scene's glTF materials and a filtered colour map).
# With the overlays shown, the record's `layout` says where they lie and what is wrong with that.
# --near-far without --centre: each cell's centre is pvs view's (pvs export --centres); per frame
# `centre` and `centre_source`.
# Exit: 0 done, 1 the page failed, 2 bad arguments or missing build, 77 chromium cannot start.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { sed -n 's/^# Usage: //p;s/^#   *\(\[--png.*\)/\1/p' "$0" >&2; exit 2; }
[[ $# -ge 2 ]] || usage
scene=$1 pvs=$2
shift 2
path_text="" json="" png="" png_frames="" size=640x400 fov=60 extra= near_far="" pinned=""
shading=reference
while [[ $# -gt 0 ]]; do
  if [[ $1 == --bare ]]; then
    extra+="&overlay=0"
    shift
    continue
  fi
  if [[ $1 == --clovr ]]; then
    extra+="&clovr=1"
    shift
    continue
  fi
  [[ $# -ge 2 ]] || usage
  case $1 in
    --path) path_text=$2 ;;
    --json) json=$2 ;;
    --png) png=$2 ;;
    --png-frames) png_frames=$2 ;;
    --size) size=$2 ;;
    --fov) fov=$2 ;;
    --shading) shading=$2 ;;
    --popping) extra+="&popping=$2" ;;
    --near-far) extra+="&nearfar=$2" near_far=1 ;;
    --centre) extra+="&centre=$2" pinned=1 ;;
    --env-size) extra+="&envsize=$2" ;;
    --lookup) extra+="&lookup=$2" ;;
    --prefetch) extra+="&prefetch=$2" ;;
    *) echo "web-check: unknown option $1" >&2; usage ;;
  esac
  shift 2
done
[[ -n $path_text && -n $json ]] || usage
command -v node >/dev/null || { echo "web-check: node not found (bash scripts/install-web-deps.sh)" >&2; exit 2; }
source "$root/scripts/web_stage.sh"
trap web_unstage EXIT
centres=""
[[ -n $near_far && -z $pinned ]] && centres=centres
web_stage "$scene" "$pvs" $centres
query=$(python3 -c 'import sys, urllib.parse as u; print(u.quote(sys.argv[1], safe=",;@.-"))' "$path_text")
url="$PAGE&path=$query&size=$size&fov=$fov&shading=$shading$extra"
mkdir -p "$(dirname "$json")"
set +e
node "$root/web/tools/web_check.mjs" --url "$url" --json "$json" \
  ${png:+--png-dir "$png"} ${png_frames:+--png-frames "$png_frames"} \
  --server-log "$SERVER_LOG" --pvs-name "$PVS_NAME" --size "$size"
rc=$?
set -e
exit $rc
