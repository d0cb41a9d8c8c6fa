"""Every command of the CLI, one parametrised test: the Python binding's ``to_dict()`` equals
``chain <command> ... --format json`` on the same example input (issue 31: one application layer,
``chain::ops``, under both)."""

import numpy as np
import pytest

import chain
from conftest import ROOT

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
]


@pytest.mark.parametrize("command,call,args", CASES, ids=[c[0] for c in CASES])
def test_every_command_is_the_cli_json(command, call, args, cli, tmp_path):
    got = call()
    assert got.command == command
    argv = [str(a).replace("{tmp}", str(tmp_path)) for a in args]
    assert got.to_dict() == cli(command.split()[0], *argv)
