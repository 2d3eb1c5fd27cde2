#!/usr/bin/env bash
# Headless tests of the web client's stereo modes (ctest web_check_ods, web_check_stereo) on a
# small bake of data/city.glb: 2 x 2 walkable cells of 24 m meeting at the centre crossing, --res
# 32 (made once in WORKDIR/.., shared by both tests).
#  ods: the page's ODS pair (WebGPU, docs/web.md) centred on the crossing, where the viewing disc
#    touches all 4 cells, against `pvs view --ods --ods-method rays` with the same centre, IPD
#    and size (1024 x 512 an eye): the cells used and the triangles drawn equal pvs view's; per
#    eye PSNR >= ODS_MIN_PSNR dB and SSIM >= ODS_MIN_SSIM; then with pole merging (45,0,1) the
#    same bounds; then no tessellation (static level 1) differs from the rays on more pixels
#    than dynamic tessellation (what the paper's tessellation is for).
#  stereo: single-render stereo (WebGL2: the left eye rendered, reprojected to the right, holes
#    patched by the yoro patcher) against `pvs view --stereo yoro --patch yoro` at 320 x 240,
#    90 degrees: both true renders against pvs view's (PSNR >= 36 dB, at most 0.5% of the pixels
#    off by more than 8 steps: measured 49.7 / 40.7 dB and 0.01 / 0.06%, the right eye's edge
#    pixels being a vertical edge through pixel centres, where coverage ties), the produced right eye
#    against the true right eye no worse than STEREO_PSNR_SLACK dB below pvs view's method error
#    PSNR, and the hole pixels within a factor of 2 (+ 0.2% of the frame) of pvs view's.
# Frame times are printed, never asserted (docs/web.md: SwiftShader is not a GPU).
# Usage: web-xr-test.sh ods|stereo PVS_EXE WORKDIR. Exit 0 pass, 1 fail, 2 missing build, 77
# chromium cannot start or offers no WebGPU (ods). Time budget: the bake about 15 s on 2 cores
# (once), ods about 40 s, stereo about 25 s.
set -euo pipefail
mode=$1 pvs=$2 work=$3
root=$(cd "$(dirname "$0")/.." && pwd)
ODS_MIN_PSNR=35       # dB per eye (measured: see docs/web.md, "ODS")
ODS_MIN_SSIM=0.97
STEREO_PSNR_SLACK=1.0 # dB below pvs view's method-error PSNR
mkdir -p "$work"
bake=$work/../web_xr_city.pvs
start=$(date +%s)
if [[ ! -f $bake ]]; then
  "$pvs" bake "$root/data/city.glb" --walkable --cell-size 24 --box -24,-1,-24,24,1,24 \
    --res 32 --runs 1 -q -o "$bake.tmp.pvs"
  mv "$bake.tmp.pvs" "$bake"
fi
echo "web-xr-test: bake $bake ($(($(date +%s) - start)) s)"
check() {  # web-check.sh with the exit codes mapped to the test's
  set +e
  PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$bake" "$@"
  local rc=$?
  set -e
  [[ $rc -eq 77 ]] && { echo "web-xr-test: SKIPPED: chromium cannot start or offers no WebGPU"; exit 77; }
  [[ $rc -eq 0 ]] || { echo "web-xr-test: FAIL: web-check.sh exited $rc"; exit 1; }
}
compare=(/usr/bin/python3 "$root/scripts/web_image_compare.py")

if [[ $mode == ods ]]; then
  centre=0,1.6,0
  ods_case() {  # NAME [pvs view options] -- [web-check options]
    local name=$1 cpu=() web=()
    shift
    while [[ $# -gt 0 && $1 != -- ]]; do cpu+=("$1"); shift; done
    shift
    web=("$@")
    mkdir -p "$work/$name"
    "$pvs" view "$bake" --scene "$root/data/city.glb" --at "$centre" --ods --ods-method rays \
      --ods-size 1024 "${cpu[@]}" -q -o "$work/$name/cpu.png" --json "$work/$name/cpu.json"
    check --mode ods --ods-size 1024 --path "$centre" "${web[@]}" --reps 2 \
      --json "$work/$name.json" --png "$work/$name" --png-frames 0
  }
  ods_case plain -- --tessellation dynamic
  python3 - "$work/plain/cpu.json" "$work/plain.json" <<'PY'
import json, sys
cpu, web = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
f = web["frames"][0]
cpu_cells, web_cells = sorted(cpu["ods"]["cells_used"]), sorted(f["cells_used"])
ok = cpu_cells == web_cells and len(web_cells) == 4 and f["triangles_drawn"] == cpu["ods"]["triangles"]["visible"]
print("web-xr-test: ods cells %s (pvs view %s), triangles %d (pvs view %d), %.1f ms a pair "
      "(median of 2, %s): %s" % (web_cells, cpu_cells, f["triangles_drawn"], cpu["ods"]["triangles"]["visible"],
                                 f["ms"], f["adapter"], "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
  "${compare[@]}" "$work/plain/cpu.png" "$work/plain/frame_0000.png" --tiles 2x1 --names left,right \
    --min-psnr $ODS_MIN_PSNR --json "$work/plain_compare.json"
  ods_case merged --pole-merge 45,0,1 -- --pole-merge 45,0,1 --tessellation dynamic
  "${compare[@]}" "$work/merged/cpu.png" "$work/merged/frame_0000.png" --tiles 2x1 --names left,right \
    --min-psnr $ODS_MIN_PSNR --json "$work/merged_compare.json"
  check --mode ods --ods-size 1024 --path "$centre" --tessellation 1 --json "$work/none.json" \
    --png "$work/none" --png-frames 0
  "${compare[@]}" "$work/plain/cpu.png" "$work/none/frame_0000.png" --tiles 2x1 --names left,right \
    --json "$work/none_compare.json"
  python3 - "$work/plain_compare.json" "$work/merged_compare.json" "$work/none_compare.json" \
    "$ODS_MIN_SSIM" <<'PY'
import json, sys
plain, merged, none = (json.load(open(f)) for f in sys.argv[1:4])
ok = all(m[e]["ssim"] >= float(sys.argv[4]) for m in (plain, merged) for e in ("left", "right"))
more = all(none[e]["diff_share"] > plain[e]["diff_share"] for e in ("left", "right"))
print("web-xr-test: ods SSIM %s (>= %s); pixels off, no tessellation %s against dynamic %s: %s"
      % ([round(m[e]["ssim"], 4) for m in (plain, merged) for e in ("left", "right")], sys.argv[4],
         [round(none[e]["diff_share"], 5) for e in ("left", "right")],
         [round(plain[e]["diff_share"], 5) for e in ("left", "right")], "pass" if ok and more else "FAIL"))
sys.exit(0 if ok and more else 1)
PY
elif [[ $mode == stereo ]]; then
  at=4,1.6,3 look=30,1.6,-2
  mkdir -p "$work/cpu"
  "$pvs" view "$bake" --scene "$root/data/city.glb" --at "$at" --look "$look" --stereo yoro \
    --ipd 0.064 --dominant left --patch yoro --frame 320x240 -q -o "$work/cpu/st.png" \
    --json "$work/cpu.json"
  check --mode stereo --size 320x240 --fov 90 --ipd 0.064 --dominant left --patch yoro \
    --path "$at@$look" --reps 3 --json "$work/stereo.json" --png "$work/stereo" --png-frames 0
  png=$work/stereo/frame_0000.png
  "${compare[@]}" "$work/cpu/st_stereo_left_truth.png" "$png" --crop-b 0,240,320,240 \
    --names left_truth --min-psnr 36 --max-diff 0.005
  "${compare[@]}" "$work/cpu/st_stereo_right_truth.png" "$png" --crop-b 320,240,320,240 \
    --names right_truth --min-psnr 36 --max-diff 0.005
  "${compare[@]}" "$work/cpu/st_stereo_right.png" "$png" --crop-b 320,0,320,240 --names right_vs_cpu_yoro
  python3 - "$work/cpu.json" "$work/stereo.json" "$STEREO_PSNR_SLACK" <<'PY'
import json, sys
cpu, web = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
f, e = web["frames"][0], cpu["stereo"]["eyes"]["right"]
cpu_psnr, cpu_holes = e["method_error"]["psnr"], e["holes"]["share"]
ok_psnr = f["psnr"] is None or f["psnr"] >= cpu_psnr - float(sys.argv[3])
ok_holes = f["hole_share"] <= 2 * cpu_holes + 0.002 and cpu_holes <= 2 * f["hole_share"] + 0.002
print("web-xr-test: stereo right eye against its true render: PSNR %.2f dB (pvs view %.2f, slack %s), "
      "holes %.3f%% (pvs view %.3f%%): %s" % (f["psnr"], cpu_psnr, sys.argv[3], 100 * f["hole_share"],
                                             100 * cpu_holes, "pass" if ok_psnr and ok_holes else "FAIL"))
print("web-xr-test: stereo ms (median of %d): single %.1f, two renders %.1f, multiview %s; ratio to "
      "two %.2f (printed, not asserted)" % (f["reps"], f["ms_single"], f["ms_two_renders"],
                                          f["ms_multiview"], f["ratio_single_to_two"]))
sys.exit(0 if ok_psnr and ok_holes else 1)
PY
else
  echo "usage: web-xr-test.sh ods|stereo PVS_EXE WORKDIR" >&2
  exit 2
fi
echo "web-xr-test: $mode pass ($(($(date +%s) - start)) s)"
