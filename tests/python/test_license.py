import json
import pathlib

import pyvislib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_module_license_is_the_one_of_license_file_and_web_package():
    assert pyvislib.__license__ == "Apache-2.0"
    assert (ROOT / "LICENSE").read_text().split()[:4] == ["Apache", "License", "Version", "2.0,"]
    assert json.loads((ROOT / "web" / "package.json").read_text())["license"] == pyvislib.__license__
