#!/usr/bin/env bash
# The one test command: every Rust test, then the Python package's tests.
#
#   ./test.sh
#
# Creates (or reuses) the virtual environment .venv-test/, installs maturin,
# numpy, pytest, sympy and pandas into it, builds and installs ./python
# (`pip install ./python`, the wheel in release), and runs pytest.
set -euo pipefail
cd "$(dirname "$0")"

cargo test --workspace --release

PY=${PYTHON:-python3}
VENV=.venv-test
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
"$VENV/bin/python" -m pip install --quiet "maturin>=1.5,<2" numpy pytest sympy pandas
# The wheel is built in the workspace's target/ (reused between runs): the
# dependencies it shares with the Rust tests (same versions, features and
# release profile) are compiled once for both.
CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$PWD/target}" \
  "$VENV/bin/python" -m pip install --quiet --force-reinstall --no-deps ./python
# From the repository root, so the installed package (not python/chain/) is imported.
"$VENV/bin/python" -m pytest -p no:cacheprovider python/tests
