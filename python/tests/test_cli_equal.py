"""Every binding returns what the CLI's JSON returns for the same input, on each example machine;
the batch evaluations against the derived expressions evaluated independently by SymPy."""

import numpy as np
import pytest
import sympy

import chain
from conftest import MACHINES, ROOT

WITH_RELIABILITY = [p for p in MACHINES if "\nreliability:" in p.read_text() and "\nstatistics:" in p.read_text()]
IDS = [p.stem for p in MACHINES]


@pytest.mark.parametrize("path", MACHINES, ids=IDS)
def test_derive_is_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    assert m.derive().to_dict() == cli("derive", path)
    for frame in ("tool", "workpiece"):
        assert m.derive(frame).to_dict() == cli("derive", path, "--frame", frame)
    doc = cli("derive", path)
    assert m.variables == doc["variables"] and m.errors == doc["errors"]
    assert list(m.parameters) == doc["parameters"]


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=[p.stem for p in WITH_RELIABILITY])
def test_reliability_is_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    assert m.reliability().to_dict() == cli("reliability", path)


def test_reliability_without_statistics_fails_as_the_cli_does(cli_error):
    path = ROOT / "examples/machines/vmc3.yaml"
    with pytest.raises(chain.MachineError) as info:
        chain.Machine.load(path).reliability()
    e = info.value
    assert e.line > 0 and e.key
    flat = lambda t: "".join(t.replace("│", " ").replace("×", " ").split())
    assert flat(str(e).splitlines()[0].replace(str(ROOT) + "/", "")) in flat(cli_error("reliability", "examples/machines/vmc3.yaml"))


def test_reliability_sampling_options_are_the_cli_json(cli):
    path = ROOT / "examples/machines/gantry_grinder.yaml"
    m = chain.Machine.load(path)
    r = m.reliability(method="mc", samples=2000, seed=7, grid={"x": [0, 1000]}, sided="two")
    assert r.to_dict() == cli("reliability", path, "--method", "mc", "--samples", 2000, "--seed", 7,
                              "--grid", "x=0,1000", "--sided", "two")
    r = m.reliability(method="is", samples=500, seed=3)
    assert r.to_dict() == cli("reliability", path, "--method", "is", "--samples", 500, "--seed", 3)
    assert r.method == "is" and set(r.summary) == {"px", "py", "pz"}


def _points(m, n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(-400.0, 400.0, size=(n, len(m.variables)))


def _symbolic(m):
    """The derived expressions (the CLI's derive JSON) evaluated by SymPy at a point."""
    doc = m.derive().to_dict()
    values = {k: v for k, v in doc["parameter_values"].items()}
    sym = {n: sympy.Symbol(n) for n in doc["variables"] + doc["parameters"] + doc["errors"]}

    def at(q):
        subs = {sym[v]: float(x) for v, x in zip(doc["variables"], q)}
        subs.update({sym[k]: float(v) for k, v in values.items() if v is not None})
        s = np.zeros((6, len(doc["errors"])))
        for c, comp in enumerate(("px", "py", "pz", "ox", "oy", "oz")):
            for e, expr in doc["components"][comp].items():
                s[c, doc["errors"].index(e)] = float(sympy.sympify(expr, locals=sym).evalf(subs=subs))
        rot = np.array([[float(sympy.sympify(x, locals=sym).evalf(subs=subs)) for x in row]
                        for row in doc["nominal"]["rotation"]])
        pos = np.array([float(sympy.sympify(x, locals=sym).evalf(subs=subs)) for x in doc["nominal"]["position"]])
        return s, rot, pos

    return at


@pytest.mark.parametrize("path", MACHINES, ids=IDS)
def test_sensitivity_error_nominal_against_sympy(path):
    m = chain.Machine.load(path)
    if any(v is None for v in m.parameters.values()):
        pytest.skip("symbolic parameters (covered in test_arrays)")
    q = _points(m, 3, 1)
    S = m.sensitivity(q)
    nom = m.nominal(q)
    at = _symbolic(m)
    e = np.random.default_rng(2).normal(0.0, 1e-3, size=(3, len(m.errors)))
    E = m.error(q, e)
    for i in range(3):
        s, rot, pos = at(q[i])
        scale = max(1.0, np.abs(s).max())
        np.testing.assert_allclose(S[i], s, rtol=1e-11, atol=1e-11 * scale)
        np.testing.assert_allclose(nom.rotation[i], rot, atol=1e-12)
        np.testing.assert_allclose(nom.position[i], pos, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(E[i], s @ e[i], rtol=1e-10, atol=1e-12 * scale)


def test_to_sympy_is_the_sensitivity():
    m = chain.Machine.load(ROOT / "examples/machines/ac_trunnion.yaml")
    M = m.to_sympy()
    assert M.shape == (6, len(m.errors))
    q = _points(m, 1, 5)[0]
    subs = {sympy.Symbol(v): x for v, x in zip(m.variables, q)}
    subs.update({sympy.Symbol(k): v for k, v in m.parameters.items()})
    np.testing.assert_allclose(np.array(M.evalf(subs=subs), dtype=float), m.sensitivity(q), rtol=1e-11, atol=1e-9)
