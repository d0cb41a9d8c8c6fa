"""The rules of the options every command shares, decided once in ``chain::ops`` (``choice``: the
spellings of every option with a closed set of values; ``resolve``: ``--param`` known and finite,
the grid or rows of a map or export): each refusal in the same words from Python and the CLI."""

import math

import pytest

import chain
from conftest import ROOT, flat

EX = ROOT / "examples"
GANTRY = EX / "machines/gantry_grinder.yaml"
VMC3 = EX / "machines/vmc3.yaml"
VALUES = EX / "values/vmc3.yaml"
PROBE = EX / "measurements/vmc3_probe.yaml"
CANDIDATES = EX / "measurements/candidates.csv"
SWING = EX / "data/swing_htm50200.csv"
AXES = EX / "paths/cnc5_bevel_axes.csv"


def _gantry():
    return chain.Machine.load(GANTRY)


def _vmc3():
    return chain.Machine.load(VMC3)


# (the Python call that must fail, the CLI's arguments, the words both say)
CASES = [
    ("method", lambda: _gantry().reliability(method="bogus"), ["reliability", GANTRY, "--method", "bogus"],
     "`bogus` is not a method: choose one of form, is, mc, subset, directional, sorm"),
    ("sided", lambda: _gantry().reliability(sided="three"), ["reliability", GANTRY, "--sided", "three"],
     "`three` is not a side: choose one of upper, two"),
    ("system", lambda: _gantry().reliability(system="parallel"), ["reliability", GANTRY, "--system", "parallel"],
     "`parallel` is not a system target: choose one of series, volumetric"),
    ("controller", lambda: _vmc3().export(VALUES, controller="fanuc"),
     ["export", VMC3, "--values", VALUES, "--controller", "fanuc"],
     "`fanuc` is not a controller: choose one of grid, beckhoff, linuxcnc, siemens-cec, klipper, linuxcnc-trt, heidenhain, siemens-carr, fanuc-tcp, siemens-thermal, linuxcnc-thermal, beckhoff-thermal, heidenhain-thermal, klipper-thermal"),
    ("frame", lambda: _vmc3().derive("base"), ["derive", VMC3, "--frame", "base"],
     "`base` is not a frame: choose one of tool, workpiece"),
    ("kind", lambda: chain.Machine.load(PROBE).plan(CANDIDATES, 40, kind="line"),
     ["plan", PROBE, "--candidates", CANDIDATES, "--count", 40, "--kind", "line"],
     "`line` is not a measurement kind: choose one of point, direction"),
    ("select", lambda: chain.compensate(SWING, length=577.11, select="best"),
     ["compensate", SWING, "--length", "577.11", "--select", "best"],
     "`best` is not a selection rule: choose one of loocv, adjusted-r2, aicc, bic"),
    ("strategy", lambda: _gantry().allocate(strategy="cheapest"), ["allocate", GANTRY, "--strategy", "cheapest"],
     "`cheapest` is not a strategy: choose one of optimal, paper"),
    ("rank", lambda: _gantry().allocate(rank="total"), ["allocate", GANTRY, "--rank", "total"],
     "`total` is not a ranking: choose one of component, pooled"),
    ("target", lambda: _gantry().allocate(target="cost"), ["allocate", GANTRY, "--target", "cost"],
     "`cost` is not an allocation target: choose one of requirement, acceptance"),
    ("param unknown", lambda: _vmc3().map(VALUES, grid={"x": [0.0]}, params={"l": 1.0}),
     ["map", VMC3, "--values", VALUES, "--grid", "x=0", "--param", "l=1"],
     "--param l: machine `vmc3` has no parameter `l` (did you mean `L`?)"),
    ("param not finite", lambda: _vmc3().map(VALUES, grid={"x": [0.0]}, params={"L": math.nan}),
     ["map", VMC3, "--values", VALUES, "--grid", "x=0", "--param", "L=nan"],
     "--param L: NaN is not finite"),
    ("grid with rows", lambda: _vmc3().map(VALUES, grid={"x": [0.0]}, points=[[0.0, 0.0, 0.0]]),
     ["map", VMC3, "--values", VALUES, "--grid", "x=0", "--axes", AXES],
     "--grid cannot be combined with --axes"),
]


@pytest.mark.parametrize("call,args,words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_rule_is_refused_in_one_wording(call, args, words, cli_error):
    with pytest.raises(ValueError) as info:
        call()
    assert words in str(info.value)
    assert flat(words) in flat(cli_error(*args))
