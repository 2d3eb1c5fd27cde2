#!/usr/bin/env python3
"""quake_leaf_picture.py MAP.obj CELL.json COMPARE.json OUT.png: a top view of one BSP leaf's two
visible sets (docs/quake.md). MAP.obj is `pvs export MAP.bsp` (triangle i = face i of the OBJ),
CELL.json is `pvs inspect OURS.pvs --cell C --json` (our set and the leaf's box), COMPARE.json is
`pvs vis-compare MAP.bsp OURS.pvs --json` (its per-leaf row gives theirs minus ours and the
extras). Upward-facing triangles (floors, the top view's readable part) are drawn by height,
coloured: in both sets, drawn by the engine only (theirs, hidden from the whole leaf by ours), in
ours only (extras), in neither; the leaf's box is outlined. Counts in the title are of all
triangles, not only floors."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Patch, Rectangle  # noqa: E402

from doc_images import finish, read_obj  # noqa: E402

# Colours of the classes, in drawing legend order.
CLASSES = (("both", "tab:red"), ("theirs only", "orange"), ("ours only", "tab:blue"), ("neither", "0.82"))


def up_facing(v, t):
    a, b, c = (v[i] for i in t)
    e1 = [b[k] - a[k] for k in range(3)]
    e2 = [c[k] - a[k] for k in range(3)]
    n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
    length = sum(x * x for x in n) ** 0.5
    return length > 0 and n[1] / length > 0.5


def main(obj, cell_json, compare_json, out):
    v, f = read_obj(obj)
    cell = json.load(open(cell_json))
    rows = [r for r in json.load(open(compare_json))["per_leaf"] if r["cell"] == cell["cell"]]
    if not rows:
        sys.exit("quake_leaf_picture.py: %s has no row for cell %d" % (compare_json, cell["cell"]))
    row = rows[0]
    ours = set(cell["visible"])
    extras = set()
    for key in ("extras_confirmed", "extras_unconfirmed", "extras_coincident"):
        for e in row.get(key, []):
            extras.add(e["tri"] if isinstance(e, dict) else e)
    theirs_only = set(row["ours_lacks"])
    cls = {}
    for i in range(len(f)):
        if i in theirs_only:
            cls[i] = "theirs only"
        elif i in extras:
            cls[i] = "ours only"
        elif i in ours:
            cls[i] = "both"
        else:
            cls[i] = "neither"
    floors = sorted((i for i in range(len(f)) if up_facing(v, f[i])), key=lambda i: max(v[k][1] for k in f[i]))
    colour = dict(CLASSES)
    polys = [[(v[k][0], v[k][2]) for k in f[i]] for i in floors]
    fig, ax = plt.subplots(figsize=(6.4, 5.0), dpi=90)
    ax.add_collection(PolyCollection(polys, facecolors=[colour[cls[i]] for i in floors], edgecolors="0.5",
                                     linewidths=0.15))
    b = cell["box"]
    ax.add_patch(Rectangle((b["min"][0], b["min"][2]), b["max"][0] - b["min"][0], b["max"][2] - b["min"][2],
                           fill=False, edgecolor="k", lw=1.4))
    ax.legend(handles=[Patch(color=c, label=n) for n, c in CLASSES], fontsize=7, loc="lower right")
    ax.set_title("leaf %d (cell %d, box outlined): ours %d, theirs %d, both %d, theirs only %d, ours only %d\n"
                 "(triangle counts of all faces; floors drawn, from above)"
                 % (row["leaf"], row["cell"], row["ours"], row["theirs"], row["common"], len(theirs_only),
                    len(extras)), fontsize=8)
    finish(ax, polys, unit="Quake units")
    fig.savefig(out, bbox_inches="tight")
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    main(*sys.argv[1:])
