"""Shared fixtures: the repository, the example machines and the CLI binary."""

import json
import os
import pathlib
import re
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
MACHINES = sorted((ROOT / "examples" / "machines").glob("*.yaml"))


def cli_binary() -> pathlib.Path:
    """The `chain` binary: `CHAIN_CLI` (test.sh sets it to the one its Rust tests built,
    target/ci/chain), else the release binary, built here if absent."""
    exe = pathlib.Path(os.environ.get("CHAIN_CLI", ROOT / "target" / "release" / "chain"))
    if not exe.exists():
        subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    return exe


@pytest.fixture(scope="session")
def cli():
    """Runs `chain ARGS --format json` from the repository root and returns the parsed JSON."""
    exe = cli_binary()

    def run(*args):
        out = subprocess.run([str(exe), *map(str, args), "--format", "json"], cwd=ROOT,
                             check=True, capture_output=True, text=True)
        return json.loads(out.stdout)

    return run


@pytest.fixture(scope="session")
def cli_error():
    """Runs `chain ARGS` expecting failure; returns its stderr."""
    exe = cli_binary()

    def run(*args):
        out = subprocess.run([str(exe), *map(str, args)], cwd=ROOT, capture_output=True, text=True,
                             env={**os.environ, "NO_COLOR": "1"})
        assert out.returncode != 0
        return out.stderr

    return run


def flat(text):
    """Text without the CLI renderer's frame, runs of white space made one space: miette wraps long
    lines (where, depends on the length of the paths in them), so a message is compared flattened."""
    return " ".join(re.sub(r"[│×╭╰─┬·▶]", " ", text).split())


def squeezed(text):
    """``flat`` without any space: for messages whose wrap falls inside a path."""
    return flat(text).replace(" ", "")
