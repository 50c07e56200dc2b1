#!/usr/bin/env bash
# Instructions and wall time of one operating point, baseline and with each effect on its
# own (docs/PERFORMANCE.md). Instruction counts come from callgrind and do not depend on
# the machine's load; wall times are medians of blocks and do.
#   bash scripts/callgrind.sh                  every set, cold points and the baseline sweep
#   bash scripts/callgrind.sh SET [MODE]       one set (see crates/trum-core/examples/point_cost.rs)
# POINTS=N sets the points per callgrind run (default 1000; the wall-time run uses 4000).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
command -v valgrind >/dev/null || { echo "callgrind.sh: valgrind is not installed" >&2; exit 1; }
cargo build --release -q -p trum-core --example point_cost
bin=target/release/examples/point_cost
points=${POINTS:-1000}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
if [ $# -gt 0 ]; then
    runs=("$1 ${2:-cold}")
else
    runs=("none cold" "none sweep" "preset cold" "preset sweep"
          "radial_friction=1 cold" "tangential_compliance=1 cold" "thermal_drift=-4e-4 cold"
          "voltage_sag=150 cold" "eccentricity=2e-5 cold" "preload_stiffening=0.05 cold"
          "hertz_softening=1e18 cold")
fi
printf '%-26s %-5s %12s %14s %12s\n' set mode "µs/point" "instr/point" "evals/point"
for run in "${runs[@]}"; do
    read -r set mode <<<"$run"
    wall=$("$bin" "$set" "$mode" 4000)
    valgrind --tool=callgrind --callgrind-out-file="$out/cg" --toggle-collect='*point_cost::measured*' \
        "$bin" "$set" "$mode" "$points" >/dev/null 2>"$out/log"
    ir=$(grep -m1 '^summary:\|^totals:' "$out/cg" | awk '{print $2}')
    n=$(( (points / 25) * 25 ))
    us=$(awk '{for (i = 1; i <= NF; i++) if ($i == "us/point") print $(i-1)}' <<<"$wall")
    ev=$(awk '{for (i = 1; i <= NF; i++) if ($i ~ /^evaluations/) print $(i-1)}' <<<"$wall")
    printf '%-26s %-5s %12s %14d %12s\n' "$set" "$mode" "$us" $(( ir / n )) "$ev"
done
