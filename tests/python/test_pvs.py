"""PVS files through pyvislib.Pvs (the runtime's reader) against `pvs inspect --json`."""
import numpy as np
import pytest

import pyvislib
from conftest import pvs_json


def test_cell_count_header_and_every_cell_equal_pvs_inspect(city, city_pvs):
    pvs = pyvislib.Pvs(str(city_pvs))
    summary = pvs_json("inspect", city_pvs, "--json")
    assert pvs.cell_count == summary["cells"] == 9
    assert pvs.universe == summary["universe"]
    assert pvs.granularity == summary["granularity"]
    assert "0x%016x" % pvs.scene_fingerprint == summary["scene_fingerprint"]
    assert pvs.scene_fingerprint == pyvislib.load_scene(str(city)).fingerprint
    assert [pvs.visible_count(c) for c in range(9)] == summary["per_cell"]["visible"]
    for cell in (0, 4, 8):  # one `pvs inspect` run costs about a second: three cells
        ids = pvs.visible_ids(cell)
        assert ids.dtype == np.uint32
        shown = pvs_json("inspect", city_pvs, "--cell", cell, "--json")
        assert ids.tolist() == shown["visible"]
        assert pvs.visible_count(cell) == shown["visible_count"] == len(ids)
        lo, hi = pvs.cell_box(cell)
        assert list(lo) == shown["box"]["min"] and list(hi) == shown["box"]["max"]


def test_find_cell_equals_pvs_inspect_at(city_pvs):
    pvs = pyvislib.Pvs(str(city_pvs))
    for p in [(13.4, 1.0, -26.0), (39.9, 3.0, 39.9)]:
        shown = pvs_json("inspect", city_pvs, "--at", "%r,%r,%r" % p, "--json")
        assert pvs.find_cell(p) == shown["cell"]
    assert pvs.find_cell((500.0, 2.0, 0.0)) is None


def test_missing_pvs_raises_file_not_found_naming_the_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="absent.pvs"):
        pyvislib.Pvs(str(tmp_path / "absent.pvs"))


def test_truncated_pvs_raises_format_error_with_the_byte_offset(city_pvs, tmp_path):
    cut = tmp_path / "cut.pvs"
    cut.write_bytes(city_pvs.read_bytes()[:100])
    with pytest.raises(pyvislib.FormatError, match="byte"):
        pyvislib.Pvs(str(cut))


def test_pvs_of_another_scene_is_rejected_by_its_fingerprint(city, city_pvs):
    fp = pyvislib.load_scene(str(city)).fingerprint
    assert pyvislib.Pvs(str(city_pvs), expected_fingerprint=fp).cell_count == 9
    with pytest.raises(pyvislib.FormatError):
        pyvislib.Pvs(str(city_pvs), expected_fingerprint=fp ^ 1)


def test_cell_out_of_range_raises_index_error(city_pvs):
    pvs = pyvislib.Pvs(str(city_pvs))
    with pytest.raises(IndexError, match="9 cells"):
        pvs.visible_ids(9)
    with pytest.raises(IndexError):
        pvs.visible_ids(-1)
