"""Fixtures of the pyvislib suite (docs/python.md): the `pvs` command and small generated inputs.

ctest runs this suite (tests/CMakeLists.txt, Python.Pytest) with PYTHONPATH naming the folder of the
built module and VISLIB_PVS_EXE the `pvs` binary of the same build, so every check here compares the
binding with the C++ side through an independent path: the CLI's JSON output.
"""
import json
import os
import subprocess

import pytest

PVS = os.environ.get("VISLIB_PVS_EXE", "pvs")


def run_pvs(*args):
    """Runs `pvs ARGS...` quietly and returns its stdout; fails the test on a non-zero exit."""
    r = subprocess.run([PVS, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, f"pvs {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}"
    return r.stdout


def pvs_json(*args):
    return json.loads(run_pvs(*args))


@pytest.fixture(scope="session")
def workdir(tmp_path_factory):
    return tmp_path_factory.mktemp("pyvislib")


@pytest.fixture(scope="session")
def city(workdir):
    """A 2 x 2 block generated city (482 triangles): small enough for N = 64 in well under a second."""
    path = workdir / "city.glb"
    run_pvs("generate", "city", "--blocks", "2,2", "--lots", "2", "--seed", "3", "-q", "-o", path)
    return path


@pytest.fixture(scope="session")
def city_pvs(workdir, city):
    """A 3 x 1 x 3 grid bake of `city` over the streets around the centre, at N = 32."""
    path = workdir / "city.pvs"
    run_pvs("bake", city, "--box", "-40,1,-40,40,3,40", "--grid", "3,1,3", "--res", "32", "-q",
            "-o", path)
    return path
