#!/usr/bin/env bash
# The diagnosis at scale (docs/PERFORMANCE.md): wall time, CPU time and peak RSS of
# `trum diagnose` on clean and erratic data of 10^3 to 10^5 rows (benches/make_rows.sh:
# combined campaigns of one ring motor with radial_friction; erratic = every speed reading
# scattered by 30 %), with the time a row and the memory a row above the 1000-row run's.
#   bash benches/diagnose_scale.sh                 # 1000 10000 100000 rows
#   SIZES="1000 3000" bash benches/diagnose_scale.sh
set -euo pipefail
cd "$(dirname "$0")/.."
# TRUM=path/to/trum times that binary instead of building target/release/trum
if [ -z "${TRUM:-}" ]; then cargo build --release -q -p trum-cli; fi
T=${TRUM:-target/release/trum}
export TRUM="$T"
MOTOR=tests/data/motors/ring60.toml
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
printf '%-8s %-8s %9s %9s %10s %12s %9s  %s\n' rows data "wall s" "CPU s" "ms/row" "peak RSS MB" "load" verdict
for n in ${SIZES:-1000 10000 100000}; do
    for kind in clean erratic; do
        scatter=0
        if [ "$kind" = erratic ]; then scatter=0.3; fi
        ERRATIC=$scatter bash benches/make_rows.sh "$n" "$dir/d.csv" > /dev/null
        load=$(cut -d' ' -f1 /proc/loadavg)
        /usr/bin/time -f "%e %U %S %M" -o "$dir/time" "$T" diagnose --motor "$MOTOR" --data "$dir/d.csv" \
            --max-rows "$n" -q > "$dir/out.txt" 2> "$dir/err.txt" || { cat "$dir/err.txt"; exit 1; }
        read -r wall user sys rss < "$dir/time"
        verdict=$(sed -n 's/^verdict *//p' "$dir/out.txt" | cut -c1-60)
        awk -v n="$n" -v k="$kind" -v w="$wall" -v u="$user" -v s="$sys" -v m="$rss" -v l="$load" -v v="$verdict" \
            'BEGIN { printf "%-8d %-8s %9.2f %9.2f %10.3f %12.1f %9s  %s\n", n, k, w, u + s, 1000 * w / n, m / 1024, l, v }'
    done
done
