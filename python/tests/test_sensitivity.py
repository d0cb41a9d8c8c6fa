"""`Machine.sensitivity_reliability` (`chain sensitivity --kind reliability`) and
`Machine.geometric_sensitivity` (`chain sensitivity --kind geometric`): each document equal to the
CLI's `--format json` for the same input on the example machines, checked against an independent
computation (central differences of the reliability; `|S|` from `Machine.sensitivity`), bad
options refused naming the keyword."""

import numpy as np
import pytest

import chain
from conftest import MACHINES, ROOT, flat
from test_reliability import POSTERIOR

WITH_RELIABILITY = [p for p in MACHINES if "\nreliability:" in p.read_text() and "\nstatistics:" in p.read_text()]
IDS = [p.stem for p in WITH_RELIABILITY]
GANTRY = ROOT / "examples/machines/gantry_grinder.yaml"


def first_point(m):
    """The first grid value of every axis variable (the geometric grid document lists them)."""
    grid = m.geometric_sensitivity().grid
    return {v: grid[v][0] for v in m.variables}


def at_option(point):
    return ",".join(f"{k}={v!r}" for k, v in point.items())


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
def test_reliability_sensitivity_is_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    mean = m.sensitivity_reliability()
    assert mean.to_dict() == cli("sensitivity", path)
    assert mean.at is None
    point = first_point(m)
    at = m.sensitivity_reliability(at=point)
    assert at.to_dict() == cli("sensitivity", path, "--at", at_option(point))
    assert set(at.at) == set(m.variables)
    for target, errors in at.components.items():
        assert sorted(e["error"] for e in errors) == sorted(m.errors)
        ranked = [abs(e["dr_dstd"]) for e in errors]
        assert ranked == sorted(ranked, reverse=True)
        assert "mean_abs_dr_dstd" not in errors[0] and "mean_abs_dr_dstd" in mean.components[target][0]
    rows = at.to_dataframe()
    assert len(rows) == sum(len(e) for e in at.components.values())


def test_reliability_sensitivity_with_a_posterior_and_options_is_the_cli_json(tmp_path, cli):
    values = tmp_path / "posterior.yaml"
    values.write_text(POSTERIOR)
    m = chain.Machine.load(GANTRY)
    doc = m.sensitivity_reliability(values=values).to_dict()
    assert doc == cli("sensitivity", GANTRY, "--values", values)
    assert [v["name"] for v in doc["posterior"]["values"]] == ["dxx", "dxz", "eyx", "dxy"]
    grid = {"x": [0, 700], "y": [0, 1500]}
    assert m.sensitivity_reliability(grid=grid, sided="upper").to_dict() == cli(
        "sensitivity", GANTRY, "--grid", "x=0,700", "--grid", "y=0,1500", "--sided", "upper")


def test_dr_dstd_is_the_central_difference_of_the_reliability(tmp_path):
    """dR/dstd of dxx at one point against (R(std + h) - R(std - h)) / 2h, the reliability run
    with the posterior's std of dxx moved by h (the correlations held fixed, as the derivative)."""
    m = chain.Machine.load(GANTRY)
    point = first_point(m)
    values = tmp_path / "posterior.yaml"
    values.write_text(POSTERIOR)
    s = m.sensitivity_reliability(at=point, values=values)
    h = 1e-6
    r = {}
    for sign in (1, -1):
        moved = tmp_path / f"moved{sign}.yaml"
        moved.write_text(POSTERIOR.replace("{value: 0.004, std: 0.003}", f"{{value: 0.004, std: {0.003 + sign * h!r}}}"))
        doc = m.reliability(values=moved, grid={k: [v] for k, v in point.items()}).to_dict()
        r[sign] = {c["component"]: c["reliability"] for c in doc["results"]}
    checked = 0
    for target, errors in s.components.items():
        e = next(e for e in errors if e["error"] == "dxx")
        fd = (r[1][target] - r[-1][target]) / (2 * h)
        assert e["dr_dstd"] == pytest.approx(fd, rel=1e-4, abs=1e-6)
        checked += abs(fd) > 1e-3
    assert checked > 0


@pytest.mark.parametrize("path", MACHINES, ids=[p.stem for p in MACHINES])
def test_geometric_sensitivity_is_the_cli_json_and_the_jacobian(path, cli):
    m = chain.Machine.load(path)
    # Symbolic parameters (no value in the file) get one, here and on the command line.
    params = {p: 120.0 for p, v in m.parameters.items() if v is None}
    opts = [o for p, v in params.items() for o in ("--param", f"{p}={v!r}")]
    has_grid = "\nreliability:" in path.read_text()
    point = first_point(m) if has_grid else {v: 0.1 * (i + 1) for i, v in enumerate(m.variables)}
    r = m.geometric_sensitivity(at=point, params=params)
    assert r.to_dict() == cli("sensitivity", path, "--kind", "geometric", "--at", at_option(point), *opts)
    # S = |dE/de| from the exact Jacobian, e the paper's 0.001 mm / 0.001 deg, C = S e / sum(S e).
    S = np.abs(m.sensitivity(np.array([point[v] for v in m.variables]), params=params))
    for u, (component, errors) in enumerate(r.components.items()):
        assert component == ["px", "py", "pz", "ox", "oy", "oz"][u]
        se = {e["error"]: e["s"] * e["e"] for e in errors}
        total = sum(se.values())
        assert r.totals[component] == pytest.approx(total, rel=1e-12, abs=1e-300)
        for e in errors:
            j = m.errors.index(e["error"])
            assert e["s"] == pytest.approx(S[u, j], rel=1e-12, abs=1e-12)
            if total > 0:
                assert e["c"] == pytest.approx(se[e["error"]] / total, rel=1e-12, abs=1e-15)
    sizes = {"linear": 0.002, "angular": "0.003deg"}
    assert m.geometric_sensitivity(at=point, sizes=sizes, params=params).to_dict() == cli(
        "sensitivity", path, "--kind", "geometric", "--at", at_option(point), "--values",
        "linear=0.002,angular=0.003deg", *opts)
    if has_grid:
        mean = m.geometric_sensitivity()
        assert mean.to_dict() == cli("sensitivity", path, "--kind", "geometric")
        assert mean.points == int(np.prod([len(v) for v in mean.grid.values()]))
        assert len(mean.to_dataframe()) == 6 * len(m.errors)


def test_geometric_grid_replaces_an_axis(cli):
    m = chain.Machine.load(GANTRY)
    r = m.geometric_sensitivity(grid={"x": [0, 350, 700]}, sizes="linear=0.001,angular=0.001")
    assert r.to_dict() == cli("sensitivity", GANTRY, "--kind", "geometric", "--grid", "x=0,350,700",
                              "--values", "linear=0.001,angular=0.001")
    assert r.grid["x"] == [0, 350, 700]


def test_bad_options_are_refused_naming_the_keyword(cli_error):
    m = chain.Machine.load(GANTRY)
    with pytest.raises(ValueError, match="`sizes`: unknown error kind `volume`"):
        m.geometric_sensitivity(sizes={"volume": 1})
    with pytest.raises(ValueError) as info:
        m.geometric_sensitivity(at=first_point(m), grid={"x": [0]})
    assert str(info.value).startswith("--grid cannot be combined with --at\nhelp: --at evaluates at one point")
    assert flat(str(info.value)) in flat(cli_error("sensitivity", GANTRY, "--kind", "geometric", "--at",
                                                   ",".join(f"{k}={v}" for k, v in first_point(m).items()),
                                                   "--grid", "x=0"))
    with pytest.raises(ValueError, match="at has no value for axis variable"):
        m.geometric_sensitivity(at={"x": 0})
    with pytest.raises(ValueError, match="at has no value for axis variable"):
        m.sensitivity_reliability(at={"x": 0})
    with pytest.raises(chain.MachineError, match="unknown axis variable `q`"):
        m.geometric_sensitivity(grid={"q": [0]})
    assert "unknown axis variable" in flat(cli_error("sensitivity", GANTRY, "--kind", "geometric", "--grid", "q=0"))
    with pytest.raises(ValueError, match="`three` is not a side: choose one of upper, two"):
        m.sensitivity_reliability(sided="three")
    with pytest.raises(ValueError, match="--grid x: NaN is not finite"):
        m.geometric_sensitivity(grid={"x": [0, float("nan")]})
    with pytest.raises(ValueError, match="no-such.yaml"):
        m.sensitivity_reliability(values="no-such.yaml")


