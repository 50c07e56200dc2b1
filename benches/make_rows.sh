#!/usr/bin/env bash
# Writes a measurement file of about N rows for the scale benchmarks (docs/PERFORMANCE.md):
# `combined` campaigns (140 rows each) of one ring motor (tests/data/motors/ring60.toml)
# with an injected effect at nominal noise, at drive voltages cycling through 165-235 V,
# each campaign its own noise seed and run ids prefixed with its block number. Beyond
# 100 000 rows the first 100 000 are repeated with new run ids (synthesis would dominate
# the benchmark's set-up time, and a fit sees the repeats as more readings of the same
# runs).
#   bash benches/make_rows.sh N OUT.csv
#   EFFECT=none bash benches/make_rows.sh N OUT.csv       # no effect (default radial_friction=1)
#   ERRATIC=0.3 bash benches/make_rows.sh N OUT.csv       # erratic speeds: every speed_rpm
#                                                         # reading scattered by 30 % (normal,
#                                                         # folded at zero)
# Needs target/release/trum (cargo build --release -p trum-cli).
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:?rows}
out=${2:?output file}
T=${TRUM:-target/release/trum}
MOTOR=tests/data/motors/ring60.toml
effect=${EFFECT:-radial_friction=1}
effect_args=(--effect "$effect")
if [ "$effect" = none ]; then effect_args=(); fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
volts=(165 175 185 195 205 215 225 235)
synth_n=$n
if [ "$synth_n" -gt 100000 ]; then synth_n=100000; fi
blocks=$(((synth_n + 139) / 140))
body="$dir/body.csv"
: > "$body"
for ((i = 1; i <= blocks; i++)); do
    v=${volts[$((i % 8))]}
    "$T" synth --motor "$MOTOR" "${effect_args[@]}" --campaign combined --noise 1 --seed "$i" \
        --motor-seed 1 --voltage-v "$v" -o "$dir/c.csv" > /dev/null 2>&1
    if [ "$i" = 1 ]; then head -n 1 "$dir/c.csv" > "$dir/header.csv"; fi
    # the run id is the last column: prefixed with the block so runs stay distinct
    tail -n +2 "$dir/c.csv" | awk -F, -v OFS=, -v p="b$i-" '{ $NF = p $NF; print }' >> "$body"
done
{
    cat "$dir/header.csv"
    awk -F, -v OFS=, -v n="$n" -v synth="$(wc -l < "$body")" -v erratic="${ERRATIC:-0}" '
        BEGIN { srand(17) }
        { line[NR] = $0 }
        END {
            for (k = 0; k < n; k++) {
                $0 = line[(k % synth) + 1]
                if (k >= synth) { $NF = "r" int(k / synth) "-" $NF }
                # column 5 is speed_rpm: a normal scatter of the given relative size
                if (erratic > 0 && $5 != "") {
                    z = sqrt(-2 * log(1 - rand())) * cos(6.283185307179586 * rand())
                    s = $5 * (1 + erratic * z)
                    # (a speed reading is never negative: a scatter below zero reads its size)
                    $5 = s < 0 ? -s : s
                }
                print
            }
        }' "$body"
} > "$out"
echo "wrote $(($(wc -l < "$out") - 1)) rows to $out"
