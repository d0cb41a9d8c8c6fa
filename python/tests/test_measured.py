"""Group B (the measured machine): map, identify and plan return the CLI's JSON for the same input."""

import csv

import numpy as np
import pytest

import chain
from conftest import MACHINES, ROOT, squeezed

MEAS = ROOT / "examples/measurements"
PROBE = MEAS / "vmc3_probe.yaml"
VMC3 = ROOT / "examples/machines/vmc3.yaml"
VALUES = ROOT / "examples/values/vmc3.yaml"
TOOL = {"tx": 0, "ty": 0, "tz": -150}


def _columns(path):
    with open(path) as f:
        rows = list(csv.reader(line for line in f if not line.startswith("#")))
    header, data = rows[0], np.array(rows[1:], dtype=float)
    return {name: data[:, j] for j, name in enumerate(header)}


@pytest.mark.parametrize("values", [VALUES, ROOT / "examples/values/vmc3_legendre.yaml"], ids=["tables", "legendre"])
def test_map_is_the_cli_json(values, cli):
    m = chain.Machine.load(VMC3)
    assert m.map(values).to_dict() == cli("map", VMC3, "--values", values)
    r = m.map(values, grid={"x": [0, 400, 800], "z": [100]})
    assert r.to_dict() == cli("map", VMC3, "--values", values, "--grid", "x=0,400,800", "--grid", "z=100")
    assert len(r.to_dataframe()) == len(r.points)


def test_map_at_points_is_the_cli_axes_csv(cli, tmp_path):
    m = chain.Machine.load(VMC3)
    q = np.random.default_rng(1).uniform(0, 500, size=(7, 3))
    path = tmp_path / "axes.csv"
    path.write_text(",".join(m.variables) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n" for row in q))
    assert m.map(VALUES, points=q).to_dict() == cli("map", VMC3, "--values", VALUES, "--axes", path)


@pytest.mark.parametrize("path", MACHINES, ids=[p.stem for p in MACHINES])
def test_map_of_a_dict_of_values_is_the_cli_json(path, cli, tmp_path):
    """Every example machine: constant errors from a dict, against the same values file through the CLI."""
    m = chain.Machine.load(path)
    values = {e: 1e-3 * (k % 5 + 1) for k, e in enumerate(m.errors) if not e.startswith("E") or "_" not in e}
    grid = {v: [0.0, 0.25] for v in m.variables}
    params = {n: 100.0 for n, v in m.parameters.items() if v is None}
    try:
        got = m.map(values, grid=grid, params=params).to_dict()
    except ValueError as e:  # a function slot's coefficients need a table or all coefficients
        pytest.skip(str(e))
    vfile = tmp_path / "values.yaml"
    vfile.write_text(f"machine: {m.name}\nunits: {{linear: mm, angular: rad}}\nvalues:\n"
                     + "".join(f"  {k}: {v!r}\n" for k, v in values.items()))
    args = ["map", path, "--values", vfile] + [a for v in m.variables for a in ("--grid", f"{v}=0,0.25")]
    args += [a for n, v in params.items() for a in ("--param", f"{n}={v}")]
    assert got == cli(*args)


def test_map_bad_input():
    m = chain.Machine.load(VMC3)
    with pytest.raises(ValueError, match="points of shape"):
        m.map(VALUES, points=np.zeros((3, 2)))
    with pytest.raises(ValueError, match="non-finite"):
        m.map(VALUES, points=np.array([[0.0, np.nan, 0.0]]))
    with pytest.raises(chain.MachineError) as info:
        m.map({"NOT_AN_ERROR": 1.0})
    assert info.value.file == "<values>" and "NOT_AN_ERROR" in str(info.value)
    with pytest.raises(chain.MachineError):
        m.map(VALUES, grid={"w": [1.0]})


@pytest.mark.parametrize("name", ["ballplate.csv", "interferometer.csv"])
def test_identify_is_the_cli_json(name, cli, tmp_path):
    m = chain.Machine.load(PROBE)
    out = tmp_path / "identified.yaml"
    r = m.identify(MEAS / name, values_out=out)
    assert r.to_dict() == cli("identify", PROBE, "--measurements", MEAS / name)
    cli_out = tmp_path / "cli.yaml"
    cli("identify", PROBE, "--measurements", MEAS / name, "--values-out", cli_out)
    assert out.read_text() == cli_out.read_text() == r.values_text
    # the same measurements as arrays: the same numbers (the file name aside); the lines
    # are those of the CSV the arrays make (a header, then one row per record, no comments)
    a = m.identify(_columns(MEAS / name), name=str(MEAS / name)).to_dict()
    b = r.to_dict()
    data_lines = [i + 1 for i, line in enumerate((MEAS / name).read_text().splitlines()) if not line.startswith("#")][1:]
    for x, y in zip(a["largest_residuals"], b["largest_residuals"]):
        assert data_lines[x.pop("line") - 2] == y.pop("line")
    assert a == b
    assert [row["error"] for row in r._rows()] == list(r.estimates)


def test_identify_validate_is_the_cli_json(cli):
    """Machine.identify(validate=...) equals `chain identify --validate`: the
    held-out measurements as a path or as columns give the same prediction."""
    m = chain.Machine.load(PROBE)
    ball, inter = MEAS / "ballplate.csv", MEAS / "interferometer.csv"
    r = m.identify(ball, validate=inter)
    assert r.to_dict() == cli("identify", PROBE, "--measurements", ball, "--validate", inter)
    v = r.validation
    assert v["file"] == str(inter) and v["after"]["rms"] < v["before"]["rms"]
    columns = m.identify(ball, validate=_columns(inter), validate_name="held-out").validation
    assert columns["file"] == "held-out"
    assert {k: columns[k] for k in ("before", "after", "rows")} == {k: v[k] for k in ("before", "after", "rows")}


def test_identify_bad_input():
    m = chain.Machine.load(PROBE)
    cols = _columns(MEAS / "ballplate.csv")
    cols["dpx"] = cols["dpx"][:-1]
    with pytest.raises(ValueError, match="has 449 values"):
        m.identify(cols)
    cols = _columns(MEAS / "ballplate.csv")
    cols["dpy"][3] = np.inf
    with pytest.raises(ValueError, match=r"non-finite value \(inf\) at row 3"):
        m.identify(cols)
    cols = _columns(MEAS / "ballplate.csv")
    cols["bogus"] = cols.pop("dpz")
    with pytest.raises(chain.MachineError) as info:
        m.identify(cols)
    assert info.value.file == "<measurements>" and info.value.line == 1
    with pytest.raises(ValueError, match="has no parameter `tw`"):
        m.identify(MEAS / "ballplate.csv", params={"tw": 1.0})


@pytest.mark.parametrize("k", [40, 66])
def test_plan_is_the_cli_json(k, cli):
    m = chain.Machine.load(PROBE)
    r = m.plan(MEAS / "candidates.csv", k)
    assert r.to_dict() == cli("plan", PROBE, "--candidates", MEAS / "candidates.csv", "--count", k)
    a = m.plan(_columns(MEAS / "candidates.csv"), k, name=str(MEAS / "candidates.csv"))
    assert a.to_dict() == r.to_dict()
    assert len(r._rows()) == len(r.errors)


def test_plan_bad_input():
    m = chain.Machine.load(PROBE)
    with pytest.raises(ValueError, match="--kind direction needs the columns"):
        m.plan(MEAS / "candidates.csv", 40, kind="direction")
    with pytest.raises(ValueError, match="`line` is not a measurement kind: choose one of point, direction"):
        m.plan(MEAS / "candidates.csv", 40, kind="line")
    with pytest.raises(ValueError, match="--count 451 is not a count"):
        m.plan(MEAS / "candidates.csv", 451)
    with pytest.raises(ValueError, match="positive integer"):
        m.plan(MEAS / "candidates.csv", 0)


def test_options_are_refused_in_the_cli_s_words(cli_error, tmp_path):
    """Grid axes, --at and --param go through chain::ops::resolve in both: the same message."""

    no_grid = tmp_path / "m.yaml"
    no_grid.write_text(
        "machine: m\nparameters: {L: 100}\nbodies:\n  bed: {}\n"
        "  x_slide: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: EXX}}\n"
        "workpiece: bed\ntool: x_slide\n"
    )
    values = tmp_path / "v.yaml"
    values.write_text("machine: m\nvalues: {EXX: 0.001}\n")
    m = chain.Machine.load(no_grid)
    cases = [
        (lambda: m.map(values), ["map", no_grid, "--values", values], chain.MachineError,
         "no grid values for axis variable `x`"),
        (lambda: m.map(values, grid={"xx": [0.0]}), ["map", no_grid, "--values", values, "--grid", "xx=0"],
         chain.MachineError, "unknown axis variable `xx` (did you mean `x`?)"),
        (lambda: m.identify({"x": [0.0, 1.0], "dpx": [0.0, 0.0], "dpy": [0.0, 0.0], "dpz": [0.0, 0.0]},
                            params={"l": 1.0}),
         None, ValueError, "--param l: machine `m` has no parameter `l` (did you mean `L`?)"),
    ]
    for call, args, kind, wording in cases:
        with pytest.raises(kind) as info:
            call()
        assert wording in str(info.value)
        if args is not None:
            assert squeezed(wording) in squeezed(cli_error(*args))


def test_map_outside_a_table_is_the_cli_refusal(cli_error, tmp_path):
    """A point outside a values table: Machine.map raises the CLI's message and help (chain::ops::map), word for word."""
    values = tmp_path / "values.yaml"
    values.write_text(
        "machine: vmc3\nunits: {linear: um, angular: urad}\nvalues:\n"
        f"  EXX: {{table: {ROOT / 'examples/values/x_axis.csv'}, column: EXX}}\n"
    )
    m = chain.Machine.load(VMC3)
    with pytest.raises(ValueError) as info:
        m.map(values, grid={"x": [0, 850], "y": [0], "z": [0]})
    message, help_text = str(info.value).split("\nhelp: ")
    assert message.startswith("at point 2 (y = 0, x = 850, z = 0): x = 850 is outside the table of `EXX`")
    assert "extrapolate: hold" in help_text
    err = cli_error("map", VMC3, "--values", values, "--grid", "x=0,850", "--grid", "y=0", "--grid", "z=0")
    assert squeezed(message) in squeezed(err) and squeezed(help_text) in squeezed(err)


def test_inverse_is_the_cli_json(cli, cli_error, tmp_path):
    """Machine.inverse over an array equals `chain inverse --pose` on the same poses (chain::ops::inverse)."""
    machine = ROOT / "examples/machines/cnc5_bevel.yaml"
    pose_file = ROOT / "examples/paths/cnc5_bevel_pose.csv"
    with open(pose_file) as f:
        rows = [line for line in f if line.strip() and not line.startswith("#")]
    poses = np.array([[float(v) for v in r.split(",")[1:]] for r in rows[1:]])
    m = chain.Machine.load(machine)
    got = m.inverse(poses)
    assert got.to_dict() == cli("inverse", machine, "--pose", pose_file)
    assert len(got.to_dataframe()) >= len(poses)
    # One pose as a 1-D row; fix and params by name.
    one = m.inverse(poses[0])
    assert one.rows[0] == got.rows[0]
    with pytest.raises(ValueError, match="poses: a pose has 6 values \\(px, py, pz, i, j, k\\) or 12"):
        m.inverse(np.zeros((2, 5)))
    with pytest.raises(ValueError, match="poses row 1: the tool axis \\(i, j, k\\) is zero"):
        m.inverse(np.array([poses[0], [0, 0, 0, 0, 0, 0]]))
    bad = tmp_path / "bad.csv"
    bad.write_text("px,py,pz,i,j,k\n0,0,0,0,0,0\n")
    from conftest import flat

    assert "the tool axis (i, j, k) is zero" in flat(cli_error("inverse", machine, "--pose", bad))
    with pytest.raises(chain.MachineError) as info:
        m.inverse(poses, fix={"muu": 0.0})
    assert "--fix: `muu` is not an axis variable" in str(info.value)


def test_identify_subset_options_are_the_cli_json(cli):
    """Machine.identify(fix=, estimate=, rank_tol=) equals `chain identify --fix/--estimate/--rank-tol`:
    the same subset document; a bad name raises the CLI's message."""
    m = chain.Machine.load(PROBE)
    ball = MEAS / "ballplate.csv"
    r = m.identify(ball)
    fixed = [f["error"] for f in r.subset["fixed"]]
    # keep EXX_0 instead of EXY_0 (the two act alike on the plate)
    swapped = [("EXY_0" if f == "EXX_0" else f) for f in fixed]
    a = m.identify(ball, fix=swapped)
    assert a.to_dict() == cli("identify", PROBE, "--measurements", ball, "--fix", ",".join(swapped))
    assert a.subset["chosen_by"] == "fix" and "EXX_0" in a.subset["estimated"]
    b = m.identify(ball, estimate=r.subset["estimated"], rank_tol=1e-6)
    assert b.to_dict() == cli(
        "identify", PROBE, "--measurements", ball, "--estimate", ",".join(r.subset["estimated"]), "--rank-tol", 1e-6
    )
    rows = {row["error"]: row for row in r._rows()}
    assert rows["EXX_0"]["status"] == "redundant" and rows["EXY_0"]["status"] == "estimated"
    with pytest.raises(ValueError, match=r"--fix: `EXX_9` is not an error parameter of these measurements"):
        m.identify(ball, fix=["EXX_9"])
    with pytest.raises(ValueError, match="--fix: cannot be given with --estimate"):
        m.identify(ball, fix=["EXX_0"], estimate=["EXY_0"])


def test_identify_iterate_is_the_cli_json(cli):
    """Machine.identify(iterate=True) equals `chain identify --iterate`."""
    m = chain.Machine.load(PROBE)
    ball = MEAS / "ballplate.csv"
    r = m.identify(ball, iterate=True)
    assert r.to_dict() == cli("identify", PROBE, "--measurements", ball, "--iterate")
    assert r.iteration["converged"] and r.first_order["exceeds_noise"] is False
    with pytest.raises(ValueError, match="--iterate fits the exact kinematics by least squares"):
        m.identify(ball, iterate=True, prior=True)


def test_identify_holdout_is_the_cli_json(cli):
    """Machine.identify(holdout=, seed=) equals `chain identify --holdout --seed`."""
    m = chain.Machine.load(PROBE)
    ball = MEAS / "ballplate.csv"
    r = m.identify(ball, holdout=0.25, seed=7)
    assert r.to_dict() == cli("identify", PROBE, "--measurements", ball, "--holdout", 0.25, "--seed", 7)
    v = r.validation
    assert v["holdout"] == {"fraction": 0.25, "seed": 7} and len(v["lines"]) == 113  # 112.5 rounded half away from zero
    assert r.measurements == 450 - len(v["lines"])
    with pytest.raises(ValueError, match="--holdout: --seed chooses the records --holdout holds out"):
        m.identify(ball, seed=7)


def test_dh_robot_calibration_is_the_cli_json(cli):
    """The PUMA 560 from its DH table (examples/robots/, docs/identify.md) gives the CLI's fit, from
    the file or from numpy columns: rank 23 of 28 with the four position-only redundancies."""
    robots = ROOT / "examples/robots"
    m = chain.Machine.load(robots / "puma560_dh.yaml")
    assert m.errors[:6] == ["DD1", "DT1", "DA1", "DAL1", "DD2", "DT2"]
    fit, held = robots / "puma560_tracker.csv", robots / "puma560_validate.csv"
    r = m.identify(fit, validate=held)
    assert r.to_dict() == cli("identify", robots / "puma560_dh.yaml", "--measurements", fit, "--validate", held)
    assert (r.to_dict()["rank"], len(r.to_dict()["groups"])) == (23, 4)
    assert m.identify(_columns(fit), name=str(fit)).estimates == r.estimates
    # Held-out rms before/after (docs/identify.md): 0.682 mm -> 0.0224 mm.
    assert r.validation["before"]["rms"] == pytest.approx(0.6818, abs=1e-4)
    assert r.validation["after"]["rms"] == pytest.approx(0.02236, abs=1e-5)
