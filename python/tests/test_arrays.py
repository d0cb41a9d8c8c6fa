"""Shapes, dtypes and broadcasting; wrong shapes and NaN are ValueErrors; malformed files MachineErrors."""

import re

import numpy as np
import pytest

import chain
from conftest import ROOT, squeezed

AC = ROOT / "examples/machines/ac_trunnion.yaml"


@pytest.fixture(scope="module")
def ac():
    return chain.Machine.load(AC)


def test_shapes_and_dtypes(ac):
    V, NE = len(ac.variables), len(ac.errors)
    assert (V, NE) == (5, 41)
    q = np.random.default_rng(0).uniform(-1, 1, size=(17, V))
    S = ac.sensitivity(q)
    assert S.shape == (17, 6, NE) and S.dtype == np.float64 and S.flags["C_CONTIGUOUS"]
    one = ac.sensitivity(q[4])
    assert one.shape == (6, NE) and one.flags["C_CONTIGUOUS"]
    np.testing.assert_array_equal(one, S[4])
    # lists, ints, float32 and non-contiguous views are converted, same values
    np.testing.assert_array_equal(ac.sensitivity(q[4].tolist()), one)
    np.testing.assert_array_equal(ac.sensitivity(np.asfortranarray(q)), S)
    np.testing.assert_array_equal(ac.sensitivity(q[::2]), S[::2])
    assert ac.sensitivity(np.zeros((0, V))).shape == (0, 6, NE)
    assert ac.sensitivity(np.ones(V, dtype=np.int64)).dtype == np.float64


def test_sensitivity_into_a_callers_array(ac):
    """``out=``: the same values written into the caller's array (returned, no new one), reused
    over batches; every value overwritten (NaN beforehand); a wrong array refused by name."""
    V, NE = len(ac.variables), len(ac.errors)
    rng = np.random.default_rng(1)
    out = np.full((9, 6, NE), np.nan)
    for _ in range(3):
        q = rng.uniform(-1, 1, size=(9, V))
        got = ac.sensitivity(q, out=out)
        assert got is out
        np.testing.assert_array_equal(out, ac.sensitivity(q))
    one = np.full((6, NE), np.nan)
    assert ac.sensitivity(q[2], out=one) is one
    np.testing.assert_array_equal(one, ac.sensitivity(q[2]))
    for bad, kind, msg in [
        (np.zeros((9, 6, NE - 1)), ValueError, f"out has shape (9, 6, {NE - 1}), expected (9, 6, {NE})"),
        (np.zeros((9, 6, NE), dtype=np.float32), ValueError, "out must be float64, not float32"),
        (np.zeros((6, NE, 9)).transpose(2, 0, 1), ValueError, "out must be C-contiguous"),
        ([[0.0] * NE] * 6, TypeError, "out must be a numpy array, not list"),
    ]:
        with pytest.raises(kind, match=re.escape(msg)):
            ac.sensitivity(q, out=bad)
    frozen = np.zeros((9, 6, NE))
    frozen.flags.writeable = False
    with pytest.raises(ValueError, match="out must be writeable"):
        ac.sensitivity(q, out=frozen)


def test_error_broadcasts(ac):
    V, NE = len(ac.variables), len(ac.errors)
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, size=(9, V))
    e = rng.normal(0, 1e-3, size=(9, NE))
    S = ac.sensitivity(q)
    expected = np.einsum("ncj,nj->nc", S, e)
    E = ac.error(q, e)
    assert E.shape == (9, 6) and E.dtype == np.float64
    np.testing.assert_allclose(E, expected, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ac.error(q, e[0]), S @ e[0], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ac.error(q[0], e), np.einsum("cj,nj->nc", S[0], e), rtol=1e-12, atol=1e-15)
    assert ac.error(q[0], e[0]).shape == (6,)
    with pytest.raises(ValueError, match="9 points and e 4 rows"):
        ac.error(q, e[:4])


def test_nominal(ac):
    q = np.zeros((2, 5))
    q[1, 1] = np.pi / 2  # A = 90°
    rot, pos = ac.nominal(q)
    assert rot.shape == (2, 3, 3) and pos.shape == (2, 3)
    np.testing.assert_allclose(rot[0], np.eye(3), atol=1e-15)
    for r in rot:  # rotations are orthonormal
        np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-14)
    assert ac.nominal(q[0]).rotation.shape == (3, 3)


@pytest.mark.parametrize("bad,msg", [
    (np.zeros(4), r"shape \(4,\): expected \(5,\) or \(N, 5\)"),
    (np.zeros((3, 6)), r"shape \(3, 6\)"),
    (np.zeros((2, 2, 5)), r"shape \(2, 2, 5\)"),
    ("abc", "array of numbers"),
])
def test_wrong_shapes_raise(ac, bad, msg):
    with pytest.raises(ValueError, match=msg):
        ac.sensitivity(bad)


def test_nan_raises_with_its_place(ac):
    q = np.zeros((4, 5))
    q[2, 3] = np.nan
    for f in (ac.sensitivity, ac.nominal, lambda q: ac.error(q, np.zeros(41))):
        with pytest.raises(ValueError, match=r"q has a non-finite value \(NaN\) at row 2, column 3"):
            f(q)
    e = np.zeros(41)
    e[7] = np.inf
    with pytest.raises(ValueError, match=r"e has a non-finite value \(inf\) at row 0, column 7"):
        ac.error(np.zeros(5), e)
    with pytest.raises(ValueError, match="e of shape"):
        ac.error(np.zeros(5), np.zeros(40))


def test_params(ac):
    q = np.random.default_rng(3).uniform(-1, 1, size=5)
    base = ac.sensitivity(q)
    longer = ac.sensitivity(q, params={"tool_length": 250.0})
    assert not np.array_equal(base, longer)
    np.testing.assert_array_equal(ac.sensitivity(q, params={"tool_length": 150.0}), base)
    with pytest.raises(chain.MachineError, match="--param tool_lenght: machine `ac_trunnion` has no parameter `tool_lenght`"):
        ac.sensitivity(q, params={"tool_lenght": 1.0})
    with pytest.raises(ValueError, match="--param tool_length: NaN is not finite"):
        ac.sensitivity(q, params={"tool_length": float("nan")})


def test_symbolic_parameter_needs_a_value():
    text = (ROOT / "examples/machines/ac_trunnion.yaml").read_text()
    text = re.sub(r"tool_length: *[0-9.]+", "tool_length: null", text, count=1)
    m = chain.Machine.from_yaml(text, "sym.yaml")
    assert m.parameters["tool_length"] is None
    with pytest.raises(chain.MachineError, match="tool_length` is symbolic"):
        m.sensitivity(np.zeros(5))
    s = m.sensitivity(np.zeros(5), params={"tool_length": 150.0})
    np.testing.assert_array_equal(s, chain.Machine.load(AC).sensitivity(np.zeros(5)))


BAD = """machine: m
bodies:
  bed: {}
  x: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, errors: {dx: dxx}, bogus: 1}
workpiece: bed
tool: x
"""



def test_malformed_machine_raises_machine_error(tmp_path, cli_error):
    with pytest.raises(chain.MachineError) as info:
        chain.Machine.from_yaml(BAD, "bad.yaml")
    e = info.value
    assert isinstance(e, ValueError)
    assert (e.file, e.line, e.column, e.key) == ("bad.yaml", 4, 88, "bodies.x.bogus")
    assert str(e).startswith("bad.yaml:4:88: unknown key `bogus` at key `bodies.x.bogus`")
    path = tmp_path / "bad.yaml"
    path.write_text(BAD)
    with pytest.raises(chain.MachineError) as info:
        chain.Machine.load(path)
    assert info.value.line == 4 and info.value.key == "bodies.x.bogus"
    # the same message as the CLI's
    assert squeezed(str(info.value)) in squeezed(cli_error("derive", path))


def test_missing_file_and_reliability_section(tmp_path, cli_error):
    with pytest.raises(chain.MachineError, match="nope.yaml"):
        chain.Machine.load(tmp_path / "nope.yaml")
    m = chain.Machine.load(AC)
    with pytest.raises(chain.MachineError, match="missing key `reliability`") as info:
        m.reliability()
    assert squeezed(str(info.value).splitlines()[0]) in squeezed(cli_error("reliability", AC))


def test_missing_statistic_is_located(tmp_path):
    text = BAD.replace(", bogus: 1", "") + "reliability: {tolerance: {px: 0.1}, grid: {x: [0, 1]}}\n"
    m = chain.Machine.from_yaml(text, "nostat.yaml")
    with pytest.raises(chain.MachineError) as info:
        m.reliability()
    assert info.value.line == 4 and "statistics.dxx" in str(info.value)


def test_bad_options(ac):
    g = chain.Machine.load(ROOT / "examples/machines/gantry_grinder.yaml")
    with pytest.raises(ValueError, match=r"`sorm\?` is not a method: choose one of form, is, mc"):
        g.reliability(method="sorm?")
    with pytest.raises(ValueError, match="the number of samples must be between 1 and"):
        g.reliability(method="mc", samples=0)
    with pytest.raises(chain.MachineError, match="axis variable"):
        g.reliability(grid={"w": [0.0]})
    with pytest.raises(ValueError, match="--grid x: NaN is not finite"):
        g.reliability(grid={"x": [0.0, float("nan")]})
    with pytest.raises(ValueError, match="`base` is not a frame: choose one of tool, workpiece"):
        ac.derive("base")


def test_result_objects_and_dataframe():
    pd = pytest.importorskip("pandas")
    g = chain.Machine.load(ROOT / "examples/machines/gantry_grinder.yaml")
    r = g.reliability()
    d = r.to_dict()
    assert r.summary == d["summary"] and r.machine == "gantry_grinder"
    d["summary"] = None  # a copy
    assert r.summary is not None
    df = r.to_dataframe()
    assert isinstance(df, pd.DataFrame) and len(df) == len(r.results) == 375
    first = r.results[0]
    p = first["point"]
    row = df[(df.component == first["component"]) & (df.x == p["x"]) & (df.y == p["y"]) & (df.z == p["z"])]
    assert len(row) == 1 and row.reliability.iloc[0] == first["reliability"]
    with pytest.raises(AttributeError, match="no attribute"):
        r.nothing
