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


THERMAL_MACHINE = ROOT / "examples/thermal/vmc3_thermal.yaml"
THERMAL_VALUES = ROOT / "examples/thermal/vmc3_thermal_values.yaml"


def test_the_map_at_a_thermal_state_is_the_cli_s(cli):
    m = chain.Machine.load(THERMAL_MACHINE)
    got = m.map(THERMAL_VALUES, grid={"x": [0, 800], "y": [0], "z": [0, 500]}, temperature={"T_x": 28, "T_coltop": 23.5})
    want = cli("map", THERMAL_MACHINE, "--values", THERMAL_VALUES, "--grid", "x=0,800", "--grid", "y=0", "--grid",
               "z=0,500", "--temperature", "T_x=28,T_coltop=23.5")
    assert got.to_dict() == want
    assert want["temperatures"] == {"T_x": 28.0, "T_front": 20.0, "T_rear": 20.0, "T_head": 20.0, "T_coltop": 23.5}
    # The X scale's growth: 11.5e-3 µm/mm/K · 800 mm · 8 K along −x (the
    # table moves opposite to the tool), plus the reference map.
    reference = m.map(THERMAL_VALUES, grid={"x": [0, 800], "y": [0], "z": [0, 500]}).to_dict()
    for a, b in zip(want["points"], reference["points"]):
        growth = -11.5e-6 * a["point"]["x"] * 8.0
        assert a["error"]["px"] - b["error"]["px"] == pytest.approx(growth, abs=1e-12)


def test_temperature_refusals_are_the_cli_s():
    m = chain.Machine.load(THERMAL_MACHINE)
    with pytest.raises(ValueError) as e:
        m.map(THERMAL_VALUES, temperature={"T_z": 25})
    assert "--temperature: `T_z` is not a sensor of machine `vmc3_thermal` (did you mean `T_x`?)" in flat(str(e.value))
    with pytest.raises(ValueError, match="sensor `T_x`: 'hot' is not a number"):
        m.map(THERMAL_VALUES, temperature={"T_x": "hot"})
    with pytest.raises(TypeError, match="temperature must be a mapping of sensor name to °C"):
        m.map(THERMAL_VALUES, temperature=[("T_x", 25)])


def test_the_fitted_models_into_the_machine_are_the_cli_s(cli, tmp_path):
    m = chain.Machine.load(THERMAL_MACHINE)
    out = tmp_path / "spindle_values.yaml"
    got = chain.thermal(RUN, fit=True, holdout=0.25, machine=m, slots={"EZS": "Z(um)"}, values_out=out)
    cli_out = tmp_path / "cli_values.yaml"
    want = cli("thermal", RUN, "--fit", "--holdout", "0.25", "--values-out", cli_out, "--machine", THERMAL_MACHINE,
               "--slot", "EZS=Z(um)")
    assert got.to_dict() == want
    assert out.read_text(encoding="utf-8") == cli_out.read_text(encoding="utf-8") == got.values_text
    assert [c["name"] for c in want["values"]["terms"][0]["coefficients"]] == [
        "EZS_T_front", "EZS_T_rear", "EZS_T_head", "EZS_T_coltop"]
    with pytest.raises(ValueError, match="machine and slots go together"):
        chain.thermal(RUN, fit=True, machine=m)
    with pytest.raises(ValueError) as e:
        chain.thermal(RUN, fit=True, machine=m, slots={"EZX": "Z(um)"})
    assert "--slot: `EZX` is not a thermal term `{name, per}` of machine `vmc3_thermal` (did you mean `EZS`?)" in flat(str(e.value))


ROOM = ROOT / "tests/data/thermal_room.yaml"


def test_reliability_over_temperatures_is_the_cli_s(cli):
    path = ROOM
    m = chain.Machine.load(path)
    assert m.reliability().to_dict() == cli("reliability", path)
    assert m.reliability(temperature={"T_x": 27}).to_dict() == cli("reliability", path, "--temperature", "T_x=27")
    assert m.sensitivity_reliability(temperature={"T_x": 27}).to_dict() == cli(
        "sensitivity", path, "--temperature", "T_x=27")


def test_the_thermal_export_is_the_cli_s(cli, tmp_path):
    m = chain.Machine.load(THERMAL_MACHINE)
    grid = {"x": [0, 400, 800], "y": [0, 250, 500], "z": [0, 250, 500]}
    for controller in ("siemens-thermal", "linuxcnc-thermal", "beckhoff-thermal", "heidenhain-thermal",
                       "klipper-thermal"):
        got = m.export(THERMAL_VALUES, controller=controller, grid=grid)
        want = cli("export", THERMAL_MACHINE, "--values", THERMAL_VALUES, "--controller", controller, "--out",
                   tmp_path / controller, "--grid", "x=0,400,800", "--grid", "y=0,250,500", "--grid", "z=0,250,500")
        assert got.to_dict() == want
        for name, text in got.files.items():
            assert (tmp_path / controller / name).read_text(encoding="utf-8") == text
