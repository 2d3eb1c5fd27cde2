#!/usr/bin/env bash
# Headless test of what the web client shows a person (ctest web_look): on a glTF written here
# (two walls 10 m in front of the eye: one with a red/blue checker base colour texture, one with a
# green base colour factor), baked small:
#  - the overlays at 640 x 400 and 1280 x 720 stay inside their corners, overlap nothing and
#    clip no text (getBoundingClientRect in chromium: web_check.mjs's `layout`), and key H hides
#    them and shows them again;
#  - the default shading draws the scene's own materials: the checker's red and its blue on the
#    first wall, green on the second, one texture decoded; shading=reference (what the frame
#    comparisons use) draws the first wall in one hue, as the CPU renderer does;
#  - with near-far on (both walls beyond r2, in the environment map, 32 x 32 faces), the default
#    shading reads the colour map filtered: the green wall's top edge against the sky blends over
#    several pixels per column, where shading=reference (nearest texel, as pvs view) steps.
# Usage: web-look-test.sh PVS_EXE WORKDIR. Exit 0 pass, 1 fail, 2 missing build, 77 chromium
# cannot start. Time budget: about 40 s on 2 cores (six page loads, a bake of one cell).
set -euo pipefail
pvs=$1 work=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
start=$(date +%s)
python3 - "$work/walls.gltf" <<'PY'
import base64, json, struct, sys, zlib
def png(w, h, rows):  # 8-bit RGB, no filter
    raw = b"".join(b"\0" + bytes(c for px in row for c in px) for row in rows)
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
red, blue = (230, 20, 20), (20, 20, 230)
image = png(2, 2, [[red, blue], [blue, red]])
arrays = []  # (packed bytes, glTF type, component type, count, min, max): accessor i = arrays[i]
def quad(x0, x1):  # the wall x0..x1, y 0..4, at z = -10, facing the eye; UV (0,0) top left
    ps = [(x0, 0, -10), (x1, 0, -10), (x1, 4, -10), (x0, 4, -10)]
    uv = [(0, 1), (1, 1), (1, 0), (0, 0)]
    arrays.append((struct.pack("<12f", *sum(ps, ())), "VEC3", 5126, 4,
                   [min(p[k] for p in ps) for k in range(3)], [max(p[k] for p in ps) for k in range(3)]))
    arrays.append((struct.pack("<8f", *sum(uv, ())), "VEC2", 5126, 4, None, None))
    arrays.append((struct.pack("<6I", 0, 1, 2, 0, 2, 3), "SCALAR", 5125, 6, None, None))
    n = len(arrays)
    return {"attributes": {"POSITION": n - 3, "TEXCOORD_0": n - 2}, "indices": n - 1}
meshes = [{"name": "checker", "primitives": [dict(quad(-4, 0), material=0)]},
          {"name": "green", "primitives": [dict(quad(0, 4), material=1)]}]
g = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
     "nodes": [{"name": "checker", "mesh": 0}, {"name": "green", "mesh": 1}],
     "meshes": meshes,
     "materials": [{"name": "checker", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}},
                   {"name": "green", "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.6, 0.05, 1]}}],
     "textures": [{"source": 0}],
     "images": [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}]}
blob, g["bufferViews"], g["accessors"] = b"", [], []
for i, (data, type_, ctype, count, lo, hi) in enumerate(arrays):
    g["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
    g["accessors"].append(dict({"bufferView": i, "componentType": ctype, "count": count, "type": type_},
                               **({"min": lo, "max": hi} if lo else {})))
    blob += data
g["buffers"] = [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}]
json.dump(g, open(sys.argv[1], "w"))
PY
"$pvs" bake "$work/walls.gltf" --cell-size 8 --box -4,0,-4,4,3,4 --res 16 --runs 1 -q \
  -o "$work/walls.pvs"
echo "web-look-test: scene and bake ($(($(date +%s) - start)) s)"
look() {  # NAME SIZE [web-check.sh options...]
  local name=$1 size=$2
  shift 2
  set +e
  PVS_EXE=$pvs bash "$root/scripts/web-check.sh" "$work/walls.gltf" "$work/walls.pvs" \
    --path "0,1.6,0@0,1.6,-10" --fov 90 --size "$size" --json "$work/$name.json" \
    --png "$work/$name" --png-frames 0 "$@"
  local rc=$?
  set -e
  [[ $rc -eq 77 ]] && { echo "web-look-test: SKIPPED: chromium cannot start"; exit 77; }
  [[ $rc -eq 0 ]] || { echo "web-look-test: FAIL: web-check.sh ($name) exited $rc"; exit 1; }
}
look overlay_640 640x400 --shading materials
look overlay_1280 1280x720 --shading materials
look materials 320x240 --bare --shading materials
look reference 320x240 --bare --shading reference
look far_materials 320x240 --bare --shading materials --near-far 2,5 --centre 0,1.6,0 --env-size 32
look far_reference 320x240 --bare --shading reference --near-far 2,5 --centre 0,1.6,0 --env-size 32
/usr/bin/python3 - "$work" <<'PY'
import json, sys
import matplotlib.image as mi
import numpy as np
work = sys.argv[1]
ok = True
def report(good, text):
    global ok
    ok = ok and good
    print("web-look-test: %s: %s" % (text, "pass" if good else "FAIL"))
for name in ("overlay_640", "overlay_1280"):
    lay = json.load(open("%s/%s.json" % (work, name)))["layout"]
    good = (lay is not None and not lay["problems"] and set(lay["boxes"]) == {"overlay", "map", "help"}
            and lay["hidden_by_h"] and lay["shown_again_by_h"])
    boxes = {k: [round(v[s]) for s in ("left", "top", "right", "bottom")] for k, v in lay["boxes"].items()}
    report(good, "overlays at %dx%d: %s; problems %s; H hides %s, shows again %s"
           % (*lay["viewport"], boxes, lay["problems"], lay["hidden_by_h"], lay["shown_again_by_h"]))
img = lambda n: np.round(mi.imread("%s/%s/frame_0000.png" % (work, n))[:, :, :3] * 255).astype(int)
# The walls: rows 91-139, columns 112-160 (checker) and 160-208 (green) at 320 x 240, 90 degrees.
m, r = img("materials"), img("reference")
checker, green = m[100:130, 115:157].reshape(-1, 3), m[100:130, 163:205].reshape(-1, 3)
reds = int(((checker[:, 0] > 150) & (checker[:, 2] < 80)).sum())
blues = int(((checker[:, 2] > 150) & (checker[:, 0] < 80)).sum())
greens = float(((green[:, 1] > green[:, 0] + 60) & (green[:, 1] > green[:, 2] + 60)).mean())
textures = json.load(open("%s/materials.json" % work))["frames"][0]["textures"]
report(reds > 100 and blues > 100 and greens > 0.95 and textures == 1,
       "materials: the checker wall shows %d red and %d blue pixels (> 100 each), %.0f%% of the "
       "green wall is green (> 95%%), %d texture decoded (1)" % (reds, blues, 100 * greens, textures))
flat = r[100:130, 115:157].reshape(-1, 3)
spread = int((flat.max(axis=0) - flat.min(axis=0)).max())
report(spread < 30, "reference: the checker wall in one hue, channels spread over %d steps (< 30)"
       % spread)
# The green wall's top edge (row 91) against the sky, columns 165-204: pixels of rows 70-110 far
# (more than 12 steps in some channel) from both the sky (row 20) and the wall (row 125).
def blended(n):
    a = img(n)
    count = 0
    for x in range(165, 205):
        sky, wall = a[20, x], a[125, x]
        col = a[70:110, x]
        far = lambda c: np.abs(col - c).max(axis=1) > 12
        count += int((far(sky) & far(wall)).sum())
    return count / 40.0
fm, fr = blended("far_materials"), blended("far_reference")
report(fm >= 2 and fr == 0, "near-far, the far wall's top edge: %.1f blended pixels per column with "
       "the default shading (>= 2: filtered), %.1f with shading=reference (0: nearest texel)"
       % (fm, fr))
sys.exit(0 if ok else 1)
PY
echo "web-look-test: done in $(($(date +%s) - start)) s"
