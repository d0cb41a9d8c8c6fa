"""Machine.export: `chain export` through chain::ops::export (the CLI's request, checks and document)."""

import numpy as np
import pytest

import chain
from conftest import ROOT, flat

MACHINE = ROOT / "examples/machines/vmc3.yaml"
VALUES = ROOT / "examples/values/vmc3.yaml"


@pytest.mark.parametrize("controller", ["grid", "beckhoff", "linuxcnc", "siemens-cec", "klipper"])
def test_export_is_the_cli_s(cli, controller, tmp_path):
    """The summary equals `chain export --format json`; the files equal the committed examples
    (examples/export/, which tests/it/commands/export_controllers.rs regenerates from the
    library)."""
    m = chain.Machine.load(MACHINE)
    got = m.export(VALUES, controller=controller, params={"L": 150}, out=tmp_path / "out")
    want = cli("export", MACHINE, "--values", VALUES, "--controller", controller, "--param", "L=150")
    assert got.to_dict() == want
    expected = sorted(p.name for p in (ROOT / "examples/export" / controller).iterdir())
    assert sorted(got.files) == expected
    for name, text in got.files.items():
        assert text == (ROOT / "examples/export" / controller / name).read_text()
        assert (tmp_path / "out" / name).read_text() == text
    if controller == "grid":
        frame = got._rows()
        assert len(frame) == got.summary["nodes"]
        assert set(m.variables) <= set(frame[0])


@pytest.mark.parametrize("controller,files,module,angles", [
    ("linuxcnc-trt", ["xyzac-trt-kins-README.txt", "xyzac-trt-kins.hal"], "xyzac-trt-kins", False),
    ("heidenhain", ["KINEMATICS_ROTARY-README.txt", "KINEMATICS_ROTARY.TAB"],
     "kinematics description (Trans rows of the rotary axes)", False),
    ("heidenhain", ["KINEMATICS_ROTARY-README.txt", "KINEMATICS_ROTARY.TAB"],
     "kinematics description (Trans rows of the rotary axes)", True),
    ("siemens-carr", ["TC_CARR.SPF"], "$TC_CARR (type P)", False),
    ("fanuc-tcp", ["TCP-README.txt", "TCP.PRM"], "tool centre point control, table rotation type (19680 = 12)", False),
])
def test_rotary_export_is_the_cli_s(cli, cli_error, tmp_path, controller, files, module, angles):
    """The rotary formats from the sphere example's true location errors: the CLI's JSON and files."""
    machine = ROOT / "examples/machines/ac_trunnion_rotary.yaml"
    values = ROOT / "examples/spheres/truth.yaml"
    tau = 6.283185307179586
    grid = {"x": [-100.0, 100.0], "y": [-100.0, 100.0], "z": [-100.0, 0.0], "A": [-1.0, 1.0], "C": [0.0, tau]}
    got = chain.Machine.load(machine).export(values, controller=controller, grid=grid, out=tmp_path / "out",
                                             angles=angles)
    args = [a for k, v in grid.items() for a in ("--grid", f"{k}={v[0]!r},{v[1]!r}")]
    args += ["--angles"] if angles else []
    assert got.to_dict() == cli("export", machine, "--values", values, "--controller", controller, *args)
    assert got.to_dict()["kinematics"]["module"] == module
    assert sorted(got.files) == files
    for name, text in got.files.items():
        assert (tmp_path / "out" / name).read_text() == text
    if controller != "heidenhain":
        with pytest.raises(ValueError) as info:
            chain.Machine.load(machine).export(values, controller=controller, grid=grid, angles=True)
        assert flat(str(info.value)) in flat(cli_error("export", machine, "--values", values, "--controller",
                                                       controller, *args, "--angles"))
    with pytest.raises(ValueError, match="angles must be True or False"):
        chain.Machine.load(machine).export(values, controller=controller, grid=grid, angles=1)
    with pytest.raises(ValueError) as info:
        chain.Machine.load(MACHINE).export(VALUES, controller=controller, params={"L": 150})
    assert "takes a table-table five-axis machine" in flat(str(info.value))
    assert flat(str(info.value)) in flat(cli_error("export", MACHINE, "--values", VALUES, "--controller",
                                                   controller, "--param", "L=150"))


def test_beckhoff_rotary_terms_are_the_cli_s(cli):
    """Beckhoff's volumetric tables of the A/C trunnion, rotary terms included: the CLI's JSON and files."""
    machine = ROOT / "examples/machines/ac_trunnion_rotary.yaml"
    values = ROOT / "examples/spheres/identified.yaml"
    grid = {"x": [-100.0, 100.0], "y": [-100.0, 100.0], "z": [-100.0, 0.0],
            "A": [-1.0471975511965976, 1.0471975511965976], "C": [0.0, 6.283185307179586]}
    got = chain.Machine.load(machine).export(values, controller="beckhoff", grid=grid)
    args = [a for k, v in grid.items() for a in ("--grid", f"{k}={v[0]!r},{v[1]!r}")]
    assert got.to_dict() == cli("export", machine, "--values", values, "--controller", "beckhoff", *args)
    assert [a["axis"] for a in got.to_dict()["axes"]] == ["Y", "A", "C", "X", "Z"]
    for name, text in got.files.items():
        assert text == (ROOT / "examples/spheres/beckhoff" / name).read_text()
    assert "chain                    CAYXZ" in got.files["vol_comp_0.lis"]


def test_export_points_and_refusals(cli_error, tmp_path):
    """Nodes from rows (`--axes`); options a controller does not take and values outside a table: the CLI's words."""
    m = chain.Machine.load(MACHINE)
    q = np.array([[100.0, 50.0, 20.0], [200.0, 60.0, 30.0]])
    got = m.export(VALUES, points=q, params={"L": 150})
    assert got.summary["nodes"] == 2
    with pytest.raises(ValueError) as info:
        m.export(VALUES, controller="grid", step=5.0, params={"L": 150})
    message = str(info.value)
    assert message.startswith("--controller grid does not take --step\nhelp: the grid export corrects")
    cli = flat(cli_error("export", MACHINE, "--values", VALUES, "--controller", "grid", "--step", "5"))
    assert flat(message) in cli
    with pytest.raises(ValueError, match="--controller linuxcnc does not take --axes"):
        m.export(VALUES, controller="linuxcnc", points=q, params={"L": 150})
    with pytest.raises(ValueError) as info:
        m.export(VALUES, controller="fanuc")
    wording = "`fanuc` is not a controller: choose one of grid, beckhoff, linuxcnc, siemens-cec, klipper, linuxcnc-trt, heidenhain, siemens-carr, fanuc-tcp, siemens-thermal, linuxcnc-thermal, beckhoff-thermal, heidenhain-thermal, klipper-thermal"
    assert str(info.value) == wording
    assert wording in flat(cli_error("export", MACHINE, "--values", VALUES, "--controller", "fanuc"))
    with pytest.raises(ValueError) as info:
        m.export(VALUES, grid={"x": [0.0]}, points=q, params={"L": 150})
    assert str(info.value).startswith("--grid cannot be combined with --axes\nhelp: --axes gives the points")
    with pytest.raises(ValueError) as info:
        m.export(VALUES, controller="linuxcnc", grid={"x": [0, 900]}, params={"L": 150})
    message = str(info.value)
    assert "covers" in message and "nothing is extrapolated" in message
    cli = flat(cli_error("export", MACHINE, "--values", VALUES, "--controller", "linuxcnc", "--grid", "x=0,900",
                         "--param", "L=150"))
    assert flat(message) in cli
