#!/usr/bin/env python3
"""The pictures of docs/ods.md from `pvs view --ods` outputs (needs numpy and matplotlib).

  scripts/ods_plots.py PAIR.png MERGE_NONE.json MERGE_A.json [MERGE_B.json ...] OUT_DIR

PAIR.png: a top-bottom ODS pair (`pvs view --ods -o PAIR.png`), downscaled 2x into
OUT_DIR/ods_pair.png. MERGE_*.json: `pvs view --ods --json` runs of one scene and eye with different
--pole-merge settings; OUT_DIR/ods_pole_merge.png plots Eq. 6's factor over latitude for each setting
(left) and the measured left/right triangle disagreement per 5 degree latitude band (right).
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def factor(lat, side):
    """Eq. 6 as runtime/ods.h defines it (start = end: no merging)."""
    start, end, exp = side["start_deg"], side["end_deg"], side["exponent"]
    if start == end:
        return np.ones_like(lat)
    ms, me = 90.0 - start, 90.0 - end
    x = np.clip((np.abs(lat) - ms) / (me - ms), 0.0, 1.0)
    return (1.0 - x) ** exp


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    pair, runs, out = sys.argv[1], sys.argv[2:-1], sys.argv[-1]
    img = mpimg.imread(pair)[:, :, :3]
    h, w = img.shape[0] // 2 * 2, img.shape[1] // 2 * 2
    small = img[:h, :w].reshape(h // 2, 2, w // 2, 2, 3).mean(axis=(1, 3))
    mpimg.imsave(f"{out}/ods_pair.png", small)

    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.4), dpi=90)
    lat = np.linspace(-90, 90, 721)
    for path in runs:
        j = json.load(open(path))["ods"]
        pm = j["pole_merge"]
        t, bt = pm["top"], pm["bottom"]
        label = "none" if t["start_deg"] == t["end_deg"] else f"{t['start_deg']:g},{t['end_deg']:g},{t['exponent']:g}"
        f = np.where(lat >= 0, factor(lat, t), factor(lat, bt))
        a.plot(lat, f, label=label)
        bands = j["lr_disagreement_by_latitude"]
        mid = [(x["lat_max"] + x["lat_min"]) / 2 for x in bands]
        b.plot(mid, [x["triangle_mismatch"] for x in bands], marker=".", label=label)
    a.set_xlabel("latitude (deg)")
    a.set_ylabel("IPD factor a (Eq. 6)")
    a.set_title("pole merging factor")
    a.legend(fontsize=8)
    b.set_xlabel("latitude band centre (deg)")
    b.set_ylabel("left/right triangle disagreement")
    b.set_title("measured (pvs view --ods)")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{out}/ods_pole_merge.png")


if __name__ == "__main__":
    main()
