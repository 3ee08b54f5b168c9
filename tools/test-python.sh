#!/usr/bin/env bash
# Installs the Python package (python/) from this checkout into a fresh virtual environment,
# target/python-test-venv, as a user would (`pip install ./python`), and runs its tests
# (python/tests) with pytest against the `pathlight` program cargo builds. The extension is
# built with cargo's dev profile; needs python3 with venv and pip, and PyPI (maturin, NumPy,
# pytest). Arguments go to pytest.
#
#   tools/test-python.sh [PYTEST ARGS...]
set -euo pipefail
cd "$(dirname "$0")/.."

venv=target/python-test-venv
rm -rf "$venv"
python3 -m venv "$venv"
# The program the tests compare with, as `cargo test --workspace` builds it (with the
# workspace's features: a build of its package alone would compile everything again).
cargo test --workspace --locked --no-run --quiet
MATURIN_PEP517_ARGS="--profile dev --locked" \
    "$venv/bin/pip" install --quiet --disable-pip-version-check "./python[test]"
PATHLIGHT_BIN="$PWD/target/debug/pathlight" "$venv/bin/python" -m pytest -q python/tests "$@"
