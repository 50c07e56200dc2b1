#!/usr/bin/env bash
# Coverage-guided fuzzing (cargo-fuzz, libFuzzer) of every target in fuzz/coverage/ for a
# stated budget, with a seed that changes per run unless given, printed for replay.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]
# Needs a nightly toolchain (`rustup toolchain list`) and cargo-fuzz (`cargo install
# cargo-fuzz`). Corpora grow in fuzz/coverage/corpus/<target>/ (git-ignored, seeded from
# the committed fuzz/corpus/ where a target reads the same format); crashes go to
# fuzz/coverage/artifacts/<target>/. Prints executions, coverage and corpus size per
# target (docs/RELIABILITY.md, "Coverage-guided fuzzing").
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-60}
shift || true
TARGETS=("$@")
if [ ${#TARGETS[@]} -eq 0 ]; then
  TARGETS=(motor_reader measurement_reader solver writers_round_trip calibrate_diagnose)
fi
SEED=${TRUM_FUZZ_SEED:-$(( $(date +%s) % 1000000007 ))}
echo "fuzz seed: $SEED, ${SECONDS_PER_TARGET} s per target (replay a crash: cargo +nightly fuzz run --fuzz-dir fuzz/coverage TARGET ARTIFACT)"
for t in "${TARGETS[@]}"; do
  corpus=fuzz/coverage/corpus/$t
  mkdir -p "$corpus" "fuzz/coverage/artifacts/$t"
  # inputs up to the length a target can use, from the start (-len_control=0)
  case $t in
    motor_reader) seeds=fuzz/corpus/toml; max_len=8192 ;;
    measurement_reader) seeds=fuzz/corpus/csv; max_len=8192 ;;
    solver) seeds=; max_len=128 ;;
    writers_round_trip) seeds=; max_len=512 ;;
    calibrate_diagnose) seeds=; max_len=64 ;;
    *) seeds=; max_len=4096 ;;
  esac
  echo "== $t"
  log=$(mktemp)
  # -rss_limit_mb bounds memory; -timeout reports an input slower than 10 s as a hang
  if ! cargo +nightly fuzz run --fuzz-dir fuzz/coverage "$t" "$corpus" $seeds -- \
      -seed="$SEED" -max_total_time="$SECONDS_PER_TARGET" -rss_limit_mb=4096 -timeout=10 \
      -max_len="$max_len" -len_control=0 \
      -print_final_stats=1 >"$log" 2>&1; then
    tail -40 "$log"
    echo "FAILED: $t (seed $SEED; the input is in fuzz/coverage/artifacts/$t/)"
    rm -f "$log"
    exit 1
  fi
  grep -E "^#[0-9]+.*(DONE|cov:)" "$log" | tail -1
  grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$log" || true
  rm -f "$log"
done
