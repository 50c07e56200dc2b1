#!/usr/bin/env bash
# The diagnosis speed benchmark: a diagnosis of about 1000 rows with all seven candidates
# and block cross-validation (docs/PERFORMANCE.md). Builds eight `combined` campaigns of
# one ring motor (tests/data/motors/ring60.toml: the TRUM60A values, frozen; radial_friction injected, nominal noise) at drive voltages 165-235 V, joins
# them into one file (run ids prefixed with the voltage) and times `trum diagnose`.
#   bash benches/diagnose_1000.sh            # release build, then the timed run
#   SEED_OFFSET=10 bash benches/diagnose_1000.sh   # noise seeds 11-18, motor seed 11
#   FLEET=1 bash benches/diagnose_1000.sh    # a fleet instead: each campaign
#                                            # its own motor (motor seed = noise seed)
#   EFFECT=voltage_sag=150 SEED_OFFSET=40 bash benches/diagnose_1000.sh
#                                            # another injected effect (EFFECT=none: none)
#   KEEP=data.csv bash benches/diagnose_1000.sh   # also keep the joined data file
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release -q -p trum-cli
T=target/release/trum
MOTOR=tests/data/motors/ring60.toml
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
out="$dir/bench1000.csv"
i=0
off=${SEED_OFFSET:-0}
for v in 165 175 185 195 205 215 225 235; do
    i=$((i + 1))
    # one motor measured in eight runs: the motor seed is shared, the noise seeds differ
    motor_seed=$((1 + off))
    if [ -n "${FLEET:-}" ]; then motor_seed=$((i + off)); fi
    effect=${EFFECT:-radial_friction=1}
    effect_args=(--effect "$effect")
    if [ "$effect" = none ]; then effect_args=(); fi
    "$T" synth --motor "$MOTOR" "${effect_args[@]}" --campaign combined --noise 1 --seed "$((i + off))" \
        --motor-seed "$motor_seed" --voltage-v "$v" -o "$dir/c$i.csv" > /dev/null
    if [ "$i" = 1 ]; then head -n 1 "$dir/c$i.csv" > "$out"; fi
    # prefix every run id (the last column) with the voltage so runs stay distinct
    tail -n +2 "$dir/c$i.csv" | awk -F, -v OFS=, -v p="v$v-" '{ $NF = p $NF; print }' >> "$out"
done
echo "rows: $(($(wc -l < "$out") - 1))"
if [ -n "${KEEP:-}" ]; then cp "$out" "$KEEP"; fi
/usr/bin/time -f "wall %e s, CPU %U s user, peak RSS %M KB" "$T" diagnose --motor "$MOTOR" --data "$out" | sed -n 1,40p
