#!/usr/bin/env python3
"""doc_images.py WORK OUT: the top views and the frame strip of docs/img/ from the files that
scripts/make-doc-images.sh leaves in WORK (city.obj from `pvs export`, city.pvs (its cell boxes),
summary.json from `pvs inspect --json`, at.json and render/ from `pvs inspect --render`, view.json
and the frames it names from `pvs view`)."""
import json
import os
import struct
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402


def read_obj(path):
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                x, y, z = map(float, line.split()[1:4])
                v.append((x, y, z))
            elif line.startswith("f "):
                f.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
    return v, f


def cell_boxes(path):
    """The (min, max) boxes of a box-list PVS file, read as docs/pvs-format.md specifies: u32
    cell_count at byte 36, u8 layout at 41 (1 = box list), then from byte 64 f64[3] min, f64[3]
    max per cell (the box is the cell's view region)."""
    with open(path, "rb") as fh:
        data = fh.read()
    if data[:8] != b"\x89PVS\r\n\x1a\n" or data[41] != 1:
        sys.exit("doc_images.py: %s is not a box-list PVS file (walkable cells)" % path)
    (n,) = struct.unpack_from("<I", data, 36)
    boxes = []
    for c in range(n):
        v = struct.unpack_from("<6d", data, 64 + 48 * c)
        boxes.append((v[:3], v[3:]))
    return boxes


def top_shades(v, f):
    """Grey levels of top_polys(v, f), in its order: streets light, the higher the darker."""
    tops = sorted(max(v[i][1] for i in t) for t in f)
    lo, hi = tops[0], tops[-1]
    return [str(0.9 - 0.45 * (h - lo) / max(1e-9, hi - lo)) for h in tops]


def top_polys(v, f, ids=None):
    """Triangles seen from above (x right, z down), highest last so roofs cover streets."""
    tris = f if ids is None else [f[i] for i in ids]
    tris = sorted(tris, key=lambda t: max(v[i][1] for i in t))
    return [[(v[i][0], v[i][2]) for i in t] for t in tris]


def main(work, out):
    v, f = read_obj(os.path.join(work, "city.obj"))
    summary = json.load(open(os.path.join(work, "summary.json")))
    n = summary["cells"]
    counts = summary["per_cell"]["visible"]
    boxes = cell_boxes(os.path.join(work, "city.pvs"))
    if len(boxes) != n:
        sys.exit("doc_images.py: city.pvs has %d cells, its summary %d" % (len(boxes), n))
    at = json.load(open(os.path.join(work, "at.json")))
    all_polys = top_polys(v, f)
    shades = top_shades(v, f)

    # 1. cells coloured by PVS size over the scene's top view.
    fig, ax = plt.subplots(figsize=(5.2, 4.4), dpi=90)
    ax.add_collection(PolyCollection(all_polys, facecolors=shades, edgecolors="none"))
    cmap = plt.get_cmap("viridis")
    lo, hi = min(counts), max(counts)
    for c, (bmin, bmax) in enumerate(boxes):
        x0, z0, x1, z1 = bmin[0], bmin[2], bmax[0], bmax[2]
        t = (counts[c] - lo) / max(1, hi - lo)
        ax.add_patch(Rectangle((x0, z0), x1 - x0, z1 - z0, facecolor=cmap(t), alpha=0.75, edgecolor="k", lw=0.3))
    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(lo, hi))
    fig.colorbar(sm, ax=ax, label="visible triangles of the cell")
    ax.set_title("%d walkable cells of data/city.glb (24 m), by PVS size" % n, fontsize=9)
    finish(ax, all_polys)
    fig.savefig(os.path.join(out, "cells_top.png"), bbox_inches="tight")
    plt.close(fig)

    # 2. one cell's visible set against the full scene.
    fig, ax = plt.subplots(figsize=(4.6, 4.4), dpi=90)
    ax.add_collection(PolyCollection(all_polys, facecolors=shades, edgecolors="none"))
    ax.add_collection(PolyCollection(top_polys(v, f, at["visible"]), facecolors="tab:red", edgecolors="none"))
    b = at["view_region"]
    ax.add_patch(Rectangle((b["min"][0], b["min"][2]), b["max"][0] - b["min"][0], b["max"][2] - b["min"][2],
                           fill=False, edgecolor="k", lw=1.2))
    ax.set_title("cell %d: %d of %d triangles visible (red)" % (at["cell"], at["visible_count"], len(f)), fontsize=9)
    finish(ax, all_polys)
    fig.savefig(os.path.join(out, "cell_set.png"), bbox_inches="tight")
    plt.close(fig)

    # 3. full-scene frame | PVS frame | error heat map, from the cell.
    view = at["render"]["views"][0]
    fig, axes = plt.subplots(1, 3, figsize=(9, 2.5), dpi=90)
    for a, key, title in zip(axes, ("full", "pvs", "heat_map"), ("full scene", "cell's PVS", "error heat map")):
        a.imshow(mpimg.imread(view[key]))
        a.set_title(title, fontsize=9)
        a.axis("off")
    fig.suptitle("from %s looking %s: epsilon %.3g, SSIM %.4f" % (view["eye"], view["forward"], view["epsilon"],
                                                                   view["ssim"]), fontsize=9)
    fig.savefig(os.path.join(out, "cell_frames.png"), bbox_inches="tight")
    plt.close(fig)

    # 4. the near-far frame of the cell (pvs view): near-far | without morph | full scene | heat map.
    nf = json.load(open(os.path.join(work, "view.json")))
    im = nf["images"]
    fig, axes = plt.subplots(1, 4, figsize=(12, 2.5), dpi=90)
    panels = (
        ("near_far", "near-far frame\nepsilon %.3g, SSIM %.3f" % (nf["epsilon"], nf["ssim"])),
        ("nomorph", "without morph\nepsilon %.3g, SSIM %.3f" % (nf["without_morph"]["epsilon"], nf["without_morph"]["ssim"])),
        ("truth", "full scene\n"),
        ("heat_map", "error heat map\n(near-far frame)"),
    )
    for a, (key, title) in zip(axes, panels):
        a.imshow(mpimg.imread(im[key]))
        a.set_title(title, fontsize=9)
        a.axis("off")
    t = nf["triangles"]
    fig.suptitle("cell %d, r1 %.1f m, r2 %.1f m: near %d, intermediate %d, far %d of %d visible triangles"
                 % (nf["cell"], nf["r1"], nf["r2"], t["near"], t["intermediate"], t["far"], t["visible"]), fontsize=9)
    fig.savefig(os.path.join(out, "near_far.png"), bbox_inches="tight")
    plt.close(fig)


def finish(ax, polys, unit="m"):
    xs = [p[0] for poly in polys for p in poly]
    zs = [p[1] for poly in polys for p in poly]
    ax.set_xlim(min(xs), max(xs))
    ax.set_ylim(max(zs), min(zs))
    ax.set_aspect("equal")
    ax.set_xlabel("x (%s)" % unit)
    ax.set_ylabel("z (%s)" % unit)
    ax.tick_params(labelsize=7)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
