"""`Machine.allocate` (`chain allocate`): each document equal to the CLI's `--format json` for the
same input on the example machines with a requirement; the allocated standard deviations
re-evaluated independently (a posterior values file through `Machine.reliability`); bad options
refused naming the keyword; a refused allocation located as the CLI locates it."""

import re

import pytest

import chain
from conftest import MACHINES, ROOT, flat, squeezed

WITH_REQUIREMENT = [p for p in MACHINES if "requirement:" in p.read_text() and "\nstatistics:" in p.read_text()]
IDS = [p.stem for p in WITH_REQUIREMENT]
GANTRY = ROOT / "examples/machines/gantry_grinder.yaml"


@pytest.mark.parametrize("path", WITH_REQUIREMENT, ids=IDS)
@pytest.mark.parametrize("strategy", ["optimal", "paper"])
def test_allocation_is_the_cli_json(path, strategy, cli):
    a = chain.Machine.load(path).allocate(strategy=strategy)
    assert a.to_dict() == cli("allocate", path, "--strategy", strategy)
    assert a.strategy == strategy and a.final["met"]
    rows = a.to_dataframe()
    assert list(rows["error"]) == list(a.initial["std"])
    assert (rows["ratio"] >= 1 - 1e-12).all()


def test_paper_options_are_the_cli_json(cli):
    m = chain.Machine.load(GANTRY)
    a = m.allocate(strategy="paper", step=0.01, threshold=0.2, rank="pooled")
    assert a.to_dict() == cli("allocate", GANTRY, "--strategy", "paper", "--step", 0.01, "--threshold", 0.2,
                              "--rank", "pooled")
    # Table 5's first round (Wang & Yuan 2021): px mean reliability 93.66 %, 7 errors tightened.
    b = m.allocate(strategy="paper")
    assert b.steps[0]["summary"]["px"]["mean"] * 100 == pytest.approx(93.66, abs=0.1)
    assert len(b.steps[0]["tightened"]) == 7


def test_acceptance_target_is_the_cli_json(cli):
    a = chain.Machine.load(GANTRY).allocate(target="acceptance", level=0.5)
    assert a.to_dict() == cli("allocate", GANTRY, "--target", "acceptance", "--level", 0.5)
    assert a.acceptance["level"] == 0.5 and a.acceptance["probability"] >= 0.5 - 3 * a.acceptance["std_error"]


def test_allocated_stds_meet_the_requirement_when_reevaluated(tmp_path):
    """The optimal standard deviations as a posterior (means 0, as the gantry's statistics): FORM's
    reliability over the grid equals the allocation's summary and meets the requirement."""
    m = chain.Machine.load(GANTRY)
    a = m.allocate()
    lines = ["machine: gantry_grinder", "values:"]
    lines += [f"  {e}: {{value: 0, std: {s!r}}}" for e, s in a.final["std"].items()]
    values = tmp_path / "allocated.yaml"
    values.write_text("\n".join(lines) + "\n")
    r = m.reliability(values=values)
    req = a.requirement
    for component, s in a.final["summary"].items():
        rs = [c["reliability"] for c in r.results if c["component"] == component]
        assert min(rs) == pytest.approx(s["min"], rel=1e-9) and sum(rs) / len(rs) == pytest.approx(s["mean"], rel=1e-9)
        assert min(rs) >= req["min"] - 1e-9 and sum(rs) / len(rs) >= req["mean"] - 1e-9
    # The cost: every weight 1 in the gantry, sum(std0 / std - 1).
    cost = sum(a.initial["std"][e] / s - 1 for e, s in a.final["std"].items())
    assert a.final["cost"] == pytest.approx(cost, rel=1e-12)


def test_bad_options_are_refused_naming_the_keyword(cli_error):
    m = chain.Machine.load(GANTRY)
    # A choice is refused in the words of ops::choice, the CLI's.
    with pytest.raises(ValueError, match="^`best` is not a strategy: choose one of optimal, paper$"):
        m.allocate(strategy="best")
    with pytest.raises(ValueError, match="^`all` is not a ranking: choose one of component, pooled$"):
        m.allocate(strategy="paper", rank="all")
    with pytest.raises(ValueError, match="^`everything` is not an allocation target: choose one of requirement, acceptance$"):
        m.allocate(target="everything")
    # The CLI's messages, word for word (chain::ops::allocate).
    for kw, opts, wording in [
        ({"target": "acceptance"}, ["--target", "acceptance"], "`--target acceptance` needs `--level L`"),
        ({"target": "acceptance", "level": 1.5}, ["--target", "acceptance", "--level", "1.5"],
         "invalid value for `--level`: 1.5 (an acceptance probability strictly between 0 and 1)"),
        ({"level": 0.5}, ["--level", "0.5"], "`--level` applies to `--target acceptance` only"),
    ]:
        with pytest.raises(ValueError) as info:
            m.allocate(**kw)
        message, _, help_text = str(info.value).partition("\nhelp: ")
        assert message == wording
        err = flat(cli_error("allocate", GANTRY, *opts))
        assert wording in err and flat(help_text) in err
    with pytest.raises(ValueError, match=r"the threshold is a fraction of the largest sensitivity, in \[0, 1\]"):
        m.allocate(strategy="paper", threshold=1.5)
    with pytest.raises(ValueError, match="the step must be positive"):
        m.allocate(strategy="paper", step=0)
    assert "the step must be positive" in flat(cli_error("allocate", GANTRY, "--strategy", "paper", "--step", 0))
    text = GANTRY.read_text()
    assert "  requirement: {min: 0.95, mean: 0.97}\n" in text
    no_req = chain.Machine.from_yaml(text.replace("  requirement: {min: 0.95, mean: 0.97}\n", ""), "no_req.yaml")
    with pytest.raises(ValueError, match="gantry_grinder: the reliability section has no `requirement`"):
        no_req.allocate()


def _pinned(tmp_path):
    """The gantry with every standard deviation pinned at its `min_std`: nothing can be tightened.
    Returns the file and its lines."""
    lines = []
    for line in GANTRY.read_text().splitlines():
        if "dist: normal" in line and "std: " in line:
            expr = line[line.index("std: ") + 5:].rstrip("}").strip()
            line = line.replace("}", f", min_std: {expr}}}", 1)
        lines.append(line)
    path = tmp_path / "pinned.yaml"
    path.write_text("\n".join(lines) + "\n")
    return path, lines


@pytest.mark.parametrize("strategy,code,names_first", [
    ("paper", "chain::allocate::stalled", "further ("),
    ("optimal", "chain::allocate::infeasible", "binding bounds: "),
])
def test_refused_allocation_is_located_at_its_statistics_entry_as_the_cli_says(strategy, code, names_first,
                                                                                 tmp_path, cli_error):
    """The paper's rounds stall and the least-cost allocation finds the requirement infeasible; each
    refusal names an error first, and Python raises the CLI's message (at that error's statistics
    entry, file:line:column) and help, word for word."""
    path, lines = _pinned(tmp_path)
    with pytest.raises(chain.MachineError) as info:
        chain.Machine.load(path).allocate(strategy=strategy)
    e = info.value
    message, _, help_text = str(e).partition("\nhelp: ")
    first = re.match(r"\w+", message.split(names_first, 1)[1]).group()
    line = 1 + next(i for i, text in enumerate(lines) if text.startswith(f"  {first}: {{dist"))
    assert (e.line, e.column) == (line, 3)
    assert message.startswith(f"{e.file}:{line}:3: gantry_grinder: ")
    err = cli_error("allocate", path, "--strategy", strategy)
    assert code in err and "its statistics entry" in err
    assert help_text
    assert squeezed(message) in squeezed(err) and squeezed(help_text) in squeezed(err)
