"""chain.thermal returns `chain thermal --format json` for the same drift test, its predictions as arrays."""

import csv

import numpy as np
import pytest

import chain
from conftest import ROOT, flat, squeezed

RUN = ROOT / "examples/thermal/spindle_drift.csv"
FIT = ["--fit", "--holdout", "0.25", "--lag"]


def _columns(path):
    with open(path, encoding="utf-8") as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    return {name: np.array([float(r[j]) for r in rows[1:]]) for j, name in enumerate(rows[0])}


def test_thermal_is_the_cli_json(cli, tmp_path):
    pairs = ["X1(um):X2(um)=100", ("Y1(um)", "Y2(um)", 100.0)]
    r = chain.thermal(RUN, pairs=pairs)
    assert r.to_dict() == cli("thermal", RUN, "--pair", "X1(um):X2(um)=100", "--pair", "Y1(um):Y2(um)=100.0")
    fitted = chain.thermal(RUN, fit=True, holdout=0.25, lag=True)
    want = cli("thermal", RUN, *FIT)
    assert fitted.to_dict() == want
    assert [c["name"] for c in fitted.to_dataframe().to_dict("records")] == [c["name"] for c in want["channels"]]
    # The arrays are --format csv's columns.
    import subprocess
    from conftest import cli_binary

    out = subprocess.run([str(cli_binary()), "thermal", str(RUN), *FIT, "--format", "csv"], capture_output=True,
                         text=True, check=True).stdout.splitlines()
    rows = [line.split(",") for line in out[1:]]
    n = len(fitted.time)
    assert n == want["samples"] and len(rows) == 5 * n
    for k, name in enumerate(fitted.measured):
        block = rows[k * n:(k + 1) * n]
        assert all(b[1] == name for b in block)
        np.testing.assert_array_equal(fitted.time, [float(b[0]) for b in block])
        np.testing.assert_array_equal(fitted.measured[name], [float(b[2]) for b in block])
        np.testing.assert_array_equal(fitted.predicted[name], [float(b[3]) for b in block])
    # Held out: the arrays give the document's statistics.
    z = fitted.channels[0]
    held = fitted.time >= fitted.fit["until"]
    residual = fitted.measured["Z(um)"][held] - fitted.predicted["Z(um)"][held]
    assert np.sqrt(np.mean(residual ** 2)) == pytest.approx(z["holdout"]["rms_after"], rel=1e-12)


def test_columns_and_text_are_read_as_the_file():
    by_file = chain.thermal(RUN, fit=True, holdout=0.25).to_dict()
    cols = _columns(RUN)
    assert chain.thermal(cols, name=str(RUN), fit=True, holdout=0.25).to_dict() == by_file
    import pandas

    assert chain.thermal(pandas.DataFrame(cols), name=str(RUN), fit=True, holdout=0.25).to_dict() == by_file
    text = RUN.read_text(encoding="utf-8")
    assert chain.thermal(text=text, name=str(RUN), fit=True, holdout=0.25).to_dict() == by_file


def test_refusals_are_the_cli_messages(cli_error, tmp_path):
    bad = tmp_path / "time.csv"
    bad.write_text("time(s),Z(um),T(°C)\n0,0,20\n60,1,20.5\n60,2,21\n", encoding="utf-8")
    with pytest.raises(chain.MachineError) as info:
        chain.thermal(bad)
    e = info.value
    assert (e.file, e.line, e.column) == (str(bad), 4, 1)
    assert "60 s is not after 60 s (line 3)" in str(e)
    assert squeezed(e.message) in squeezed(cli_error("thermal", bad))
    good = tmp_path / "good.csv"
    good.write_text("time(s),Z(um),T(°C)\n0,0,20\n60,1,20.5\n120,2,21\n", encoding="utf-8")
    with pytest.raises(ValueError) as info:
        chain.thermal(good, pairs=["Z(um):T(°C)=100"])
    assert squeezed(str(info.value)) in squeezed(cli_error("thermal", good, "--pair", "Z(um):T(°C)=100"))
    with pytest.raises(ValueError) as info:
        chain.thermal(good, fit=True, holdout=2.0)
    assert flat(str(info.value)) in flat(cli_error("thermal", good, "--fit", "--holdout", "2"))
    with pytest.raises(ValueError, match="give fit=True"):
        chain.thermal(good, lag=True)
    with pytest.raises(ValueError, match="as run .* or as text, one of them"):
        chain.thermal()
