"""`Machine.reliability` with every option of `chain reliability`, and `Machine.sobol` (`chain sobol`):
each document equal to the CLI's `--format json` for the same input, on every example machine with a
reliability section; bad options refused with the CLI's wording."""

import math

import pytest

import chain
from conftest import MACHINES, ROOT, flat

WITH_RELIABILITY = [p for p in MACHINES if "\nreliability:" in p.read_text() and "\nstatistics:" in p.read_text()]
IDS = [p.stem for p in WITH_RELIABILITY]
GANTRY = ROOT / "examples/machines/gantry_grinder.yaml"

# (python keywords, CLI options): every method, seeded, small sample counts.
METHODS = [
    ({"method": "form"}, ["--method", "form"]),
    ({"method": "sorm"}, ["--method", "sorm"]),
    ({"method": "is", "samples": 400, "seed": 3}, ["--method", "is", "--samples", 400, "--seed", 3]),
    ({"method": "mc", "samples": 3000, "seed": 5}, ["--method", "mc", "--samples", 3000, "--seed", 5]),
    ({"method": "subset", "samples": 300, "seed": 2}, ["--method", "subset", "--samples", 300, "--seed", 2]),
    ({"method": "directional", "samples": 300, "seed": 4},
     ["--method", "directional", "--samples", 300, "--seed", 4]),
]


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
@pytest.mark.parametrize("kw,opts", METHODS, ids=[k["method"] for k, _ in METHODS])
def test_every_method_is_the_cli_json(path, kw, opts, cli):
    doc = chain.Machine.load(path).reliability(**kw).to_dict()
    assert doc == cli("reliability", path, *opts)
    assert doc["method"] == kw["method"]
    assert len(doc["results"]) > 0 and all(0.0 <= c["reliability"] <= 1.0 for c in doc["results"])


COV = [
    ({"method": "mc", "cov": 0.5, "samples": 20000, "seed": 1}, ["--method", "mc", "--cov", 0.5, "--samples", 20000, "--seed", 1]),
    ({"method": "is", "cov": 0.3, "samples": 5000, "seed": 1}, ["--method", "is", "--cov", 0.3, "--samples", 5000, "--seed", 1]),
    ({"method": "subset", "cov": 0.5, "samples": 200, "seed": 1},
     ["--method", "subset", "--cov", 0.5, "--samples", 200, "--seed", 1]),
    ({"method": "directional", "cov": 0.3, "samples": 3000, "seed": 1},
     ["--method", "directional", "--cov", 0.3, "--samples", 3000, "--seed", 1]),
]


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
@pytest.mark.parametrize("kw,opts", COV, ids=[k["method"] for k, _ in COV])
def test_target_cov_is_the_cli_json(path, kw, opts, cli):
    doc = chain.Machine.load(path).reliability(**kw).to_dict()
    assert doc == cli("reliability", path, *opts)
    # The stopping rule is reported per case, with the target asked for.
    assert all(c["sampling"]["target_cov"] == kw["cov"] for c in doc["results"])


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
def test_systems_are_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    series = m.reliability(system="series").to_dict()
    assert series == cli("reliability", path, "--system", "series")
    assert "series" in series["summary"]
    vol = m.reliability(system="volumetric").to_dict()
    assert vol == cli("reliability", path, "--system", "volumetric")
    assert "volumetric" in vol["summary"]
    tol = m.reliability(system="volumetric", system_tolerance=0.05, method="mc", samples=2000, seed=9).to_dict()
    assert tol == cli("reliability", path, "--system", "volumetric", "--system-tolerance", 0.05,
                      "--method", "mc", "--samples", 2000, "--seed", 9)
    # A series system is no more reliable than its weakest component at any point.
    by_point = {}
    for c in series["results"]:
        by_point.setdefault(tuple(sorted(c["point"].items())), {})[c["component"]] = c["reliability"]
    for rs in by_point.values():
        assert rs["series"] <= min(v for k, v in rs.items() if k != "series") + 1e-12


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
def test_acceptance_is_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    r = m.reliability(acceptance=True, acceptance_tolerance=0.01, seed=2)
    doc = r.to_dict()
    assert doc == cli("reliability", path, "--acceptance", "--acceptance-tolerance", 0.01, "--seed", 2)
    a = r.acceptance
    assert list(doc)[-1] == "acceptance"
    assert 0.0 <= a["probability"] <= 1.0 and a["tolerance"] == 0.01
    assert [s["error"] for s in a["sensitivity"]] == m.errors
    # Every point within tolerance at once is no likelier than the least reliable case.
    assert a["probability"] <= min(c["reliability"] for c in doc["results"]) + 3 * a["std_error"]
    # With sampling and the default tolerance too.
    doc = m.reliability(method="is", samples=300, seed=1, acceptance=True).to_dict()
    assert doc == cli("reliability", path, "--method", "is", "--samples", 300, "--seed", 1, "--acceptance")


POSTERIOR = """machine: gantry_grinder
values:
  dxx: {value: 0.004, std: 0.003}
  dxz: {value: -0.002, std: 0.0025}
  eyx: {value: 2.0e-6, std: 4.0e-6}
  dxy: {value: 0.001, std: 0.004}
correlation:
  - [dxx, dxz, -0.45]
  - [eyx, dxx, 0.3]
  - [dxy, dxz, 0.2]
"""


def test_values_posterior_is_the_cli_json(tmp_path, cli):
    values = tmp_path / "posterior.yaml"
    values.write_text(POSTERIOR)
    m = chain.Machine.load(GANTRY)
    doc = m.reliability(values=values).to_dict()
    assert doc == cli("reliability", GANTRY, "--values", values)
    assert [v["name"] for v in doc["posterior"]["values"]] == ["dxx", "dxz", "eyx", "dxy"]
    assert m.reliability(values=str(values), method="is", samples=300, seed=2, acceptance=True).to_dict() == cli(
        "reliability", GANTRY, "--values", values, "--method", "is", "--samples", 300, "--seed", 2, "--acceptance")


def test_a_carried_error_is_the_cli_json(tmp_path, cli, cli_error):
    # docs/posterior.md, "Fixed and carried": ezx is taken as exact.
    values = tmp_path / "carried.yaml"
    values.write_text(POSTERIOR.replace("correlation:", "  ezx: {value: 2.0e-6, carried_by: [dxx, eyx]}\ncorrelation:"))
    m = chain.Machine.load(GANTRY)
    doc = m.reliability(values=values, acceptance=True).to_dict()
    assert doc == cli("reliability", GANTRY, "--values", values, "--acceptance")
    assert doc["posterior"]["values"][4] == {"name": "ezx", "mean": 2.0e-6, "carried_by": ["dxx", "eyx"]}
    assert "ezx" not in [s["error"] for s in doc["acceptance"]["sensitivity"]]
    values.write_text(POSTERIOR.replace("correlation:", "  ezx: {value: 0, carried_by: [dxq]}\ncorrelation:"))
    with pytest.raises(chain.MachineError) as info:
        m.reliability(values=values)
    assert (info.value.line, info.value.column) == (7, 32)
    assert "`dxq` in `carried_by` of `ezx` is not an error parameter" in str(info.value)
    assert "`dxq` in `carried_by` of `ezx` is not an error parameter" in flat(
        cli_error("reliability", GANTRY, "--values", values))


def test_a_bad_posterior_is_located_in_the_values_file(tmp_path, cli_error):
    values = tmp_path / "posterior.yaml"
    values.write_text(POSTERIOR.replace("[dxy, dxz, 0.2]", "[dxy, dxq, 0.2]"))
    with pytest.raises(chain.MachineError) as info:
        chain.Machine.load(GANTRY).reliability(values=values)
    e = info.value
    assert e.file.endswith("posterior.yaml") and (e.line, e.column) == (10, 11)
    assert "unknown name `dxq` (did you mean `dxx`?)" in str(e)
    assert "unknown name `dxq` (did you mean `dxx`?)" in cli_error("reliability", GANTRY, "--values", values)


def _first_point(m, path, cli):
    point = cli("reliability", path)["results"][0]["point"]
    return {v: point.get(v, 0.0) for v in m.variables}


@pytest.mark.parametrize("path", WITH_RELIABILITY, ids=IDS)
def test_sobol_is_the_cli_json(path, cli):
    m = chain.Machine.load(path)
    s = m.sobol(samples=600, seed=3, bootstrap=40)
    doc = s.to_dict()
    assert doc == cli("sobol", path, "--samples", 600, "--seed", 3, "--bootstrap", 40)
    assert doc["at"] is None and doc["method"] == "saltelli-jansen"
    at = _first_point(m, path, cli)
    doc = m.sobol(at=at, samples=500, seed=1, bootstrap=30, confidence=0.9).to_dict()
    opt = ",".join(f"{k}={v!r}" for k, v in at.items())
    assert doc == cli("sobol", path, "--at", opt, "--samples", 500, "--seed", 1, "--bootstrap", 30,
                      "--confidence", 0.9)
    assert doc["at"] == at and "grid" not in doc
    rows = m.sobol(at=at, samples=500, seed=1, bootstrap=30, confidence=0.9)._rows()
    assert len(rows) == sum(len(o["errors"]) for o in doc["outputs"].values())
    for output, o in doc["outputs"].items():
        # Each index lies in its bootstrap interval; Σ first <= Σ total up to sampling noise.
        for e in o["errors"]:
            assert e["first"]["low"] <= e["first"]["value"] <= e["first"]["high"]
        assert o["sum_first"]["value"] <= o["sum_total"]["value"] + 0.1


def test_sobol_with_a_grid_is_the_cli_json(cli):
    m = chain.Machine.load(GANTRY)
    doc = m.sobol(grid={"x": [0, 1000]}, samples=400, bootstrap=20).to_dict()
    assert doc == cli("sobol", GANTRY, "--grid", "x=0,1000", "--samples", 400, "--bootstrap", 20)
    assert doc["grid"]["x"] == [0.0, 1000.0]



@pytest.mark.parametrize("kw,opts,wording", [
    ({"method": "bogus"}, ["--method", "bogus"],
     "`bogus` is not a method: choose one of form, is, mc, subset, directional, sorm"),
    ({"method": "mc", "cov": 0}, ["--method", "mc", "--cov", "0"],
     "the target coefficient of variation must be in (0, 1] (found `0`)"),
    ({"method": "mc", "cov": -0.5}, ["--method", "mc", "--cov", "-0.5"],
     "the target coefficient of variation must be in (0, 1] (found `-0.5`)"),
    ({"method": "mc", "cov": 1.5}, ["--method", "mc", "--cov", "1.5"],
     "the target coefficient of variation must be in (0, 1] (found `1.5`)"),
    ({"method": "mc", "samples": 0}, ["--method", "mc", "--samples", "0"],
     "the number of samples must be between 1 and 68719476736 (found 0)"),
    ({"method": "directional", "samples": 0}, ["--method", "directional", "--samples", "0"],
     "the number of samples must be between 1 and 68719476736 (found 0)"),
    ({"method": "subset", "samples": 1005}, ["--method", "subset", "--samples", "1005"],
     "the samples per level must be a positive multiple of 1/p0 = 10"),
    ({"method": "form", "cov": 0.1}, ["--method", "form", "--cov", "0.1"],
     "FORM draws no samples; a target coefficient of variation needs"),
    ({"acceptance": True, "acceptance_tolerance": 0.0}, ["--acceptance", "--acceptance-tolerance", "0"],
     "(an absolute error in (0, 1))"),
    ({"system": "parallel"}, ["--system", "parallel"],
     "`parallel` is not a system target: choose one of series, volumetric"),
])
def test_bad_options_are_refused_with_the_cli_wording(kw, opts, wording, cli_error):
    with pytest.raises(ValueError) as info:
        chain.Machine.load(GANTRY).reliability(**kw)
    assert wording in str(info.value)
    assert flat(wording) in flat(cli_error("reliability", GANTRY, *opts))


def test_other_bad_options_raise_value_error():
    m = chain.Machine.load(GANTRY)
    bad = [
        ({"method": "mc", "cov": math.nan}, "(found `NaN`)"),
        ({"method": "sorm", "cov": 0.1}, "SORM draws no samples"),
        ({"method": "is", "samples": -3}, "samples must be a non-negative integer"),
        ({"method": 3}, "method must be a str"),
        ({"cov": "x", "method": "mc"}, "cov must be a number"),
        ({"system_tolerance": 0.1}, "give --system volumetric too"),
        ({"system": "series", "system_tolerance": 0.1},
         "invalid value for '--system-tolerance': the allowable error of --system volumetric, not series"),
        ({"system": "volumetric", "system_tolerance": -1.0},
         "invalid value for '--system-tolerance': `-1` (a positive allowable volumetric error, mm)"),
        ({"acceptance": "yes"}, "acceptance must be True or False"),
        ({"acceptance": True, "acceptance_tolerance": 1.0}, "invalid value for '--acceptance-tolerance': 1 (an absolute error in (0, 1))"),
        ({"sided": "three"}, "`three` is not a side: choose one of upper, two"),
    ]
    for kw, wording in bad:
        with pytest.raises(ValueError) as info:
            m.reliability(**kw)
        assert wording in str(info.value), (kw, str(info.value))
    with pytest.raises(chain.MachineError) as info:
        m.reliability(grid={"w": [0.0]})
    assert "unknown axis variable `w`" in str(info.value)
    with pytest.raises(ValueError, match="no-such-posterior.yaml: cannot read the file"):
        m.reliability(values=ROOT / "no-such-posterior.yaml")


def test_bad_sobol_options_are_refused_with_the_cli_wording(cli_error):
    m = chain.Machine.load(GANTRY)
    for kw, opts, wording in [
        ({"samples": 1}, ["--samples", "1"], "samples 1: must be "),
        ({"confidence": 1.5}, ["--confidence", "1.5"], "confidence 1.5: must be "),
        ({"bootstrap": 0}, ["--bootstrap", "0"], "bootstrap 0: must be "),
    ]:
        with pytest.raises(ValueError) as info:
            m.sobol(**kw)
        assert str(info.value).startswith("--" + wording)
        # The CLI's message, word for word (chain::ops::sobol).
        assert flat(str(info.value)) in flat(cli_error("sobol", GANTRY, *opts))
    with pytest.raises(ValueError) as info:
        m.sobol(at={"x": 0.0})
    assert "at has no value for axis variable `z`" in str(info.value)
    assert "--at has no value for axis variable `z`" in cli_error("sobol", GANTRY, "--at", "x=0")
    with pytest.raises(chain.MachineError) as info:
        m.sobol(at={"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0})
    # The CLI's message, word for word (chain::ops::resolve).
    wording = "--at: `w` is not an axis variable"
    assert wording in str(info.value)
    assert wording in cli_error("sobol", GANTRY, "--at", "x=0,y=0,z=0,w=1")
    with pytest.raises(ValueError) as info:
        m.sobol(at={"x": 0.0, "y": 0.0, "z": 0.0}, grid={"x": [0.0]})
    assert str(info.value).startswith("--grid cannot be combined with --at\nhelp: --at evaluates at one point")
    assert flat(str(info.value)) in flat(cli_error("sobol", GANTRY, "--at", "x=0,y=0,z=0", "--grid", "x=0"))
    with pytest.raises(ValueError, match="not finite"):
        m.sobol(at={"x": math.inf, "y": 0.0, "z": 0.0})
    with pytest.raises(ValueError, match="samples must be a non-negative integer"):
        m.sobol(samples=-1)
