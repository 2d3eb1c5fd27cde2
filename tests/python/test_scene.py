import pytest

import pyvislib
from conftest import pvs_json


def test_scene_counts_and_bounds_equal_pvs_info(city):
    scene = pyvislib.load_scene(str(city))
    info = pvs_json("info", city, "--json")
    assert scene.triangle_count == info["triangles"]
    assert scene.object_count == info["objects"]
    assert scene.sphere_count == info["spheres"]
    assert scene.state_count == info["states"]
    assert scene.vertex_count == info["vertices"]
    lo, hi = scene.bounds
    assert list(lo) == info["bbox"]["min"]
    assert list(hi) == info["bbox"]["max"]


def test_triangle_objects_map_every_triangle_to_an_object(city):
    scene = pyvislib.load_scene(str(city))
    objs = scene.triangle_objects
    assert objs.shape == (scene.triangle_count,)
    assert objs.max() < scene.object_count
    assert list(scene.objects_of([0, scene.triangle_count - 1])) == sorted({int(objs[0]), int(objs[-1])})


def test_missing_scene_raises_input_error_naming_the_file(tmp_path):
    missing = tmp_path / "no_such_scene.glb"
    with pytest.raises(pyvislib.InputError, match="no_such_scene.glb"):
        pyvislib.load_scene(str(missing))


def test_malformed_scene_raises_input_error_naming_the_file(tmp_path):
    bad = tmp_path / "broken.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(pyvislib.InputError, match="broken.obj") as e:
        pyvislib.load_scene(str(bad))
    assert isinstance(e.value, ValueError)
