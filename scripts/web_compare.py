#!/usr/bin/python3
"""Compares the web client's frames with the CPU reference renderer's, pixel by pixel.

Usage: web_compare.py CPU_DIR WEB_DIR   (CPU_DIR: pvs inspect --render's view{0..3}_pvs.png;
WEB_DIR: web-check.sh --bare's frame_000{0..3}.png of the same eye, looking +x, +z, -x, -z, at
--fov 90 and the same size). Passes when every view has a PSNR of at least MIN_PSNR_DB and at
most MAX_EDGE_SHARE of its pixels differ by more than EDGE_STEPS 8-bit steps in a channel: the
shading model is the same (docs/web.md, "Shading"), so what differs is rasterisation coverage
on triangle edges (ray through the pixel centre against WebGL's coverage rule) and one rounding
step. Debian's python3 with numpy and matplotlib (scripts/install-deps.sh).
"""
import sys

import matplotlib.image as mi
import numpy as np

MIN_PSNR_DB = 40.0     # measured 44-55 dB on the city's centre crossing at 320 x 240
EDGE_STEPS = 8         # a difference above this is a different triangle or the background
MAX_EDGE_SHARE = 0.005  # measured 0.01-0.02 % of the pixels


def main():
    cpu, web = sys.argv[1:3]
    ok = True
    for k in range(4):
        a = np.round(mi.imread("%s/view%d_pvs.png" % (cpu, k))[:, :, :3] * 255)
        b = np.round(mi.imread("%s/frame_%04d.png" % (web, k))[:, :, :3] * 255)
        if a.shape != b.shape:
            print("web-compare: view %d: sizes %s and %s differ" % (k, a.shape, b.shape))
            return 1
        mse = float(((a - b) ** 2).mean())
        psnr = 10 * np.log10(255.0 ** 2 / mse) if mse > 0 else float("inf")
        edge = float((np.abs(a - b).max(axis=2) > EDGE_STEPS).mean())
        good = psnr >= MIN_PSNR_DB and edge <= MAX_EDGE_SHARE
        ok = ok and good
        print("web-compare: view %d: PSNR %.2f dB (>= %.0f), %.3f%% of pixels differ by more than "
              "%d steps (<= %.1f%%)%s" % (k, psnr, MIN_PSNR_DB, 100 * edge, EDGE_STEPS,
                                          100 * MAX_EDGE_SHARE, "" if good else ": FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
