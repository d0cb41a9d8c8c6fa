"""Machine.motion: `chain motion` through chain::ops::motion (the CLI's request, checks and document)."""

import csv
import io
import subprocess

import numpy as np
import pytest

import chain
from conftest import ROOT, cli_binary, flat

CNC = ROOT / "examples/machines/cnc5_bevel.yaml"
SETTINGS = ROOT / "examples/settings/seed002_convex.yaml"


def test_motion_is_the_cli_s(cli):
    """The document equals `chain motion --format json`; times and exact equal `--format csv`."""
    m = chain.Machine.load(CNC)
    got = m.motion(SETTINGS, order=12, samples=50, tolerance=1e-6)
    assert got.to_dict() == cli("motion", CNC, "--settings", SETTINGS, "--order", 12, "--samples", 50,
                                "--tolerance", 1e-6)
    out = subprocess.run([str(cli_binary()), "motion", str(CNC), "--settings", str(SETTINGS), "--order", "12",
                          "--samples", "50", "--format", "csv"], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0] == ["t"] + m.variables
    values = np.array([[float(x) for x in r] for r in rows[1:]])
    assert got.times.shape == (50,) and got.exact.shape == (50, len(m.variables))
    # The CSV prints the shortest round-trip form: equal to the last bit.
    assert np.array_equal(values[:, 0], got.times)
    assert np.array_equal(values[:, 1:], got.exact)
    assert got._rows()[0]["t"] == got.times[0]


def test_motion_refusals_are_the_cli_s(cli_error, tmp_path):
    """Options out of range and a misspelt settings name: the CLI's message, word for word."""
    m = chain.Machine.load(CNC)
    with pytest.raises(ValueError) as info:
        m.motion(SETTINGS, order=171)
    assert str(info.value) == "--order 171 is above the limit 170"
    assert str(info.value) in flat(cli_error("motion", CNC, "--settings", SETTINGS, "--order", 171))
    with pytest.raises(ValueError, match="--angular-tolerance needs --tolerance"):
        m.motion(SETTINGS, angular_tolerance=1e-6)
    with pytest.raises(ValueError, match="--samples 1 must be between 2 and 1000000"):
        m.motion(SETTINGS, samples=1)
    with pytest.raises(chain.MachineError) as info:
        m.motion(SETTINGS, fix={"muu": 0.0})
    assert "--fix: `muu` is not an axis variable" in str(info.value)
    bad = tmp_path / "bad.yaml"
    generator = ROOT / "examples/machines/cradle_generator.yaml"
    bad.write_text(SETTINGS.read_text().replace("\n  S_d:", "\n  S_dd:")
                   .replace("generator: ../machines/cradle_generator.yaml", f"generator: {generator}"))
    with pytest.raises(chain.MachineError) as info:
        m.motion(bad)
    e = info.value
    assert (e.file, e.key) == (str(bad), "values.S_dd")
    assert "`S_dd` is not a parameter or variable of the generator `cradle_generator` (did you mean `S_d`?)" in str(e)
    assert "`S_dd` is not a parameter or variable of the generator" in flat(cli_error("motion", CNC, "--settings", bad))
