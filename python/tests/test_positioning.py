"""chain.positioning returns `chain positioning --format json` for the same runs."""

import csv

import numpy as np
import pytest

import chain
from conftest import ROOT, flat, squeezed

RUNS = ROOT / "examples/positioning"


def _columns(path):
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    header, data = rows[0], rows[1:]
    out = {}
    for j, name in enumerate(header):
        column = [r[j] for r in data]
        if name == "direction":
            out[name] = np.array(column, dtype=object)
        elif name == "run":
            out[name] = np.array(column, dtype=int)
        else:
            out[name] = np.array(column, dtype=float)
    return out


@pytest.mark.parametrize("name,rotary", [("x_axis_runs.csv", False), ("c_axis_runs.csv", True)])
def test_positioning_is_the_cli_json(name, rotary, cli):
    path = RUNS / name
    flags = ["--rotary"] if rotary else []
    r = chain.positioning(path, rotary=rotary)
    assert r.to_dict() == cli("positioning", path, *flags)
    assert chain.positioning(path, rotary=rotary, k=3).to_dict() == cli("positioning", path, *flags, "--k", "3")
    df = r.to_dataframe()
    assert len(df) == len(r.targets) and list(df["mean_up"]) == [t["mean_up"] for t in r.targets]


def test_columns_are_read_as_the_file():
    path = RUNS / "x_axis_runs.csv"
    cols = _columns(path)
    by_columns = chain.positioning(cols, name=str(path)).to_dict()
    assert by_columns == chain.positioning(path).to_dict()
    import pandas

    assert chain.positioning(pandas.DataFrame(cols), name=str(path)).to_dict() == by_columns


def test_refusals_are_the_cli_messages(cli_error, tmp_path):
    bad = tmp_path / "twice.csv"
    bad.write_text("target,direction,run,deviation\n0,up,1,0\n0,up,2,0\n0,down,1,0\n0,down,2,0\n"
                   "5,up,1,0\n5,up,2,0\n5,down,1,0\n5,down,1,0\n")
    with pytest.raises(chain.MachineError) as info:
        chain.positioning(bad)
    e = info.value
    assert (e.file, e.line, e.column) == (str(bad), 9, 8)
    assert "target 5, direction down, run 1 is given twice (first on line 8)" in str(e)
    assert squeezed(e.message) in squeezed(cli_error("positioning", bad))
    cols = _columns(RUNS / "x_axis_runs.csv")
    cols["direction"][3] = "sideways"
    with pytest.raises(chain.MachineError, match="`sideways` is not a direction") as info:
        chain.positioning(cols)
    assert info.value.file == "<runs>" and info.value.line == 5
    with pytest.raises(ValueError, match=r"the coverage factor k must be a finite number > 0, not 0"):
        chain.positioning(RUNS / "x_axis_runs.csv", k=0)
    with pytest.raises(ValueError, match="not both|dict of columns"):
        chain.positioning(42)


def test_map_with_an_approach_is_the_cli_json(cli, tmp_path):
    """A run written by `chain positioning --values-out`, mapped per approach, equals the CLI's JSON."""
    vmc3 = ROOT / "examples/machines/vmc3.yaml"
    values = tmp_path / "x.yaml"
    cli("positioning", RUNS / "x_axis_runs.csv", "--values-out", values, "--machine", vmc3, "--slot", "EXX")
    m = chain.Machine.load(vmc3)
    grid = {"x": [0.0, 102.8, 1000.0], "y": [0.0], "z": [0.0]}
    args = ["map", vmc3, "--values", values, "--grid", "x=0,102.8,1000", "--grid", "y=0", "--grid", "z=0"]
    for approach, flag in [(None, []), ("up", ["--approach", "up"]), ({"x": "down"}, ["--approach", "x=down"])]:
        got = m.map(values, grid=grid, approach=approach)
        assert got.to_dict() == cli(*args, *flag)
    up = m.map(values, grid=grid, approach="up")
    assert up.reversals[0]["name"] == "EXX" and up.reversals[0]["approach"] == "up"
    assert up.points[0]["error"]["px"] == pytest.approx(0.0026352, abs=1e-12)  # x̄↑ at 0 mm (chain positioning)
    with pytest.raises(ValueError, match="no table along `y` has a reverse direction"):
        m.map(values, grid=grid, approach={"y": "up"})
    with pytest.raises(ValueError, match="`sideways` is not an approach direction"):
        m.map(values, grid=grid, approach="sideways")


def test_values_out_and_reliability_with_the_repeatability(cli, cli_error, tmp_path):
    """positioning(machine=, slot=) writes what --values-out writes; reliability(values=, approach=) is the CLI's."""
    vmc3 = ROOT / "examples/machines/vmc3.yaml"
    m = chain.Machine.load(vmc3)
    ours = tmp_path / "ours.yaml"
    r = chain.positioning(RUNS / "x_axis_runs.csv", machine=m, slot="EXX", values_out=ours)
    theirs = tmp_path / "theirs.yaml"
    cli("positioning", RUNS / "x_axis_runs.csv", "--values-out", theirs, "--machine", vmc3, "--slot", "EXX")
    # The same file but for the run file's name in its comments.
    strip = lambda text: [l for l in text.splitlines() if not l.startswith("#") and not l.startswith("description")]
    assert strip(ours.read_text()) == strip(theirs.read_text())
    assert r.values_text == ours.read_text()
    assert chain.positioning(RUNS / "x_axis_runs.csv").values_text is None
    with pytest.raises(ValueError, match="is in the `dy` slot"):
        chain.positioning(RUNS / "x_axis_runs.csv", machine=m, slot="EYX")
    with pytest.raises(ValueError, match="values_out needs machine and slot"):
        chain.positioning(RUNS / "x_axis_runs.csv", values_out=tmp_path / "x.yaml")
    # Reliability of a one-axis machine with the run's mean and repeatability.
    one = tmp_path / "one.yaml"
    one.write_text(
        "machine: one\nbodies:\n  bed: {}\n"
        "  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: EXX}}\n"
        "workpiece: bed\ntool: x_slide\n"
        "reliability:\n  tolerance: {px: 0.004}\n  sided: upper\n  grid:\n    x: [0, 102.8, 401.4]\n"
    )
    m1 = chain.Machine.load(one)
    values = tmp_path / "one_values.yaml"
    chain.positioning(RUNS / "x_axis_runs.csv", machine=m1, slot="EXX", values_out=values)
    for approach, flag in [(None, []), ("up", ["--approach", "up"]), ({"x": "down"}, ["--approach", "x=down"])]:
        got = m1.reliability(values=values, approach=approach).to_dict()
        assert got == cli("reliability", one, "--values", values, *flag)
    s = m1.sensitivity_reliability(values=values, approach="up").to_dict()
    assert s == cli("sensitivity", one, "--values", values, "--approach", "up")
    # Without values there are no tables to choose a direction of: the same words as the CLI's.
    wording = "invalid value for '--approach': the direction of a values file's tables: give --values VALUES.yaml too"
    for call, command in [(m1.reliability, "reliability"), (m1.sensitivity_reliability, "sensitivity")]:
        with pytest.raises(ValueError) as info:
            call(approach="up")
        assert str(info.value) == wording
        assert flat(wording) in flat(cli_error(command, one, "--approach", "up"))


def test_compensate_is_the_cli_json(cli, cli_error):
    """chain.compensate over a path or columns equals `chain compensate ... --format json` (one reader, one analysis)."""
    path = ROOT / "examples/data/swing_htm50200.csv"
    expected = cli("compensate", path, "--length", "577.11")
    assert chain.compensate(path, length=577.11).to_dict() == expected
    cols = _columns(path)
    got = chain.compensate(cols, length=577.11, name=str(path))
    # The same analysis; the file is named as given, and its lines are the
    # columns' (no comment lines before them).
    def lineless(doc):
        return {**doc, "points": [{k: v for k, v in p.items() if k != "line"} for p in doc["points"]]}

    assert lineless(got.to_dict()) == lineless(expected)
    assert [p["line"] for p in got.points] == list(range(2, 2 + len(got.points)))
    r = chain.compensate(path, length=577.11, select="bic", max_order=5)
    assert r.to_dict() == cli("compensate", path, "--length", "577.11", "--select", "bic", "--max-order", "5")
    assert len(r.to_dataframe()) == len(r.points)
    with pytest.raises(ValueError) as info:
        chain.compensate(path, length=577.11, select="best")
    wording = "`best` is not a selection rule: choose one of loocv, adjusted-r2, aicc, bic"
    assert str(info.value) == wording
    assert wording in cli_error("compensate", path, "--length", "577.11", "--select", "best")
    bad = {k: v for k, v in cols.items() if k != "z3"}
    with pytest.raises(ValueError) as info:
        chain.compensate(bad, length=577.11, name="bad.csv")
    assert "z3" in str(info.value)


def test_temperatures_are_the_cli_s(cli):
    path = RUNS / "x_axis_runs.csv"
    r = chain.positioning(path, temperatures={"axis": 23.5, "axis_expansion": 11.5, "instrument": 22.0,
                                              "instrument_expansion": 11.0})
    assert r.to_dict() == cli("positioning", path, "--axis-temperature", "23.5", "--axis-expansion", "11.5",
                              "--instrument-temperature", "22", "--instrument-expansion", "11")
    assert r.temperature["per_metre"] == pytest.approx(11.5 * 3.5 - 11.0 * 2.0)
    with pytest.raises(ValueError, match="temperatures needs 'axis_expansion'"):
        chain.positioning(path, temperatures={"axis": 23.5})
    with pytest.raises(ValueError, match="a rotary axis's angles"):
        chain.positioning(RUNS / "c_axis_runs.csv", rotary=True, temperatures={"axis": 23.0, "axis_expansion": 11.5})
