#!/usr/bin/env bash
# One command for the Python comparison of docs/PERFORMANCE.md: builds the `trum` CLI and
# Python module (release) into .venv, then runs benches/compare_python.py, which times the
# per-point SciPy, the vectorised NumPy and the Rust versions of the baseline model on the
# same points and checks they agree to 1e-9 relative.
#   bash benches/compare_python.sh [compare_python.py args...]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/.venv"
TARGET="${CARGO_TARGET_DIR:-$ROOT/target}"
[ -x "$VENV/bin/python" ] || python3 -m venv "$VENV"
"$VENV/bin/python" -m pip install -q --disable-pip-version-check maturin numpy scipy
cargo build --release -q -p trum-cli
VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH" "$VENV/bin/maturin" develop --release -q -m crates/trum-py/Cargo.toml
"$VENV/bin/python" benches/compare_python.py --trum-bin "$TARGET/release/trum" "$@"
