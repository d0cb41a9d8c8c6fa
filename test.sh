#!/usr/bin/env bash
# The one test command: every Rust test, then the Python package's tests.
#
#   ./test.sh
#
# The Rust tests build in the `ci` profile (release, incremental; target/ci/).
# Creates (or reuses) the virtual environment .venv-test/, installs maturin,
# numpy, pytest, sympy and pandas into it, builds and installs ./python
# (`pip install ./python`, the wheel in release), and runs pytest.
set -euo pipefail
cd "$(dirname "$0")"

cargo test --workspace --profile ci

PY=${PYTHON:-python3}
VENV=.venv-test
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "maturin>=1.5,<2" numpy pytest sympy pandas html5lib
# The wheel is built in the workspace's target/ and `ci` profile (reused
# between runs): the dependencies it shares with the Rust tests (same
# versions, features and profile) are compiled once for both. (`pip install
# ./python` without these builds in release, as a user's install does.)
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}" MATURIN_PEP517_ARGS="--profile ci" \
  "$VENV/bin/python" -m pip install --quiet --force-reinstall --no-deps ./python
# From the repository root, so the installed package (not python/chain/) is imported;
# the CLI the Python tests compare with is the one the Rust tests used.
CHAIN_CLI="${CHAIN_CLI:-$PWD/target/ci/chain}" \
  "$VENV/bin/python" -m pytest -p no:cacheprovider python/tests
