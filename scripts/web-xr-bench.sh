#!/usr/bin/env bash
# The measurements of docs/web.md's ODS and single-render stereo sections, in one run:
#  - the ODS paper's Table 1 as ratios: the page's pair (WebGPU) with no tessellation, static 4,
#    static 16 and dynamic tessellation (Alg. 1 with the paper's 8-degree segments, and with
#    1-degree segments: tessdeg=1), each timed (median of REPS) and compared with `pvs view
#    --ods --ods-method rays` (PSNR, SSIM, pixels off by more than 8 steps, per eye);
#  - single-render stereo at a headset's eye size (the mesh reprojection with the yoro and render
#    patchers, the gather with yoro): the frame time of render + reproject + patch against two
#    renders and one OVR_multiview2 render (medians of REPS), each pass alone and a full-screen
#    copy, the produced eye's PSNR against its true render, against `pvs view --stereo yoro`'s at
#    the same size.
# Usage: web-xr-bench.sh PVS_EXE SCENE PVS OUTDIR [ODS_SIZE] [EYE_SIZE]
#        (defaults 4096 and 1832x1920; centre, eye and look: ODS_AT, STEREO_AT, STEREO_LOOK).
# Prints the tables; JSON and PNGs stay in OUTDIR. SwiftShader is not a GPU: read the ratios.
set -euo pipefail
pvs=$1 scene=$2 bake=$3 out=$4 size=${5:-4096} eye=${6:-1832x1920}
root=$(cd "$(dirname "$0")/.." && pwd)
at=${ODS_AT:-0,1.6,0} sat=${STEREO_AT:-4,1.6,3} slook=${STEREO_LOOK:-30,1.6,-2} reps=${REPS:-3}
mkdir -p "$out"
web() { PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$scene" "$bake" "$@"; }
"$pvs" view "$bake" --scene "$scene" --at "$at" --ods --ods-method rays --ods-size "$size" -q \
  -o "$out/rays/ods.png" --json "$out/rays/ods.json"
for t in 1 4 16 dynamic dynamic1; do
  tess=$t seg=()
  [[ $t == dynamic1 ]] && tess=dynamic seg=(--tess-segment 1)
  web --mode ods --ods-size "$size" --path "$at" --tessellation "$tess" "${seg[@]}" --reps "$reps" \
    --json "$out/ods_$t.json" --png "$out/ods_$t" --png-frames 0
  /usr/bin/python3 "$root/scripts/web_image_compare.py" "$out/rays/ods.png" "$out/ods_$t/frame_0000.png" \
    --tiles 2x1 --names left,right --json "$out/ods_${t}_compare.json" >/dev/null
done
w=${eye%x*} h=${eye#*x}
"$pvs" view "$bake" --scene "$scene" --at "$sat" --look "$slook" --stereo yoro --ipd 0.064 \
  --dominant left --patch yoro --frame "$eye" -q -o "$out/cpu_stereo/st.png" --json "$out/cpu_stereo.json"
for p in yoro render yoro-gather; do
  web --mode stereo --size "$eye" --fov 90 --ipd 0.064 --dominant left --patch "${p%-gather}" \
    --reproject "$([[ $p == *-gather ]] && echo gather || echo mesh)" \
    --path "$sat@$slook" --reps "$reps" --json "$out/stereo_$p.json" --png "$out/stereo_$p" --png-frames 0
  /usr/bin/python3 "$root/scripts/web_image_compare.py" "$out/cpu_stereo/st_stereo_right.png" \
    "$out/stereo_$p/frame_0000.png" --crop-b "$w,0,$w,$h" --names "right_${p}_vs_cpu_yoro"
done
python3 - "$out" "$size" "$eye" <<'PY'
import json, sys
out, size, eye = sys.argv[1:4]
print("ODS %s x %d an eye; the page against pvs view --ods --ods-method rays" % (size, int(size) // 2))
print("| tessellation | ms a pair | ratio to none | output slots | PSNR L / R dB | SSIM L / R | off by > 8 steps L / R |")
print("|---|---|---|---|---|---|---|")
base = None
for t in ("1", "4", "16", "dynamic", "dynamic1"):
    f = json.load(open("%s/ods_%s.json" % (out, t)))["frames"][0]
    c = json.load(open("%s/ods_%s_compare.json" % (out, t)))
    base = base or f["ms"]
    print("| %s | %.0f | %.2f | %d | %.2f / %.2f | %.4f / %.4f | %.3f%% / %.3f%% |" % (
        {"1": "none", "4": "static 4", "16": "static 16", "dynamic": "dynamic (Alg. 1, 8 deg segments)",
         "dynamic1": "dynamic (Alg. 1, 1 deg segments)"}[t], f["ms"], f["ms"] / base,
        f["small_triangle_slots"], c["left"]["psnr"], c["right"]["psnr"], c["left"]["ssim"],
        c["right"]["ssim"], 100 * c["left"]["diff_share"], 100 * c["right"]["diff_share"]))
cpu = json.load(open("%s/cpu_stereo.json" % out))["stereo"]["eyes"]["right"]
print("\nSingle-render stereo %s an eye (left rendered); pvs view --stereo yoro: PSNR %.2f dB, holes %.3f%%"
      % (eye, cpu["method_error"]["psnr"], 100 * cpu["holes"]["share"]))
print("| reprojection, patch | PSNR dB | holes | ms single | ms one render | ms reprojection | ms patch | ms full-screen copy | ms two renders | ms multiview | single / two | single / multiview |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for p in ("yoro", "render", "yoro-gather"):
    f = json.load(open("%s/stereo_%s.json" % (out, p)))["frames"][0]
    print("| %s | %.2f | %.3f%% | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %s | %.2f | %s |" % (
        "gather, yoro" if p == "yoro-gather" else "mesh, " + p, f["psnr"], 100 * f["hole_share"],
        f["ms_single"], f["ms_one_render"], f["ms_reproject"], f["ms_patch"], f["ms_copy_pass"], f["ms_two_renders"],
        "%.0f" % f["ms_multiview"] if f["ms_multiview"] else "-", f["ratio_single_to_two"],
        "%.2f" % f["ratio_single_to_multiview"] if f["ratio_single_to_multiview"] else "-"))
PY
