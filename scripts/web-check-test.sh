#!/usr/bin/env bash
# Headless test of the web client (ctest web_check_city): the quick start's bake of data/city.glb
# (at --res 32 for speed), replayed in chromium along a path through at least 5 cells. For every
# frame, the cell the runtime found in the browser must equal `pvs inspect --at`'s (or both find
# none), and the triangles drawn must equal that cell's PVS count. Then the page's frames of the
# centre crossing's PVS, looking along the four axes, are compared with `pvs inspect --render`'s
# pixel by pixel (scripts/web_compare.py: PSNR and the share of edge pixels), and the popping
# meter's pixels with the CPU renderer's missed pixels of the same views (within 0.1% of the
# frame's pixels: rasterisation against ray casting on triangle edges, and coplanar faces).
# Last, the page's near-far frame against `pvs view`'s with the same choices pinned (centre,
# radii, environment map size, eye lookup, 90 degrees, 320 x 240): PSNR at least 35 dB.
# Usage: web-check-test.sh PVS_EXE WORKDIR. Exit 0 pass, 1 fail, 2 missing build, 77 chromium
# cannot start. Time budget: the bake about 20 s on 2 cores, the replay about 10 s.
set -euo pipefail
pvs=$1 work=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
start=$(date +%s)
if [[ ! -f $work/city.pvs ]]; then
  "$pvs" bake "$root/data/city.glb" --walkable --cell-size 24 --box -120,-1,-120,120,1,120 \
    --res 32 --runs 1 -q -o "$work/city.pvs"
fi
echo "web-check-test: bake $work/city.pvs ($(($(date +%s) - start)) s)"
# Along the east-west street through the centre crossing, then north along the cross street,
# looking ahead; then looking back at the crossing; then from 40 m up, outside every cell (the
# page keeps the last cell's set: the cell found must be none there, as for pvs inspect).
path="-100,1.6,0;-80,1.6,0;-60,1.6,0;-40,1.6,0;-20,1.6,0;0,1.6,0;20,1.6,0;40,1.6,0;60,1.6,0"
path+=";80,1.6,0;0,1.6,20;0,1.6,40;0,1.6,60;0,1.6,80@0,1.6,0;0,40,60@0,0,0"
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" \
  --path "$path" --json "$work/web_check.json" --png "$work/png" --png-frames 0,5,13 --size 640x400
rc=$?
set -e
[[ $rc -eq 77 ]] && { echo "web-check-test: SKIPPED: chromium cannot start"; exit 77; }
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh exited $rc"; exit 1; }
python3 - "$pvs" "$work/city.pvs" "$work/web_check.json" "$path" <<'PY'
import json, subprocess, sys
pvs, pvs_file, check, path = sys.argv[1:5]
frames = json.load(open(check))["frames"]
points = [p.split("@")[0] for p in path.split(";")]
ok = len(frames) == len(points)
cells = set()
for f, p in zip(frames, points):
    r = subprocess.run([pvs, "inspect", pvs_file, "--at", p, "--json", "-q"], capture_output=True,
                       text=True)
    if r.returncode == 2 and "no cell contains" in r.stderr:
        want, count = -1, None
    else:
        j = json.loads(r.stdout)
        want, count = j["cell"], j["visible_count"]
    good = f["cell"] == want and (count is None or f["triangles_drawn"] == count)
    ok = ok and good
    if want >= 0:
        cells.add(want)
    print("  frame %2d at %-14s browser cell %4d, pvs inspect %4d; drawn %5d, PVS count %5s; %5.1f ms %s"
          % (f["frame"], p, f["cell"], want, f["triangles_drawn"], count, f["ms"],
             "" if good else "MISMATCH"))
if len(cells) < 5:
    print("web-check-test: FAIL: the path crosses %d cells, fewer than 5" % len(cells))
    ok = False
print("web-check-test: %s: %d frames through %d cells" % ("pass" if ok else "FAIL", len(frames),
                                                           len(cells)))
sys.exit(0 if ok else 1)
PY
"$pvs" inspect "$work/city.pvs" --scene "$root/data/city.glb" --at 0,1.6,0 --render "$work/cpu" \
  --frame 320x240 --json -q >"$work/cpu.json"
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "0,1.6,0@1,1.6,0;0,1.6,0@0,1.6,1;0,1.6,0@-1,1.6,0;0,1.6,0@0,1.6,-1" --fov 90 \
  --size 320x240 --popping 1 --json "$work/compare.json" --png "$work/compare" --png-frames 0,1,2,3
rc=$?
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (frames to compare) exited $rc"; exit 1; }
/usr/bin/python3 "$root/scripts/web_compare.py" "$work/cpu" "$work/compare"
python3 - "$work/cpu.json" "$work/compare.json" <<'PY'
import json, sys
cpu = [v["missed_pixels"] for v in json.load(open(sys.argv[1]))["render"]["views"]]
web = [f["popping_pixels"] for f in json.load(open(sys.argv[2]))["frames"]]
tolerance = 0.001 * 320 * 240  # pixels
ok = len(web) == len(cpu) and all(w is not None and abs(w - c) <= tolerance for w, c in zip(web, cpu))
print("web-check-test: popping pixels %s, CPU missed pixels %s (tolerance %d): %s"
      % (web, cpu, tolerance, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
"$pvs" view "$work/city.pvs" --scene "$root/data/city.glb" --at 0,1.6,0 --look 30,1.6,0 \
  --near-far 15,40 --centre 0,1.6,0 --env-size 512 --lookup eye --frame 320x240 -q \
  -o "$work/near_far/cpu.png"
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "0,1.6,0@30,1.6,0" --fov 90 --size 320x240 --near-far 15,40 --centre 0,1.6,0 \
  --env-size 512 --json "$work/near_far.json" --png "$work/near_far" --png-frames 0
rc=$?
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (near-far) exited $rc"; exit 1; }
/usr/bin/python3 - "$work/near_far/cpu.png" "$work/near_far/frame_0000.png" <<'PY'
import sys
import matplotlib.image as mi
import numpy as np
a, b = (np.round(mi.imread(f)[:, :, :3] * 255) for f in sys.argv[1:3])
mse = float(((a - b) ** 2).mean())
psnr = 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else float("inf")
ok = a.shape == b.shape and psnr >= 35.0
print("web-check-test: near-far frame against pvs view's: PSNR %.2f dB (>= 35): %s"
      % (psnr, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
