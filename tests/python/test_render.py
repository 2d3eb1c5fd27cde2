"""Frames and their metrics through pyvislib against `pvs inspect --render` (the same renderer and
metrics driven by the CLI) and against hand-checkable cases."""
import math

import numpy as np
import pytest

import pyvislib
from conftest import pvs_json

EYE = (5.0, 2.0, 5.0)


def test_cell_frames_metrics_equal_pvs_inspect_render(city, city_pvs, tmp_path):
    shown = pvs_json("inspect", city_pvs, "--at", "%r,%r,%r" % EYE, "--scene", city, "--render",
                     tmp_path / "views", "--frame", "160x120", "--json", "-q")
    scene = pyvislib.load_scene(str(city))
    pvs = pyvislib.Pvs(str(city_pvs))
    ids = pvs.visible_ids(pvs.find_cell(EYE))
    renderer = pyvislib.Renderer(scene, origin=EYE)  # inspect centres the BVH at the eye
    views = shown["render"]["views"]
    assert len(views) == 4
    for v in views:
        cam = dict(eye=EYE, forward=tuple(v["forward"]), width=160, height=120)
        q = pyvislib.frame_quality(renderer.render(**cam), renderer.render(**cam, visible=ids))
        assert q.missed_pixels == v["missed_pixels"]
        assert q.epsilon == v["epsilon"]
        assert q.ssim == pytest.approx(v["ssim"], rel=1e-12)
        if v["psnr"] is None:
            assert math.isinf(q.psnr)
        else:
            assert q.psnr == pytest.approx(v["psnr"], rel=1e-12)


def test_frame_against_itself_is_perfect_and_against_nothing_misses_every_hit(city, tmp_path):
    scene = pyvislib.load_scene(str(city))
    renderer = pyvislib.Renderer(scene)
    cam = dict(eye=EYE, forward=(1.0, -0.1, 0.3), width=96, height=64)
    full = renderer.render(**cam)
    assert full.rgb.shape == (64, 96, 3) and full.rgb.dtype == np.uint8
    png = tmp_path / "full.png"
    full.save(str(png))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    q = pyvislib.frame_quality(full, full)
    assert q.epsilon == 0 and math.isinf(q.psnr) and q.ssim == 1.0
    empty = renderer.render(**cam, visible=[])
    hit = full.triangles != pyvislib.NO_HIT
    assert hit.any() and not (empty.triangles != pyvislib.NO_HIT).any()
    mask = pyvislib.missed_pixels(full, empty)
    assert (mask == hit).all()
    q = pyvislib.frame_quality(full, empty)
    assert q.missed_pixels == int(hit.sum()) and q.epsilon == hit.mean()
    assert q.psnr == pytest.approx(pyvislib.psnr(full.rgb, empty.rgb), rel=0, abs=0)
    assert q.ssim == pytest.approx(pyvislib.ssim(full.rgb, empty.rgb), rel=0, abs=0)


def test_image_metrics_on_hand_computable_images():
    a = np.zeros((16, 16, 3), np.uint8)
    b = a.copy()
    b[0, 0] = (255, 255, 255)  # one pixel off by 255 in all channels: MSE = 255^2 / 256
    assert pyvislib.psnr(a, b) == pytest.approx(10 * math.log10(256), rel=1e-12)
    assert math.isinf(pyvislib.psnr(a, a))
    assert pyvislib.ssim(a, a) == 1.0 and pyvislib.ssim(a, a, whole_image=True) == 1.0
    # Whole-image SSIM of a constant image against another constant: luminance term only,
    # (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1) with mu_a = 0, mu_b = 100 (grey), C1 = (0.01*255)^2.
    c = np.full((16, 16, 3), 100, np.uint8)
    c1 = (0.01 * 255) ** 2
    assert pyvislib.ssim(a, c, whole_image=True) == pytest.approx(c1 / (100.0 ** 2 + c1), rel=1e-9)
    with pytest.raises(ValueError):
        pyvislib.psnr(a, np.zeros((8, 16, 3), np.uint8))


def test_compare_sets_counts_missed_and_extra():
    assert pyvislib.compare_sets([1, 2, 3, 7], [2, 3, 4]) == dict(size=4, reference_size=3, common=2,
                                                                   missed=1, extra=2)


def test_discontinuity_of_a_split_row_equals_the_hand_computed_values():
    # Truth positions 0, 1, 1.5, 2.5 of a 4 x 1 row, radius 1.2 (tests/discontinuity_test.cpp):
    # delta = 0, 0.5, 0.5, 0.
    xy = np.array([[[0, 0], [1, 0], [1.5, 0], [2.5, 0]]], dtype=float)
    d = pyvislib.discontinuity(xy, radius=1.2)
    assert d["delta"].shape == (1, 4)
    assert d["delta"].tolist() == [[0.0, 0.5, 0.5, 0.0]]
    assert d["mean"] == 0.25 and d["pixels"] == 4


def test_project_to_pixel_inverts_the_documented_pixel_rays_and_truth_has_zero_delta():
    # render.h: d = f + sx r + sy u, sx = ((2x+1)/W - 1) tan(vfov/2) W/H, sy = (1 - (2y+1)/H) tan.
    cam = dict(eye=EYE, forward=(1.0, -0.2, 0.4), up=(0.0, 1.0, 0.0))
    w, h = 48, 32
    fwd = np.array(cam["forward"]) / np.linalg.norm(cam["forward"])
    right = np.cross(fwd, cam["up"])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    t = np.tan(np.radians(45))
    xy = np.full((h, w, 2), np.nan)
    for y in range(0, h, 7):
        for x in range(0, w, 5):
            sx = ((2 * x + 1) / w - 1) * t * w / h
            sy = (1 - (2 * y + 1) / h) * t
            p = np.array(EYE) + 10 * (fwd + sx * right + sy * up)
            px = pyvislib.project_to_pixel(**cam, point=tuple(p), width=w, height=h)
            assert px == pytest.approx((x, y), abs=1e-9)
            xy[y, x] = px
    assert pyvislib.project_to_pixel(**cam, point=tuple(np.array(EYE) - fwd), width=w, height=h) is None
    d = pyvislib.discontinuity(xy, radius=8.0)  # the truth's own positions: delta 0
    assert d["pixels"] == 5 * 10 and abs(d["mean"]) < 1e-9
