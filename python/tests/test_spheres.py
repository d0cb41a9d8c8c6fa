"""Sphere probing and the R-test in Python (five-axis spec; docs/five-axis.md):
Machine.identify(spheres=...) as a path, CSV text or columns gives the CLI's
JSON, and refuses a bad sphere file in the CLI's words, located."""

import json
import pathlib

import pytest

import chain
from conftest import flat

ROOT = pathlib.Path(__file__).resolve().parents[2]
MACHINE = ROOT / "examples" / "machines" / "ac_trunnion_rotary.yaml"
PROBING = ROOT / "examples" / "spheres" / "probing.csv"
RTEST = ROOT / "examples" / "spheres" / "rtest.csv"


def _cli_doc(cli, *args):
    return cli("identify", MACHINE, *args)


def test_spheres_from_a_path_text_and_columns_equal_the_cli(cli):
    m = chain.Machine.load(MACHINE)
    want = _cli_doc(cli, "--spheres", PROBING)
    got = m.identify(spheres=PROBING).to_dict()
    assert got == want
    # Every location error and both spheres, estimated.
    assert want["rank"] == want["parameters"] == 14
    assert [s["name"] for s in want["setups"]] == ["low", "high"]
    # As CSV text and as columns (the sphere identifiers as text): the same
    # estimates (the file is named differently).
    text = PROBING.read_text()
    by_text = m.identify(spheres=text, name=str(PROBING)).to_dict()
    assert by_text == want
    rows = [line.split(",") for line in text.splitlines()]
    header, body = rows[0], rows[1:]
    columns = {h: [r[k] if h == "sphere" else float(r[k]) for r in body] for k, h in enumerate(header)}
    by_columns = m.identify(spheres=columns).to_dict()
    for name, e in want["estimates"].items():
        assert by_columns["estimates"][name]["value"] == pytest.approx(e["value"], rel=1e-9, abs=1e-12)
    assert by_columns["setups"][1]["name"] == "high"


def test_an_r_test_with_its_ball_equals_the_cli(cli):
    m = chain.Machine.load(MACHINE)
    want = _cli_doc(cli, "--measurements", RTEST, "--setup", "ball")
    assert m.identify(RTEST, setup="ball").to_dict() == want
    ball = want["setups"][0]
    assert ball["kind"] == "ball"
    # The generator's set-up offset (examples/spheres/README.md), within 3 std.
    for got, truth, sd in zip(ball["position"], (0.05, -0.03, 0.02), ball["std"]):
        assert abs(got - truth) < 3 * sd


def test_bad_sphere_files_and_options_are_refused_in_the_cli_words(cli_error):
    m = chain.Machine.load(MACHINE)
    text = PROBING.read_text().replace("sphere,A,C", "spere,A,C", 1)
    with pytest.raises(chain.MachineError) as info:
        m.identify(spheres=text, name="typo.csv")
    e = info.value
    assert (e.file, e.line, e.column, e.key) == ("typo.csv", 1, 1, "spere")
    assert "column `spere` is neither an axis variable" in str(e)
    with pytest.raises(ValueError) as info:
        m.identify(spheres=PROBING, setup="ball")
    assert str(info.value).startswith("--setup: the spheres of --spheres are already set-ups")
    message = str(info.value).split("\nhelp: ")[0]
    assert message in flat(cli_error("identify", MACHINE, "--spheres", PROBING, "--setup", "ball"))
    with pytest.raises(ValueError, match="^`bal` is not a set-up: choose one of ball$"):
        m.identify(RTEST, setup="bal")
    with pytest.raises(ValueError, match="or a sphere-probing CSV"):
        m.identify()


def test_plan_over_sphere_candidates_equals_the_cli(cli):
    m = chain.Machine.load(MACHINE)
    want = cli("plan", MACHINE, "--spheres-candidates", PROBING, "--count", 8)
    got = m.plan(PROBING, 8, spheres=True, name=str(PROBING)).to_dict()
    assert got == want
    assert len(want["errors"]) == want["rank"] == 14
