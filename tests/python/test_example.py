"""The documented example (docs/python.md) keeps running: examples/speed_vs_error.py on a small
generated city at tiny resolutions, its table parsed."""
import os
import pathlib
import subprocess
import sys

EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "examples" / "speed_vs_error.py"


def test_speed_vs_error_example_prints_one_row_per_resolution(city):
    r = subprocess.run([sys.executable, str(EXAMPLE), "--scene", str(city), "--from=-35,1.7,-33",
                        "--to=30,1.7,-33", "--res", "8,16", "--ref", "32", "--repeat", "1",
                        "--views", "1", "--frame", "32x24"],
                       capture_output=True, text=True, env=os.environ.copy())
    assert r.returncode == 0, r.stderr
    rows = [line.split("|")[1:-1] for line in r.stdout.splitlines() if line.startswith("| ") and
            line[2].isdigit()]
    assert [int(row[0]) for row in rows] == [8, 16, 32]
    missed = [int(row[3]) for row in rows]
    assert missed[-1] == 0  # the reference against itself
    assert missed[0] >= missed[1] >= 0
