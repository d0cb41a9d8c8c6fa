#!/usr/bin/env bash
# The longer fuzz run (docs/robustness.md, "Fuzzing"): the fuzz tests of
# tests/it/robustness/fuzz.rs (byte-level mutations) and
# tests/it/robustness/fuzz_structured.rs (structural edits, proptest programs)
# with CASES cases per input
# (default 2000; the test command runs a few dozen). A failing case is saved in the temporary
# directory the failure message names.
#
#   scripts/fuzz.sh [CASES]
set -euo pipefail
cd "$(dirname "$0")/.."
CHAIN_FUZZ_CASES="${1:-2000}" cargo test --profile ci --test it -- robustness::fuzz:: robustness::fuzz_structured:: --nocapture
