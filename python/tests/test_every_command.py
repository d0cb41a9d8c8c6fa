"""Every command of the CLI, one parametrised test: the Python binding's ``to_dict()`` equals
``chain <command> ... --format json`` on the same example input (one application layer,
``chain::ops``, under both)."""

import numpy as np
import pytest

import chain
from conftest import ROOT, squeezed

EX = ROOT / "examples"
GANTRY = EX / "machines/gantry_grinder.yaml"
VMC3 = EX / "machines/vmc3.yaml"
VALUES = EX / "values/vmc3.yaml"
PROBE = EX / "measurements/vmc3_probe.yaml"
BEVEL = EX / "paths/cnc5_bevel_stats.yaml"


def _csv(path):
    rows = [line.strip() for line in path.read_text().splitlines() if line.strip() and not line.startswith("#")]
    return rows[0].split(","), np.array([[float(v) for v in r.split(",")] for r in rows[1:]])


def _path_axes():
    header, values = _csv(EX / "paths/cnc5_bevel_axes.csv")
    return {h: values[:, k] for k, h in enumerate(header)}


def _poses():
    _, values = _csv(EX / "paths/cnc5_bevel_pose.csv")
    return values[:, 1:]


# (command, the Python call, the CLI's arguments after the command)
CASES = [
    ("derive", lambda: chain.Machine.load(VMC3).derive("tool"), [VMC3, "--frame", "tool"]),
    ("reliability", lambda: chain.Machine.load(GANTRY).reliability(method="mc", samples=500, seed=4),
     [GANTRY, "--method", "mc", "--samples", 500, "--seed", 4]),
    ("sensitivity", lambda: chain.Machine.load(GANTRY).sensitivity_reliability(), [GANTRY]),
    ("sensitivity --kind geometric", lambda: chain.Machine.load(GANTRY).geometric_sensitivity(),
     [GANTRY, "--kind", "geometric"]),
    ("sobol", lambda: chain.Machine.load(GANTRY).sobol(samples=300, seed=2, bootstrap=10),
     [GANTRY, "--samples", 300, "--seed", 2, "--bootstrap", 10]),
    ("allocate", lambda: chain.Machine.load(GANTRY).allocate(), [GANTRY]),
    ("map", lambda: chain.Machine.load(VMC3).map(VALUES, grid={"x": [0, 400, 800]}),
     [VMC3, "--values", VALUES, "--grid", "x=0,400,800"]),
    ("path", lambda: chain.Machine.load(BEVEL).path(axes=_path_axes()),
     [BEVEL, "--axes", EX / "paths/cnc5_bevel_axes.csv"]),
    ("export", lambda: chain.Machine.load(VMC3).export(VALUES, controller="linuxcnc"),
     [VMC3, "--values", VALUES, "--controller", "linuxcnc", "--out", "{tmp}"]),
    ("inverse", lambda: chain.Machine.load(BEVEL).inverse(_poses()),
     [BEVEL, "--pose", EX / "paths/cnc5_bevel_pose.csv"]),
    ("motion", lambda: chain.Machine.load(EX / "machines/cnc5_bevel.yaml").motion(
        EX / "settings/seed002_convex.yaml", samples=40),
     [EX / "machines/cnc5_bevel.yaml", "--settings", EX / "settings/seed002_convex.yaml", "--samples", 40]),
    ("identify", lambda: chain.Machine.load(PROBE).identify(EX / "measurements/ballplate.csv"),
     [PROBE, "--measurements", EX / "measurements/ballplate.csv"]),
    ("plan", lambda: chain.Machine.load(PROBE).plan(EX / "measurements/candidates.csv", k=20),
     [PROBE, "--candidates", EX / "measurements/candidates.csv", "--count", 20]),
    ("compensate", lambda: chain.compensate(EX / "data/swing_htm50200.csv", length=577.11),
     [EX / "data/swing_htm50200.csv", "--length", "577.11"]),
    ("positioning", lambda: chain.positioning(EX / "positioning/x_axis_runs.csv"),
     [EX / "positioning/x_axis_runs.csv"]),
    ("circular", lambda: chain.circular(EX / "circular/runs.csv"), [EX / "circular/runs.csv"]),
    ("report", lambda: chain.report(EX / "calibration/vmc3.yaml"), [EX / "calibration/vmc3.yaml"]),
]


@pytest.mark.parametrize("command,call,args", CASES, ids=[c[0] for c in CASES])
def test_every_command_is_the_cli_json(command, call, args, cli, tmp_path):
    got = call()
    assert got.command == command
    argv = [str(a).replace("{tmp}", str(tmp_path)) for a in args]
    assert got.to_dict() == cli(command.split()[0], *argv)


def _bad_machine(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(
        "machine: m\nbodies:\n  bed: {}\n"
        "  s: {parent: bed, joint: {type: prismatic, axis: +x, variable: x}, bogus: 1}\n"
        "workpiece: bed\ntool: s\n"
    )
    return path


def _bad_calibration(tmp_path):
    path = tmp_path / "calibration.yaml"
    path.write_text(f"machine: {VMC3}\ncustomr: X\n")
    return path


def _x_only(tmp_path):
    path = tmp_path / "x_only.csv"
    path.write_text("x\n0\n100\n")
    return path


# (command, the Python call that must fail, the CLI's arguments after the command, the exception,
# words both say). One refusal per command, reaching chain::ops (or the loader) from both sides.
BAD = [
    ("derive", lambda t: chain.Machine.load(_bad_machine(t)), lambda t: [_bad_machine(t)],
     chain.MachineError, "unknown key `bogus` at key `bodies.s.bogus`"),
    ("reliability", lambda t: chain.Machine.load(GANTRY).reliability(grid={"w": [0.0]}),
     lambda t: [GANTRY, "--grid", "w=0"], chain.MachineError, "unknown axis variable `w` (did you mean `x`?)"),
    ("sensitivity", lambda t: chain.Machine.load(GANTRY).sensitivity_reliability(at={"x": 0.0}),
     lambda t: [GANTRY, "--at", "x=0"], ValueError, "--at has no value for axis variable `z`"),
    ("sensitivity --kind geometric", lambda t: chain.Machine.load(GANTRY).geometric_sensitivity(params={"nope": 1.0}),
     lambda t: [GANTRY, "--kind", "geometric", "--param", "nope=1"], ValueError,
     "--param nope: machine `gantry_grinder` has no parameter `nope`"),
    ("sobol", lambda t: chain.Machine.load(GANTRY).sobol(samples=1), lambda t: [GANTRY, "--samples", 1],
     ValueError, "--samples 1: must be at least 2"),
    ("allocate", lambda t: chain.Machine.load(GANTRY).allocate(level=0.5), lambda t: [GANTRY, "--level", 0.5],
     ValueError, "`--level` applies to `--target acceptance` only"),
    ("map", lambda t: chain.Machine.load(VMC3).map(VALUES, grid={"xx": [0.0]}),
     lambda t: [VMC3, "--values", VALUES, "--grid", "xx=0"], chain.MachineError, "unknown axis variable `xx`"),
    ("path", lambda t: chain.Machine.load(GANTRY).path(axes={"x": [0.0, 100.0]}),
     lambda t: [GANTRY, "--axes", _x_only(t)], ValueError, "no column for axis variables `z`, `y`"),
    ("export", lambda t: chain.Machine.load(VMC3).export(VALUES, controller="grid", step=5.0),
     lambda t: [VMC3, "--values", VALUES, "--controller", "grid", "--step", 5], ValueError,
     "--controller grid does not take --step"),
    ("inverse", lambda t: chain.Machine.load(BEVEL).inverse(_poses(), params={"nope": 1.0}),
     lambda t: [BEVEL, "--pose", EX / "paths/cnc5_bevel_pose.csv", "--param", "nope=1"], ValueError,
     "--param nope: machine `cnc5_bevel_stats` has no parameter `nope`"),
    ("motion", lambda t: chain.Machine.load(EX / "machines/cnc5_bevel.yaml").motion(
        EX / "settings/seed002_convex.yaml", samples=1),
     lambda t: [EX / "machines/cnc5_bevel.yaml", "--settings", EX / "settings/seed002_convex.yaml", "--samples", 1],
     ValueError, "--samples 1 must be between 2 and 1000000"),
    ("identify", lambda t: chain.Machine.load(PROBE).identify(EX / "measurements/ballplate.csv", params={"nope": 1.0}),
     lambda t: [PROBE, "--measurements", EX / "measurements/ballplate.csv", "--param", "nope=1"], ValueError,
     "--param nope: machine `vmc3_probe` has no parameter `nope`"),
    ("plan", lambda t: chain.Machine.load(PROBE).plan(EX / "measurements/candidates.csv", k=1),
     lambda t: [PROBE, "--candidates", EX / "measurements/candidates.csv", "--count", 1], ValueError,
     "1 candidates give 3 design rows"),
    ("compensate", lambda t: chain.compensate(EX / "data/swing_htm50200.csv", length=-1.0),
     lambda t: [EX / "data/swing_htm50200.csv", "--length", "-1"], ValueError,
     "--length must be a positive number of millimetres"),
    ("positioning", lambda t: chain.positioning(EX / "positioning/x_axis_runs.csv", k=0.0),
     lambda t: [EX / "positioning/x_axis_runs.csv", "--k", "0"], ValueError,
     "the coverage factor k must be a finite number > 0, not 0"),
    ("circular", lambda t: chain.circular(EX / "circular/runs.csv", arc=0.0),
     lambda t: [EX / "circular/runs.csv", "--arc", "0"], ValueError, "--arc 0: must be in [45, 360] degrees"),
    ("report", lambda t: chain.report(_bad_calibration(t)), lambda t: [_bad_calibration(t)], chain.MachineError,
     "unknown key `customr`"),
]


@pytest.mark.parametrize("command,call,args,kind,words", BAD, ids=[c[0] for c in BAD])
def test_every_command_refuses_with_the_cli_message(command, call, args, kind, words, cli_error, tmp_path):
    """A bad input raises the CLI's message and help, word for word (the source's name aside: Python
    names an array or a mapping where the CLI names its file)."""
    with pytest.raises(kind) as info:
        call(tmp_path)
    message = str(info.value)
    assert words in message
    if command == "path":
        message = message.split(": ", 1)[1]
    # Squeezed: miette wraps long lines, inside a path too.
    assert squeezed(message) in squeezed(cli_error(command.split()[0], *args(tmp_path)))
