"""Machine.path: `chain path` over arrays, through chain::ops::path (the CLI's request, checks and document)."""

import numpy as np
import pytest

import chain
from conftest import ROOT, flat


def _csv(path):
    with open(path) as f:
        rows = [line.strip() for line in f if line.strip() and not line.startswith("#")]
    header = rows[0].split(",")
    return header, np.array([[float(v) for v in r.split(",")] for r in rows[1:]])


def test_path_axes_is_the_cli_json(cli):
    """Axis values as a mapping (any column order, `t` first) and as an (N, V) array equal `chain path --axes`."""
    machine = ROOT / "examples/paths/cnc5_bevel_stats.yaml"
    axes_file = ROOT / "examples/paths/cnc5_bevel_axes.csv"
    header, values = _csv(axes_file)
    m = chain.Machine.load(machine)
    want = cli("path", machine, "--axes", axes_file)
    got = m.path(axes={h: values[:, k] for k, h in enumerate(header)})
    assert got.to_dict() == want
    # The same rows as an array in the machine's variable order, `t` given apart.
    order = [header.index(v) for v in m.variables]
    again = m.path(axes=values[:, order], t=values[:, 0])
    assert again.to_dict() == want
    frame = got.to_dataframe() if _pandas() else None
    if frame is not None:
        assert list(frame["row"]) == list(range(1, len(values) + 1))
    # Sampling with a seed: the same numbers as the CLI's.
    mc = m.path(axes={h: values[:, k] for k, h in enumerate(header)}, method="mc", samples=2000, seed=3)
    assert mc.to_dict() == cli("path", machine, "--axes", axes_file, "--method", "mc", "--samples", 2000,
                               "--seed", 3)


def test_path_poses_is_the_cli_json(cli):
    """Tool poses solved by the inverse kinematics equal `chain path --pose`."""
    machine = ROOT / "examples/paths/cnc5_bevel_stats.yaml"
    pose_file = ROOT / "examples/paths/cnc5_bevel_pose.csv"
    _, values = _csv(pose_file)
    m = chain.Machine.load(machine)
    got = m.path(poses=values[:, 1:], t=values[:, 0], fix={"mu": 0.0}, system="volumetric")
    assert got.to_dict() == cli("path", machine, "--pose", pose_file, "--fix", "mu=0", "--system", "volumetric")
    assert got.input == "pose"


def _pandas():
    try:
        import pandas  # noqa: F401
    except ImportError:
        return False
    return True


def test_path_refusals_are_the_cli_s(cli_error, tmp_path):
    """A bad column, a column held by fix, a missing variable: the CLI's message, word for word."""
    machine = ROOT / "examples/paths/cnc5_bevel_stats.yaml"
    m = chain.Machine.load(machine)
    n = {v: np.zeros(2) for v in m.variables}
    bad = dict(n, xx=np.zeros(2))
    with pytest.raises(ValueError) as info:
        m.path(axes=bad)
    csv = tmp_path / "axes.csv"
    csv.write_text(",".join(bad) + "\n" + ",".join("0" for _ in bad) + "\n")
    message = str(info.value)
    assert message.startswith("axes:1: column `xx` is not an axis variable of machine")
    assert flat(message.replace("axes:1:", f"{csv}:1:", 1)) in flat(cli_error("path", machine, "--axes", csv))
    with pytest.raises(ValueError, match="variable `mu` has a column and a --fix value"):
        m.path(axes=n, fix={"mu": 0.0})
    with pytest.raises(ValueError, match="no column for axis variable `mu`; add the column or hold it with --fix"):
        m.path(axes={k: v for k, v in n.items() if k != "mu"})
    with pytest.raises(ValueError, match="give the path as axes=... or poses=..."):
        m.path()
    with pytest.raises(ValueError, match="FORM draws no samples"):
        m.path(axes=n, cov=0.1)
    with pytest.raises(ValueError, match="axes has a non-finite value"):
        m.path(axes=dict(n, x=np.array([0.0, np.nan])))
    with pytest.raises(ValueError) as info:
        m.path(axes=n, params={"nope": 1.0})
    assert str(info.value) == "--param nope: machine `cnc5_bevel_stats` has no parameter `nope`"
    assert str(info.value) in flat(cli_error("path", machine, "--axes", ROOT / "examples/paths/cnc5_bevel_axes.csv",
                                             "--param", "nope=1"))


def test_path_and_inverse_read_the_files_the_cli_reads(cli, cli_error, tmp_path):
    """A CSV path where the CLI reads a file: the same document, and the same words when refused
    (the reader is `chain::ops::tables` for both)."""
    machine = ROOT / "examples/paths/cnc5_bevel_stats.yaml"
    axes_file = ROOT / "examples/paths/cnc5_bevel_axes.csv"
    pose_file = ROOT / "examples/paths/cnc5_bevel_pose.csv"
    m = chain.Machine.load(machine)
    assert m.path(axes=axes_file).to_dict() == cli("path", machine, "--axes", axes_file)
    assert m.path(axes=str(axes_file), method="mc", samples=500, seed=2).to_dict() == cli(
        "path", machine, "--axes", axes_file, "--method", "mc", "--samples", 500, "--seed", 2)
    got = m.path(poses=pose_file, fix={"mu": 0.0})
    assert got.to_dict() == cli("path", machine, "--pose", pose_file, "--fix", "mu=0")
    assert got.input == "pose"
    assert m.inverse(pose_file, fix={"mu": 0.0}).to_dict() == cli("inverse", machine, "--pose", pose_file,
                                                                  "--fix", "mu=0")
    # Refusals: a cell that is not a number, a pose header, a pose that is not one, a missing file,
    # a column that names no axis variable.
    bad_cell = tmp_path / "cell.csv"
    bad_cell.write_text("t,x,y,z\n0,0,0,0\n1,0,zz,0\n")
    bad_header = tmp_path / "header.csv"
    bad_header.write_text("px,py,pz,i,j\n0,0,0,0,1\n")
    bad_pose = tmp_path / "pose.csv"
    bad_pose.write_text("px,py,pz,i,j,k\n0,0,0,0,0,0\n")
    bad_column = tmp_path / "column.csv"
    bad_column.write_text("t,x,y,zz\n0,0,0,0\n")
    missing = tmp_path / "missing.csv"
    for call, args in [
        (lambda: m.path(axes=bad_cell), ["path", machine, "--axes", bad_cell]),
        (lambda: m.path(poses=bad_header), ["path", machine, "--pose", bad_header]),
        (lambda: m.inverse(bad_header), ["inverse", machine, "--pose", bad_header]),
        (lambda: m.inverse(bad_pose), ["inverse", machine, "--pose", bad_pose]),
        (lambda: m.inverse(missing), ["inverse", machine, "--pose", missing]),
        (lambda: m.path(axes=bad_column), ["path", machine, "--axes", bad_column]),
    ]:
        with pytest.raises(ValueError) as info:
            call()
        # Compared without white space: miette wraps long paths mid-name.
        bare = "".join(flat(str(info.value)).split())
        assert bare in "".join(flat(cli_error(*args)).split()), args
    with pytest.raises(ValueError, match="t=... is given with a file"):
        m.path(axes=axes_file, t=[0.0])
