#!/usr/bin/env bash
# The short, CI-sized criterion run (a few seconds per bench; not part of scripts/test.sh).
#   bash benches/quick.sh
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cargo bench --bench solve -- --quick --noplot "$@"
