"""Each script of examples/python runs and prints what it says."""

import subprocess
import sys

import pytest

from conftest import ROOT

SCRIPTS = sorted((ROOT / "examples" / "python").glob("*.py"))


@pytest.mark.parametrize("script", SCRIPTS, ids=[s.stem for s in SCRIPTS])
def test_example_runs(script, tmp_path):
    out = subprocess.run([sys.executable, str(script), str(tmp_path)], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip(), "the example printed nothing"


def test_there_are_examples():
    assert {s.stem for s in SCRIPTS} >= {"gantry_reliability_map", "five_axis_sensitivity", "figure"}
