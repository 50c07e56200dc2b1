#!/usr/bin/env bash
# `trum calibrate` at scale (docs/PERFORMANCE.md): wall time, CPU time and peak RSS on
# 10^6 rows (benches/make_rows.sh: combined campaigns of one ring motor with
# radial_friction at nominal noise).
#   bash benches/calibrate_scale.sh              # 10^6 rows
#   SIZES="10000 100000 1000000" bash benches/calibrate_scale.sh
set -euo pipefail
cd "$(dirname "$0")/.."
# TRUM=path/to/trum times that binary instead of building target/release/trum
if [ -z "${TRUM:-}" ]; then cargo build --release -q -p trum-cli; fi
T=${TRUM:-target/release/trum}
export TRUM="$T"
MOTOR=tests/data/motors/ring60.toml
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf '%-8s %9s %9s %12s %9s  %s\n' rows "wall s" "CPU s" "peak RSS MB" "load" "chi2/reading"
for n in ${SIZES:-1000000}; do
    bash benches/make_rows.sh "$n" "$dir/d.csv" > /dev/null
    load=$(cut -d' ' -f1 /proc/loadavg)
    /usr/bin/time -f "%e %U %S %M" -o "$dir/time" "$T" calibrate --motor "$MOTOR" --data "$dir/d.csv" \
        --max-rows "$n" -q --json "$dir/cal.json" -o "$dir/cal.toml" > /dev/null 2> "$dir/err.txt" \
        || { cat "$dir/err.txt"; exit 1; }
    read -r wall user sys rss < "$dir/time"
    chi2=$(sed -n 's/.*"chi2_per_reading": *\([^,]*\),*/\1/p' "$dir/cal.json")
    awk -v n="$n" -v w="$wall" -v u="$user" -v s="$sys" -v m="$rss" -v l="$load" -v c="$chi2" \
        'BEGIN { printf "%-8d %9.2f %9.2f %12.1f %9s  %s\n", n, w, u + s, m / 1024, l, c }'
done
