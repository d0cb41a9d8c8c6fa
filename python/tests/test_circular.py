"""chain.circular returns `chain circular --format json` for the same run file (a path, its text or
its columns), and refuses what the CLI refuses with its words."""

import math
import pathlib

import numpy as np
import pytest

import chain
from conftest import flat


def _runs(tmp_path):
    """Two directions at R = 100 mm: an ellipse 3 µm · sin 2θ about an offset of 5 µm along the first
    axis, the clockwise path 1 µm outside (µm)."""
    lines = ["angle,direction,deviation(um)"]
    for d in ("ccw", "cw"):
        for k in range(360):
            t = k if d == "ccw" else 360 - k
            r = 3 * math.sin(2 * math.radians(t)) + 5 * math.cos(math.radians(t)) + (1 if d == "cw" else 0)
            lines.append(f"{t},{d},{r:.6f}")
    path = tmp_path / "runs.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def test_circular_is_the_cli_json(cli, tmp_path):
    path = _runs(tmp_path)
    r = chain.circular(path, radius=100, feed=1000)
    want = cli("circular", path, "--radius", 100, "--feed", 1000)
    assert r.command == "circular"
    assert r.to_dict() == want
    run = want["runs"][0]
    assert abs(run["directions"]["ccw"]["G"] - 0.006) < 1e-6 and abs(run["H"] - 0.001) < 1e-6
    # The text and the columns give the same document, named as asked.
    text = path.read_text()
    assert chain.circular(text=text, name=str(path), radius=100, feed=1000).to_dict() == want
    rows = [line.split(",") for line in text.splitlines()[1:]]
    columns = {
        "angle": np.array([float(a) for a, _, _ in rows]),
        "direction": [d for _, d, _ in rows],
        "deviation(um)": np.array([float(v) for _, _, v in rows]),
    }
    by_columns = chain.circular(columns, radius=100, feed=1000).to_dict()
    assert by_columns["runs"] == want["runs"]
    frame = r.to_dataframe()
    assert list(frame["direction"]) == ["ccw", "cw"] and list(frame["G"]) == [
        run["directions"]["ccw"]["G"],
        run["directions"]["cw"]["G"],
    ]


def test_refusals_are_the_cli_s(cli_error, tmp_path):
    path = _runs(tmp_path)
    with pytest.raises(chain.MachineError) as e:
        chain.circular(path)
    assert "run 1 has no radius" in flat(str(e.value))
    assert "run 1 has no radius" in flat(cli_error("circular", path))
    with pytest.raises(ValueError) as e:
        chain.circular(path, radius=100, arc=400)
    assert "--arc 400: must be in [45, 360] degrees" in str(e.value)
    assert "--arc 400: must be in [45, 360] degrees" in flat(cli_error("circular", path, "--radius", 100, "--arc", 400))
    with pytest.raises(ValueError):
        chain.circular(path, text="angle\n", radius=100)


def test_the_diagnosis_is_the_cli_s(cli, cli_error, tmp_path):
    """The ellipse 3 µm · sin 2θ in both directions is squareness 2·3 µm / 100 mm = 60 µrad
    (docs/circular.md, "Squareness S"); --pitch and --window as the CLI's."""
    path = _runs(tmp_path)
    r = chain.circular(path, radius=100, feed=1000, pitch={"x": 10.0}, window=3)
    want = cli("circular", path, "--radius", 100, "--feed", 1000, "--pitch", "x=10", "--window", 3)
    assert r.to_dict() == want
    square = [e for e in r.diagnosis if e["error"] == "squareness"]
    assert len(square) == 1 and abs(square[0]["value"] - 60.0) < 0.05, square
    assert square[0]["unit"] == "urad" and square[0]["axes"] == ["x", "y"]
    assert r.fit[0]["window"] == 3
    assert any(e["error"] == "cyclic_error" and e["axes"] == ["x"] for e in r.diagnosis)
    frame = r.diagnosis_frame()
    assert list(frame["error"]) == [e["error"] for e in want["diagnosis"]]
    assert list(frame["value"]) == [e["value"] for e in want["diagnosis"]]
    with pytest.raises(ValueError) as e:
        chain.circular(path, radius=100, pitch={"w": 5})
    assert "--pitch w=5: the axis must be x, y or z" in str(e.value)
    assert "--pitch w=5: the axis must be x, y or z" in flat(cli_error("circular", path, "--radius", 100, "--pitch", "w=5"))
    with pytest.raises(ValueError) as e:
        chain.circular(path, radius=100, window=50)
    assert "--window 50: must be more than 0 and less than 45 degrees" in str(e.value)


def test_identify_circular_is_the_cli_s(cli, cli_error):
    """Machine.identify(circular=...) gives `chain identify --circular` (each sample along the
    ball-to-ball direction, each run's table ball and bar length estimated), and refuses what the
    CLI refuses with its words."""
    root = pathlib.Path(__file__).resolve().parents[2]
    machine = root / "examples" / "machines" / "vmc3.yaml"
    runs = root / "examples" / "circular" / "runs.csv"
    m = chain.Machine.load(machine)
    want = cli("identify", machine, "--circular", runs, "--centre", "x=400,y=250,z=250")
    got = m.identify(circular=runs, centre={"x": 400, "y": 250, "z": 250}).to_dict()
    assert got == want
    assert [s["kind"] for s in want["setups"]] == ["circle"] * 6
    assert want["setups"][0]["unknowns"] == ["circle xy_f1000.x", "circle xy_f1000.y", "circle xy_f1000.length"]
    with pytest.raises(ValueError) as e:
        m.identify(circular=runs)
    words = "--circular: give the circle's centre (--centre NAME=VALUE,...) or each sample's pose"
    assert flat(str(e.value)).startswith(words)
    assert words in flat(cli_error("identify", machine, "--circular", runs))
    with pytest.raises(ValueError) as e:
        m.identify(circular=runs, centre={"w": 1})
    assert "--centre: the circle's centre names `w`" in str(e.value)
