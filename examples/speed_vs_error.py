#!/usr/bin/env python3
"""Speed against error of from-segment visibility as the cubemap resolution N varies (docs/python.md).

For one view segment of a scene, runs pyvislib.segment_visibility at each N and reports its kernel
time and two errors against a high-resolution reference:
  - missed triangles: triangles of the reference set that the set at N lacks (compare_sets);
  - pixel error epsilon: the share of pixels of full-scene frames, from points spread along the
    segment in four horizontal directions, that the set at N misses (frame_quality), in percent.
The set at the reference N itself is the last row (0 missed by definition; its epsilon is the
reference's own error against the full scene).

Run from the repository root after building (the module is in build/python):
    PYTHONPATH=build/python python3 examples/speed_vs_error.py
"""
import argparse
import statistics
import time

import pyvislib


def parse_vec(text):
    v = tuple(float(x) for x in text.split(","))
    if len(v) != 3:
        raise argparse.ArgumentTypeError("expected x,y,z")
    return v


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="data/city.glb")
    ap.add_argument("--from", dest="from_", type=parse_vec, default=(-60.0, 1.7, 0.0),
                    help="segment start x,y,z (default: along the street z = 0 of data/city.glb; write "
                         "--from=-1,2,3 when the first coordinate is negative)")
    ap.add_argument("--to", type=parse_vec, default=(60.0, 1.7, 0.0))
    ap.add_argument("--res", default="16,32,64,128,256", help="resolutions N to time, comma-separated")
    ap.add_argument("--ref", type=int, default=1024, help="reference resolution")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per N (the median is reported)")
    ap.add_argument("--views", type=int, default=5, help="points along the segment for epsilon")
    ap.add_argument("--frame", default="320x240", help="frame size WxH for epsilon")
    ap.add_argument("--threads", type=int, default=0, help="worker threads (0 = all cores)")
    a = ap.parse_args()

    scene = pyvislib.load_scene(a.scene)
    print(f"# {a.scene}: {scene.triangle_count} triangles; segment {a.from_} -> {a.to}; "
          f"reference N = {a.ref}; threads = {a.threads or 'all'}")
    t0 = time.perf_counter()
    ref = pyvislib.segment_visibility(scene, a.from_, a.to, resolution=a.ref, threads=a.threads)
    print(f"# reference: {len(ref.visible)} visible triangles, kernel {ref.seconds:.3f} s "
          f"(wall {time.perf_counter() - t0:.3f} s)")

    w, h = (int(x) for x in a.frame.split("x"))
    renderer = pyvislib.Renderer(scene)
    cams, truths = [], []
    for i in range(a.views):
        t = (i + 0.5) / a.views
        eye = tuple(p + t * (q - p) for p, q in zip(a.from_, a.to))
        for fwd in ((1, 0, 0), (0, 0, 1), (-1, 0, 0), (0, 0, -1)):
            cam = dict(eye=eye, forward=fwd, width=w, height=h, threads=a.threads)
            cams.append(cam)
            truths.append(renderer.render(**cam))

    def epsilon_percent(visible):
        ids = visible.tolist()
        missed = sum(pyvislib.frame_quality(tr, renderer.render(**c, visible=ids)).missed_pixels
                     for c, tr in zip(cams, truths))
        return 100.0 * missed / sum(tr.width * tr.height for tr in truths)

    print("| N | kernel s (median of %d) | visible | missed vs ref | extra vs ref | epsilon %% |" % a.repeat)
    print("|---:|---:|---:|---:|---:|---:|")
    for n in [int(x) for x in a.res.split(",")] + [a.ref]:
        runs = [pyvislib.segment_visibility(scene, a.from_, a.to, resolution=n, threads=a.threads)
                for _ in range(a.repeat if n != a.ref else 1)]
        secs = statistics.median(r.seconds for r in runs) if n != a.ref else ref.seconds
        c = pyvislib.compare_sets(runs[0].visible, ref.visible)
        print(f"| {n} | {secs:.3f} | {c['size']} | {c['missed']} | {c['extra']} | "
              f"{epsilon_percent(runs[0].visible):.4f} |", flush=True)


if __name__ == "__main__":
    main()
