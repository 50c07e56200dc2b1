#!/usr/bin/env bash
# Builds the `trum` Python module into a virtualenv at .venv (created or reused) and runs
# its pytest suite. Works on a fresh machine with python3 and cargo; exits non-zero on failure.
#   scripts/test-python.sh [pytest args...]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/.venv"

if [ ! -x "$VENV/bin/python" ]; then
    echo "== creating $VENV"
    python3 -m venv "$VENV"
fi
PY="$VENV/bin/python"
echo "== installing build and test dependencies"
"$PY" -m pip install -q --disable-pip-version-check --upgrade pip
"$PY" -m pip install -q --disable-pip-version-check maturin numpy pytest pandas xarray matplotlib hypothesis "dask[distributed]"

echo "== building trum (release) into $VENV"
# maturin develop installs into the virtualenv named by VIRTUAL_ENV.
VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH" "$VENV/bin/maturin" develop --release -q -m crates/trum-py/Cargo.toml

echo "== pytest"
"$PY" -m pytest crates/trum-py/tests -q "$@"
