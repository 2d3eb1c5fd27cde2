#!/usr/bin/python3
"""Compares two images of the same size, whole or in equal tiles, with the metrics of
vislib/eval/metrics.h: PSNR over RGB, SSIM of the luminance (Rec. 601, 11 x 11 Gaussian window,
sigma 1.5, K1 0.01, K2 0.03, "valid" positions only), and the share of pixels that differ by
more than EDGE_STEPS 8-bit steps in some channel (another triangle or the background there).

Usage: web_image_compare.py A.png B.png [--tiles RxC] [--crop-a x,y,w,h] [--crop-b x,y,w,h]
                            [--names n1,n2,...] [--min-psnr DB] [--max-diff SHARE] [--json OUT]
--tiles 2x1 splits a top-bottom ODS pair into its eyes (row-major tile order, named by --names);
--crop-* cut a region of either image first. Prints one line a tile; exit 1 when a tile is below
--min-psnr or above --max-diff, 2 on bad input. Debian's python3 with numpy and matplotlib.
"""
import argparse
import json
import os
import sys

import matplotlib.image as mi
import numpy as np

EDGE_STEPS = 8  # scripts/web_compare.py's: above this a pixel shows another surface
SSIM_WINDOW, SSIM_SIGMA, SSIM_K1, SSIM_K2 = 11, 1.5, 0.01, 0.03  # metrics.h


def load(path, crop):
    try:
        img = mi.imread(path)
    except (OSError, ValueError) as e:
        raise SystemExit("web-image-compare: %s: %s" % (path, e))
    if img.dtype != np.uint8:
        img = np.round(img * 255)
    img = img[:, :, :3].astype(np.float64)
    if crop:
        x, y, w, h = crop
        if y + h > img.shape[0] or x + w > img.shape[1]:
            raise SystemExit("web-image-compare: %s: crop %s outside %dx%d" % (path, crop, img.shape[1], img.shape[0]))
        img = img[y:y + h, x:x + w]
    return img


def gaussian():
    k = np.arange(SSIM_WINDOW) - (SSIM_WINDOW - 1) / 2
    g = np.exp(-(k * k) / (2 * SSIM_SIGMA * SSIM_SIGMA))
    return g / g.sum()


def filt(img, g):
    """Valid separable filtering with the 1D kernel g along both axes."""
    h = sum(g[k] * img[:, k:img.shape[1] - len(g) + 1 + k] for k in range(len(g)))
    return sum(g[k] * h[k:h.shape[0] - len(g) + 1 + k, :] for k in range(len(g)))


def ssim(a, b):
    lum = np.array([0.299, 0.587, 0.114])
    x, y = a @ lum, b @ lum
    if np.array_equal(x, y):
        return 1.0
    g = gaussian()
    mx, my = filt(x, g), filt(y, g)
    sxx, syy, sxy = filt(x * x, g) - mx * mx, filt(y * y, g) - my * my, filt(x * y, g) - mx * my
    c1, c2 = (SSIM_K1 * 255) ** 2, (SSIM_K2 * 255) ** 2
    m = ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2))
    return float(m.mean())


def metrics(a, b):
    mse = float(((a - b) ** 2).mean())
    return {"psnr": 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else None,
            "ssim": ssim(a, b),
            "diff_share": float((np.abs(a - b).max(axis=2) > EDGE_STEPS).mean())}


def ints(text, n, what):
    v = [int(t) for t in text.split(",")] if text else None
    if v is not None and (len(v) != n or min(v) < 0):
        raise SystemExit("web-image-compare: %s %s: %d non-negative integers" % (what, text, n))
    return v


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("a")
    p.add_argument("b")
    p.add_argument("--tiles", default="1x1")
    p.add_argument("--crop-a")
    p.add_argument("--crop-b")
    p.add_argument("--names")
    p.add_argument("--min-psnr", type=float)
    p.add_argument("--max-diff", type=float)
    p.add_argument("--json")
    o = p.parse_args()
    rows, cols = (int(t) for t in o.tiles.split("x"))
    a, b = load(o.a, ints(o.crop_a, 4, "--crop-a")), load(o.b, ints(o.crop_b, 4, "--crop-b"))
    if a.shape != b.shape:
        print("web-image-compare: sizes %s and %s differ" % (a.shape, b.shape), file=sys.stderr)
        return 2
    th, tw = a.shape[0] // rows, a.shape[1] // cols
    names = o.names.split(",") if o.names else ["tile%d" % k for k in range(rows * cols)]
    out, ok = {}, True
    for k in range(rows * cols):
        r, c = divmod(k, cols)
        m = metrics(a[r * th:(r + 1) * th, c * tw:(c + 1) * tw], b[r * th:(r + 1) * th, c * tw:(c + 1) * tw])
        good = (o.min_psnr is None or (m["psnr"] is None or m["psnr"] >= o.min_psnr)) and \
               (o.max_diff is None or m["diff_share"] <= o.max_diff)
        ok = ok and good
        out[names[k]] = m
        print("web-image-compare: %s: PSNR %s dB, SSIM %.4f, %.3f%% of pixels off by more than %d steps%s" % (
            names[k], "inf" if m["psnr"] is None else "%.2f" % m["psnr"], m["ssim"], 100 * m["diff_share"],
            EDGE_STEPS, "" if good else ": FAIL"))
    if o.json:
        with open(o.json + ".tmp", "w") as f:
            json.dump(out, f, indent=1)
        os.replace(o.json + ".tmp", o.json)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
