#!/usr/bin/env bash
# Headless test of the web client (ctest web_check_city): the quick start's bake of data/city.glb
# (at --res 32 for speed), replayed in chromium along a path through at least 5 cells. For every
# frame, the cell the runtime found in the browser must equal `pvs inspect --at`'s (or both find
# none), and the triangles drawn must equal that cell's PVS count. Then the page's frames of the
# centre crossing's PVS, looking along the four axes, are compared with `pvs inspect --render`'s
# pixel by pixel (scripts/web_compare.py: PSNR and the share of edge pixels), and the popping
# meter's pixels with the CPU renderer's missed pixels of the same views (within 0.1% of the
# frame's pixels: rasterisation against ray casting on triangle edges, and coplanar faces).
# Then the page's near-far frame against `pvs view`'s with the same choices (the centre pvs view
# chose, radii, environment map size, eye lookup, 90 degrees, 320 x 240): PSNR at least 38 dB; the
# CloVR growth of the near region frame by frame, ending on the exact set by triangle; the page's
# near-far centre in 7 cells against pvs view's; that prefetching neighbours with their Delta
# chains leaves nothing to wait for on entering one; and dynamic far objects against pvs view's,
# both failing (BoxAnimated) and passing (a box in front of a wall) the range test.
# Usage: web-check-test.sh PVS_EXE WORKDIR. Exit 0 pass, 1 fail, 2 missing build, 77 chromium
# cannot start. Time budget: the bake about 20 s on 2 cores, the checks about 90 s.
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
# The near-far frames against pvs view's, each with the same choices: first pinned (centre on
# the eye, 15,40), then pvs view's own (its default centre: the centre of the cell's view region,
# moved to a free point when the scene encloses it; its default radii), which it reports and the
# page is given; last the same with the cylinder lookup. Eye lookup, 512 x 512 faces, 90 degrees,
# 320 x 240. PSNR at least 38 dB.
nf_compare() {  # NAME CENTRE R1,R2 [LOOKUP]  (CENTRE -: the page reads pvs export --centres)
  local pin=(--centre "$2")
  [[ $2 == - ]] && pin=()
  set +e
  PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
    --path "0,1.6,0@30,1.6,0" --fov 90 --size 320x240 --near-far "$3" "${pin[@]}" \
    --env-size 512 --lookup "${4:-eye}" --json "$work/$1.json" --png "$work/$1" --png-frames 0
  local rc=$?
  set -e
  [[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh ($1) exited $rc"; exit 1; }
  /usr/bin/python3 - "$work/$1/cpu.png" "$work/$1/frame_0000.png" "$1" "$2" "$3" <<'PY'
import sys
import matplotlib.image as mi
import numpy as np
a, b = (np.round(mi.imread(f)[:, :, :3] * 255) for f in sys.argv[1:3])
mse = float(((a - b) ** 2).mean())
psnr = 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else float("inf")
off = float((np.abs(a - b).max(axis=2) > 8).mean()) * 100
ok = a.shape == b.shape and psnr >= 38.0
print("web-check-test: %s frame (centre %s, radii %s) against pvs view's: PSNR %.2f dB (>= 38), "
      "%.2f%% of pixels off by more than 8 steps: %s"
      % (sys.argv[3], sys.argv[4], sys.argv[5], psnr, off, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
}
"$pvs" view "$work/city.pvs" --scene "$root/data/city.glb" --at 0,1.6,0 --look 30,1.6,0 \
  --near-far 15,40 --centre 0,1.6,0 --env-size 512 --lookup eye --frame 320x240 -q \
  -o "$work/near_far/cpu.png"
nf_compare near_far 0,1.6,0 15,40
"$pvs" view "$work/city.pvs" --scene "$root/data/city.glb" --at 0,1.6,0 --look 30,1.6,0 \
  --env-size 512 --lookup eye --frame 320x240 -q -o "$work/near_far_default/cpu.png" \
  --json "$work/near_far_default/cpu.json"
read -r centre radii < <(python3 -c 'import json, sys; j = json.load(open(sys.argv[1]))
print(",".join(repr(v) for v in j["centre"]), "%r,%r" % (j["r1"], j["r2"]))' "$work/near_far_default/cpu.json")
nf_compare near_far_default - "$radii"
python3 - "$work/near_far_default/cpu.json" "$work/near_far_default.json" <<'PY'
import json, sys
cpu = json.load(open(sys.argv[1]))["centre"]
web = json.load(open(sys.argv[2]))["frames"][0]
ok = web["centre"] == cpu and web["centre_source"] == "pvs view"
print("web-check-test: the page's centre %s (%s), pvs view's %s: %s"
      % (web["centre"], web["centre_source"], cpu, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
# The centre in every cell the page enters with near-far on equals pvs view's (without --centre):
# the page reads the centres pvs export --centres computes with pvs view's function.
centres_path="-60,1.6,0;-40,1.6,0;-20,1.6,0;0,1.6,0;20,1.6,0;40,1.6,0;0,1.6,40;0,1.6,80"
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "$centres_path" --size 160x120 --near-far 30,60 --env-size 32 --json "$work/centres.json"
rc=$?
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (centres) exited $rc"; exit 1; }
python3 - "$pvs" "$work/city.pvs" "$root/data/city.glb" "$work/centres.json" "$work/centres" \
  "$centres_path" <<'PY'
import json, subprocess, sys
pvs, pvs_file, scene, check, out, path = sys.argv[1:7]
frames = json.load(open(check))["frames"]
points = path.split(";")
ok, cells, moved = len(frames) == len(points), set(), 0
for f, p in zip(frames, points):
    x, y, z = (float(v) for v in p.split(","))
    subprocess.run([pvs, "view", pvs_file, "--scene", scene, "--at", p, "--look",
                    "%r,%r,%r" % (x + 1, y, z), "--frame", "16x12",
                    "--env-size", "16", "-q", "-o", out + "/cpu.png", "--json", out + "/cpu.json"],
                   check=True, stderr=subprocess.DEVNULL)
    cpu = json.load(open(out + "/cpu.json"))
    good = f["cell"] == cpu["cell"] and f["centre"] == cpu["centre"] and f["centre_source"] == "pvs view"
    ok = ok and good
    cells.add(f["cell"])
    print("  frame %d at %-12s cell %3d: page's centre %s, pvs view's %s %s"
          % (f["frame"], p, f["cell"], f["centre"], cpu["centre"], "" if good else "MISMATCH"))
ok = ok and len(cells) >= 5
print("web-check-test: near-far centres in %d cells equal pvs view's: %s"
      % (len(cells), "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
"$pvs" view "$work/city.pvs" --scene "$root/data/city.glb" --at 0,1.6,0 --look 30,1.6,0 \
  --near-far "$radii" --centre "$centre" --env-size 512 --lookup cylinder --frame 320x240 -q \
  -o "$work/near_far_cylinder/cpu.png"
nf_compare near_far_cylinder "$centre" "$radii" cylinder
centre=0,1.6,0
# CloVR: entering the crossing's cell, the near region grows by the C API's scheduler; 40 frames
# at the same eye. The near count never shrinks, grows (frame 0 injects the first merged ring's
# objects), reaches the end (done), and near + environment map is the cell's whole set in every
# frame of the growth. Once complete, the page draws the cell's exact partition by triangle:
# triangles drawn + far (environment map) + dynamic far equal the cell's PVS count, and the last
# frame equals, triangle counts and pixels, the frame of the same view with CloVR off.
clovr_path=$(printf '0,1.6,0@30,1.6,0;%.0s' $(seq 40))
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "${clovr_path%;}" --fov 90 --size 160x120 --near-far 15,40 --centre "$centre" \
  --env-size 128 --clovr --json "$work/clovr.json" --png "$work/clovr" --png-frames 39
rc=$?
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "0,1.6,0@30,1.6,0" --fov 90 --size 160x120 --near-far 15,40 --centre "$centre" \
  --env-size 128 --json "$work/clovr_off.json" --png "$work/clovr_off" --png-frames 0
rc=$((rc | $?))
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (CloVR) exited $rc"; exit 1; }
/usr/bin/python3 - "$pvs" "$work/city.pvs" "$work/clovr.json" "$work/clovr_off.json" \
  "$work/clovr/frame_0039.png" "$work/clovr_off/frame_0000.png" <<'PY'
import json, subprocess, sys
import matplotlib.image as mi
import numpy as np
pvs, pvs_file, check, off_check, png, off_png = sys.argv[1:7]
frames = json.load(open(check))["frames"]
off = json.load(open(off_check))["frames"][0]
count = json.loads(subprocess.run([pvs, "inspect", pvs_file, "--at", "0,1.6,0", "--json", "-q"],
                                  capture_output=True, text=True, check=True).stdout)["visible_count"]
near = [f["clovr"]["near_count"] for f in frames]
ok = all(f["clovr"] is not None for f in frames) and frames[-1]["clovr"]["done"] == 1
ok = ok and all(b >= a for a, b in zip(near, near[1:])) and near[0] < near[-1]
growing = [f for f in frames if not f["clovr"]["done"]]
final = [f for f in frames if f["clovr"]["done"]]
ok = ok and all(not f["clovr"]["exact"] and f["triangles_drawn"] == f["clovr"]["near_count"] and
                f["clovr"]["near_count"] + f["clovr"]["environment_count"] == count for f in growing)
ok = ok and len(final) > 0 and all(f["clovr"]["exact"] for f in final)
done = len(growing) if final else None
print("web-check-test: CloVR near region over %d frames: %s (of %d; complete at frame %s); "
      "ms per frame %s: %s" % (len(frames), near, count, done,
                               [round(f["ms"]) for f in frames[:12]], "pass" if ok else "FAIL"))
last = frames[-1]
a, b = (np.round(mi.imread(f)[:, :, :3] * 255) for f in (png, off_png))
differ = int((np.abs(a - b).max(axis=2) > 0).sum())
exact = (last["triangles_drawn"] + last["triangles_far"] + last["triangles_far_dynamic"] == count
         and all(last[k] == off[k] for k in ("triangles_drawn", "triangles_far",
                                              "triangles_far_dynamic"))
         and a.shape == b.shape and differ == 0)
print("web-check-test: CloVR complete: drawn %d + far %d + dynamic far %d = %d (PVS count %d); "
      "CloVR off: %d + %d + %d; %d pixels differ from the CloVR-off frame: %s"
      % (last["triangles_drawn"], last["triangles_far"], last["triangles_far_dynamic"],
         last["triangles_drawn"] + last["triangles_far"] + last["triangles_far_dynamic"], count,
         off["triangles_drawn"], off["triangles_far"], off["triangles_far_dynamic"], differ,
         "pass" if exact else "FAIL"))
sys.exit(0 if ok and exact else 1)
PY
# Prefetch (prefetch=0): on entering a cell the worker fetches each touching neighbour's block and
# its Delta chain (pvs_rt_delta_chain), so that walking into a neighbour waits for no request.
# West along the street from x = 80, then north: prefetching the neighbours' own blocks only, cell
# 43 (at 20,1.6,0) waits for 2 requests (its chain refers to cells not fetched yet).
set +e
PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$root/data/city.glb" "$work/city.pvs" --bare \
  --path "80,1.6,0;60,1.6,0;40,1.6,0;20,1.6,0;0,1.6,0;0,1.6,20;0,1.6,40;0,1.6,60;0,1.6,80;20,1.6,80" \
  --size 160x120 --prefetch 0 --json "$work/prefetch.json"
rc=$?
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (prefetch) exited $rc"; exit 1; }
python3 - "$work/prefetch.json" <<'PY'
import json, sys
frames = json.load(open(sys.argv[1]))["frames"]
entered = [f for p, f in zip(frames, frames[1:]) if f["cell"] != p["cell"] and f["cell"] >= 0]
waits = [f["frame_range_requests"] for f in entered]
chain = frames[-1]["prefetched_chain_blocks"]
ok = len(entered) >= 8 and all(w == 0 for w in waits) and chain > 0
print("web-check-test: prefetch: %d cells entered, range requests waited for on entering: %s; "
      "%d Delta chain blocks prefetched beyond the neighbours' own: %s"
      % (len(entered), waits, chain, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
# Dynamic far objects (Eq. 2 + the range test of Eq. 3) on Khronos' BoxAnimated (from ../shared;
# skipped when absent): eye and centre beside the boxes, every triangle far; the inner box moves
# (4 states), so its 57 triangles are displaced by Eq. 2 and, at rest inside the shell, all fail
# the range test, as in pvs view (shown 0). Without the range test the frame measures 26.7 dB.
box=$root/../shared/scenes/khronos_boxanimated/BoxAnimated.gltf
if [[ -f $box ]]; then
  "$pvs" bake "$box" --states 4 --cell-size 8 --box -4,-1,-4,4,1,4 --res 16 --runs 1 -q \
    -o "$work/box.pvs"
  "$pvs" view "$work/box.pvs" --scene "$box" --states 4 --at 3,0,0.3 --look 0,0.5,0 \
    --near-far 0.5,1.2 --centre 3,0,0 --env-size 256 --lookup eye --frame 320x240 -q \
    -o "$work/box/cpu.png" --json "$work/box/cpu.json"
  set +e
  WEB_STATES=4 PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$box" "$work/box.pvs" --bare \
    --path "3,0,0.3@0,0.5,0" --fov 90 --size 320x240 --near-far 0.5,1.2 --centre 3,0,0 \
    --env-size 256 --lookup eye --json "$work/box.json" --png "$work/box" --png-frames 0
  rc=$?
  set -e
  [[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (dynamic far) exited $rc"; exit 1; }
  /usr/bin/python3 - "$work/box/cpu.png" "$work/box/frame_0000.png" "$work/box/cpu.json" \
    "$work/box.json" <<'PY'
import json, sys
import matplotlib.image as mi
import numpy as np
a, b = (np.round(mi.imread(f)[:, :, :3] * 255) for f in sys.argv[1:3])
cpu = json.load(open(sys.argv[3]))["triangles"]
web = json.load(open(sys.argv[4]))["frames"][0]
mse = float(((a - b) ** 2).mean())
psnr = 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else float("inf")
ok = (a.shape == b.shape and psnr >= 38.0 and web["triangles_far_dynamic"] == cpu["far_dynamic_drawn"]
      and web["triangles_far"] == cpu["far"] - cpu["far_dynamic_drawn"] and cpu["far_dynamic_drawn"] > 0)
print("web-check-test: dynamic far: %d dynamic far triangles (pvs view %d), PSNR %.2f dB (>= 38): %s"
      % (web["triangles_far_dynamic"], cpu["far_dynamic_drawn"], psnr, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
else
  echo "web-check-test: dynamic far check skipped: $box absent"
fi
# Dynamic far objects that pass the range test: a static wall 20 m away and, 6.5-9.5 m away in
# front of it, a 3 m box whose node moves 2 m along x (a glTF written here; 4 states). Eye and
# centre at the origin, radii 2,5: the box's triangles are dynamic far, displaced by Eq. 2, and in
# front of the wall in the range map, so its fragments pass (pvs view: far_dynamic_shown > 0);
# the page's frame must show the box as pvs view's does (PSNR at least 38 dB, and over a thousand
# pixels of the box's colour).
mkdir -p "$work/wallbox"
python3 - "$work/wallbox/wallbox.gltf" <<'PY'
import base64, json, struct, sys
# A static wall (z = -20) behind a box (centre 0,1,-10) whose node moves 2 along x.
wall = [(-10, -1, -20), (10, -1, -20), (10, 6, -20), (-10, 6, -20)]
wall_idx = [0, 1, 2, 0, 2, 3]
box = [(x, y, z) for x in (-1.5, 1.5) for y in (0, 3) for z in (-9.5, -6.5)]
box_idx = [0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2,
           1, 3, 7, 1, 7, 5]
blob, views, accessors = b"", [], []
def add(data, fmt, count, type_, ctype, minmax=None):
    global blob
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    a = {"bufferView": len(views) - 1, "componentType": ctype, "count": count, "type": type_}
    if minmax: a["min"], a["max"] = minmax
    accessors.append(a)
    blob += data + b"\0" * (-len(data) % 4)
    return len(accessors) - 1
def positions(ps):
    lo = [min(p[k] for p in ps) for k in range(3)]; hi = [max(p[k] for p in ps) for k in range(3)]
    return add(struct.pack("<%df" % (3 * len(ps)), *[c for p in ps for c in p]), "", len(ps), "VEC3", 5126, (lo, hi))
def indices(ix):
    return add(struct.pack("<%dI" % len(ix), *ix), "", len(ix), "SCALAR", 5125)
meshes = [{"name": "wall", "primitives": [{"attributes": {"POSITION": positions(wall)}, "indices": indices(wall_idx)}]},
          {"name": "box", "primitives": [{"attributes": {"POSITION": positions(box)}, "indices": indices(box_idx)}]}]
times = add(struct.pack("<2f", 0, 1), "", 2, "SCALAR", 5126, ([0], [1]))
moves = add(struct.pack("<6f", 0, 0, 0, 2, 0, 0), "", 2, "VEC3", 5126)
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
     "nodes": [{"name": "wall", "mesh": 0}, {"name": "box", "mesh": 1, "translation": [0, 0, 0]}],
     "meshes": meshes, "accessors": accessors, "bufferViews": views,
     "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
     "animations": [{"channels": [{"sampler": 0, "target": {"node": 1, "path": "translation"}}],
                     "samplers": [{"input": times, "output": moves, "interpolation": "LINEAR"}]}]}
json.dump(g, open(sys.argv[1], "w"))
PY
"$pvs" bake "$work/wallbox/wallbox.gltf" --states 4 --cell-size 8 --box -4,0,-4,4,3,4 --res 16 \
  --runs 1 -q -o "$work/wallbox/wallbox.pvs"
"$pvs" view "$work/wallbox/wallbox.pvs" --scene "$work/wallbox/wallbox.gltf" --states 4 \
  --at 0,1.6,0 --look 0,1.6,-10 --near-far 2,5 --centre 0,1.6,0 --env-size 256 --lookup eye \
  --frame 320x240 -q -o "$work/wallbox/cpu.png" --json "$work/wallbox/cpu.json"
set +e
WEB_STATES=4 PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$work/wallbox/wallbox.gltf" \
  "$work/wallbox/wallbox.pvs" --bare --path "0,1.6,0@0,1.6,-10" --fov 90 --size 320x240 \
  --near-far 2,5 --centre 0,1.6,0 --env-size 256 --lookup eye --json "$work/wallbox/web.json" \
  --png "$work/wallbox/web" --png-frames 0
rc=$?
set -e
[[ $rc -eq 0 ]] || { echo "web-check-test: FAIL: web-check.sh (dynamic far shown) exited $rc"; exit 1; }
/usr/bin/python3 - "$work/wallbox/cpu.png" "$work/wallbox/web/frame_0000.png" \
  "$work/wallbox/cpu.json" "$work/wallbox/web.json" <<'PY'
import json, sys
import matplotlib.image as mi
import numpy as np
a, b = (np.round(mi.imread(f)[:, :, :3] * 255) for f in sys.argv[1:3])
cpu = json.load(open(sys.argv[3]))["triangles"]
web = json.load(open(sys.argv[4]))["frames"][0]
mse = float(((a - b) ** 2).mean())
psnr = 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else float("inf")
box = a[a.shape[0] // 2, a.shape[1] // 2]  # the frame's centre shows the box
shown = int((np.abs(b - box).max(axis=2) <= 8).sum())
ok = (a.shape == b.shape and psnr >= 38.0 and cpu["far_dynamic_shown"] > 0 and shown > 1000
      and web["triangles_far_dynamic"] == cpu["far_dynamic_drawn"])
print("web-check-test: dynamic far shown: %d dynamic far triangles (pvs view %d, %d of them shown), "
      "%d pixels of the box in the page's frame, PSNR %.2f dB (>= 38): %s"
      % (web["triangles_far_dynamic"], cpu["far_dynamic_drawn"], cpu["far_dynamic_shown"], shown,
         psnr, "pass" if ok else "FAIL"))
sys.exit(0 if ok else 1)
PY
