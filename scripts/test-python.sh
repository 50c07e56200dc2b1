#!/usr/bin/env bash
# Builds the `trum` Python module into a virtualenv at .venv (created or reused) and runs
# its pytest suite. Works on a fresh machine with python3 and cargo; exits non-zero on failure.
#   scripts/test-python.sh [pytest args...]   build, then test
#   scripts/test-python.sh --build-only       build only (scripts/test.sh runs it on one
#                                             core beside the Rust tests)
#   scripts/test-python.sh --test-only [...]  test the module already built
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"

build() {
    if [ ! -x "$PY" ]; then
        echo "== creating $VENV"
        python3 -m venv "$VENV"
    fi
    echo "== installing build and test dependencies"
    "$PY" -m pip install -q --disable-pip-version-check --upgrade pip
    "$PY" -m pip install -q --disable-pip-version-check maturin numpy pytest pandas xarray matplotlib hypothesis "dask[distributed]"
    echo "== building trum (release) into $VENV"
    # maturin develop installs into the virtualenv named by VIRTUAL_ENV. Its own build
    # directory (target/python): the module's dependencies resolve with other features
    # than the workspace's, so nothing in target/ could be shared, and a build there
    # would hold cargo's lock on target/ while the Rust tests need it.
    CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$ROOT/target/python}" VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH" \
        "$VENV/bin/maturin" develop --release -q -m crates/trum-py/Cargo.toml
}

case "${1:-}" in
    --build-only) build; exit 0 ;;
    --test-only) shift ;;
    *) build ;;
esac
echo "== pytest"
"$PY" -m pytest crates/trum-py/tests -q "$@"
