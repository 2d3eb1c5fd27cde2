"""Segment and region visibility through pyvislib against `pvs segment/region --json` and against
Embree ray casts through the kernel's pixel centres (the renderer, an independent path)."""
import json

import numpy as np
import pytest

import pyvislib
from conftest import run_pvs

FROM, TO = (-35.0, 1.7, -33.0), (30.0, 1.7, -33.0)  # along a street of the generated city


def test_segment_visible_ids_equal_cli_segment_json(city, tmp_path):
    scene = pyvislib.load_scene(str(city))
    r = pyvislib.segment_visibility(scene, FROM, TO, resolution=64)
    out = tmp_path / "seg.json"
    run_pvs("segment", city, "--from", "%r,%r,%r" % FROM, "--to", "%r,%r,%r" % TO, "--res", 64, "-q",
             "--json", out)

    cli = json.loads(out.read_text())
    assert r.visible.dtype == np.uint32
    assert r.visible.tolist() == cli["visible"]
    assert 0 < len(r.visible) < scene.triangle_count
    assert r.stats["triangle_pixel_pairs"] == cli["counts"]["triangle_pixel_pairs"]
    # A second call reuses the runs of collinear edges the scene built on the first: same set.
    again = pyvislib.segment_visibility(scene, FROM, TO, resolution=64)
    assert again.visible.tolist() == cli["visible"]


def test_segment_options_reach_the_kernel(city, tmp_path):
    scene = pyvislib.load_scene(str(city))
    out = tmp_path / "seg.json"
    run_pvs("segment", city, "--from", "%r,%r,%r" % FROM, "--to", "%r,%r,%r" % TO, "--res", 16,
             "--near", 0.5, "--coplanar", "first", "-q", "--json", out)

    cli = json.loads(out.read_text())
    r = pyvislib.segment_visibility(scene, FROM, TO, resolution=16, near=0.5, coplanar="first")
    assert r.visible.tolist() == cli["visible"]
    # A lower resolution sees no more than it must: the N = 16 set differs from the N = 64 one.
    r64 = pyvislib.segment_visibility(scene, FROM, TO, resolution=64)
    assert r.visible.tolist() != r64.visible.tolist()


def test_segment_result_does_not_depend_on_threads(city):
    scene = pyvislib.load_scene(str(city))
    one = pyvislib.segment_visibility(scene, FROM, TO, resolution=48, threads=1)
    two = pyvislib.segment_visibility(scene, FROM, TO, resolution=48, threads=2)
    assert one.visible.tolist() == two.visible.tolist()


def cube_views(eye, n):
    """The six 90-degree N x N cameras from `eye`: their pixel centres are the directions of the
    kernel's world-aligned cubemap pixels (the set of a face's centres is symmetric under flips)."""
    faces = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 0, 1), (0, 1, 0)),
             ((0, 0, -1), (0, 1, 0)), ((0, 1, 0), (0, 0, 1)), ((0, -1, 0), (0, 0, 1))]
    return [dict(eye=eye, forward=f, up=u, vfov_degrees=90.0, width=n, height=n) for f, u in faces]


def test_segment_set_holds_every_triangle_ray_casts_hit_along_the_segment(city):
    """Nothing missed: at points of the segment, every triangle an Embree ray through a cubemap
    pixel centre hits first must be in the set. Rays through a shared edge may pick either
    triangle (ambiguous by float rounding), so up to 1 in 1000 hit pixels may disagree."""
    n = 64
    scene = pyvislib.load_scene(str(city))
    visible = set(pyvislib.segment_visibility(scene, FROM, TO, resolution=n).visible.tolist())
    renderer = pyvislib.Renderer(scene)
    hits = outside = 0
    for t in (0.0, 0.21, 0.5, 0.77, 1.0):
        eye = tuple(a + t * (b - a) for a, b in zip(FROM, TO))
        for cam in cube_views(eye, n):
            tri = renderer.render(**cam).triangles
            tri = tri[tri != pyvislib.NO_HIT]
            hits += tri.size
            outside += sum(1 for x in tri.tolist() if x not in visible)
    assert hits > 0
    assert outside <= hits // 1000, f"{outside} of {hits} hit pixels show a triangle not in the set"


def test_region_visible_ids_equal_cli_region_json(city, tmp_path):
    scene = pyvislib.load_scene(str(city))
    box = (-20.0, 1.5, -36.0, 20.0, 1.5, -30.0)
    r = pyvislib.region_visibility(scene, box[:3], box[3:], runs=2, seed=5, resolution=32)
    out = tmp_path / "region.json"
    run_pvs("region", city, "--box", ",".join(map(repr, box)), "--runs", 2, "--seed", 5, "--res", 32,
             "-q", "--json", out)

    cli = json.loads(out.read_text())
    assert r.visible.tolist() == cli["visible"]
    assert r.segment_count == 4 and r.run_count == 8


def test_bad_options_raise_value_error_before_any_work(city):
    scene = pyvislib.load_scene(str(city))
    with pytest.raises(ValueError, match="resolution"):
        pyvislib.segment_visibility(scene, FROM, TO, resolution=0)
    with pytest.raises(ValueError, match="coplanar"):
        pyvislib.segment_visibility(scene, FROM, TO, coplanar="sometimes")
    with pytest.raises(ValueError, match="rotation"):
        pyvislib.segment_visibility(scene, FROM, TO, orientation=[1, 0, 0, 0, 1, 0, 0, 0, 2])
    with pytest.raises(ValueError, match="from_"):
        pyvislib.segment_visibility(scene, (0, 0), TO)
