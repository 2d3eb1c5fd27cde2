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
#                     [--mode ods|stereo] [--ods-size W] [--ipd M] [--units-per-metre S]
#                     [--pole-merge s,e,x[:s,e,x]] [--tessellation dynamic|K] [--tess-segment DEG] [--reps N]
#                     [--dominant left|right] [--patch yoro|render|none] [--reproject gather|points]
#                     [--reference IMG]
# --mode ods: each path point is the centre of an ODS pair (WebGPU; docs/web.md): the PNGs are
# the W x W top-bottom pairs, --reps N renders each N more times (ms: the median); the page shows
# the pair through a read-back (display=2d: presenting a WebGPU canvas loses the device in
# headless chromium's SwiftShader).
# --mode stereo: single-render stereo (render the dominant eye, reproject, patch); the PNGs are
# 2W x 2H: the produced pair (left | right) above the two true renders.
# --reference IMG (with --mode and --png): frame 0's pair against IMG, per eye (PSNR, SSIM, pixels
# off by more than 8 steps; scripts/web_image_compare.py), into the JSON's `reference`: for ods a
# top-bottom pair (pvs view --ods's OUT.png), for stereo a side-by-side pair (pvs view --stereo's
# OUT_stereo_sbs.png).
# --popping K: the popping meter every K frames (popping_pixels per measured frame).
# --clovr: the near region grows by the CloVR scheduler on entering a cell (per frame: clovr).
# --bare: the frames without the overlays (to compare with pvs inspect --render's frames).
# --shading: the page's shading (default here `reference`, the CPU renderer's, which the frame
# comparisons need, with the near-far colour map at the nearest texel; `materials`: the page's
# own default, the scene's glTF materials and a filtered colour map).
# With the overlays shown, the record's `layout` says where they lie and what is wrong with that.
# --near-far without --centre: each cell's centre is pvs view's (pvs export --centres); per frame
# `centre` and `centre_source`.
# Exit: 0 done, 1 the page failed, 2 bad arguments or missing build, 77 chromium cannot start (or
# offers no WebGPU for --mode ods|stereo).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { sed -n 's/^# Usage: //p;s/^#   *\(\[--png.*\)/\1/p' "$0" >&2; exit 2; }
[[ $# -ge 2 ]] || usage
scene=$1 pvs=$2
shift 2
path_text="" json="" png="" png_frames="" size=640x400 fov=60 extra= near_far="" pinned="" reference=""
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
    --mode) extra+="&mode=$2"; [[ $2 == ods ]] && extra+="&display=2d" ;;
    --ods-size) extra+="&odssize=$2" ;;
    --ipd) extra+="&ipd=$2" ;;
    --units-per-metre) extra+="&upm=$2" ;;
    --pole-merge) extra+="&polemerge=$2" ;;
    --tessellation) extra+="&tess=$2" ;;
    --tess-segment) extra+="&tessdeg=$2" ;;
    --reps) extra+="&reps=$2" ;;
    --dominant) extra+="&dominant=$2" ;;
    --patch) extra+="&patch=$2" ;;
    --reference) reference=$2 ;;
    --reproject) extra+="&reproject=$2" ;;
    *) echo "web-check: unknown option $1" >&2; usage ;;
  esac
  shift 2
done
[[ -n $path_text && -n $json ]] || usage
if [[ -n $reference ]]; then
  [[ -f $reference ]] || { echo "web-check: --reference $reference: no such file" >&2; exit 2; }
  [[ $extra == *mode=ods* || $extra == *mode=stereo* ]] && [[ -n $png ]] ||
    { echo "web-check: --reference needs --mode ods|stereo and --png" >&2; exit 2; }
  png_frames=0${png_frames:+,$png_frames}
fi
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
if [[ $rc -eq 0 && -n $reference ]]; then
  frame=$png/frame_0000.png
  if [[ $extra == *mode=ods* ]]; then
    cmp_args=(--tiles 2x1)
  else
    read -r w h < <(python3 -c 'import sys; print(*sys.argv[1].split("x"))' "$size")
    cmp_args=(--tiles 1x2 --crop-b "0,0,$((2 * w)),$h")
  fi
  /usr/bin/python3 "$root/scripts/web_image_compare.py" "$reference" "$frame" "${cmp_args[@]}" \
    --names left,right --json "$json.reference" || rc=1
  python3 - "$json" "$reference" <<'PY' || rc=1
import json, os, sys
out, ref = sys.argv[1], sys.argv[2]
j = json.load(open(out))
j["reference"] = {"image": ref, "eyes": json.load(open(out + ".reference"))}
json.dump(j, open(out + ".tmp", "w"), indent=1)
os.replace(out + ".tmp", out)
os.remove(out + ".reference")
PY
fi
exit $rc
