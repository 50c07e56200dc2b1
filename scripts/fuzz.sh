#!/usr/bin/env bash
# Coverage-guided fuzzing (cargo-fuzz, libFuzzer) of the targets in fuzz/coverage/ for a
# stated budget, with a seed that changes per run unless given, printed for replay.
#   scripts/fuzz.sh [OPTIONS] [BUDGET] [TARGET[:BUDGET]...]
# BUDGET is seconds per target (default 60), or a count of executions per target when
# written with an x suffix (1000000x: libFuzzer's -runs, the run stops at the count); a
# target's own budget after a colon overrides it (diagnose:3600).
# Options:
#   --sanitizer none|address   the build (default address, cargo-fuzz's own). `none` runs
#                              several times faster; trum is safe Rust, so AddressSanitizer
#                              only adds checks inside unsafe code of its dependencies
#                              (docs/RELIABILITY.md, "Coverage-guided fuzzing")
#   --timeout S                an input slower than S seconds is a hang (default 10)
#   --no-trace-compares        build without libFuzzer's comparison tracing (its own
#                              target directory, fuzz/coverage/target-no-cmp): for the
#                              numeric targets, whose bytes become floats, where the
#                              tracing is most of the time and guides little
#                              (docs/RELIABILITY.md, "Which build")
# Debug assertions and overflow checks are on in every build (-a).
# Every target is built before the first one runs, so the figures are of one source state.
# Needs a nightly toolchain (`rustup toolchain list`) and cargo-fuzz (`cargo install
# cargo-fuzz`). Corpora grow in fuzz/coverage/corpus/<target>/ (git-ignored, seeded from
# the committed fuzz/corpus/ where a target reads the same format); crashes go to
# fuzz/coverage/artifacts/<target>/. Prints executions, rate, coverage, corpus size and
# peak RSS per target, also for a run stopped by hand with SIGINT to the target binary.
set -euo pipefail
cd "$(dirname "$0")/.."
SANITIZER=address
TIMEOUT=10
TRACE_CMP=yes
while [ $# -gt 0 ]; do
  case $1 in
    --sanitizer) SANITIZER=${2:?--sanitizer needs none or address}; shift 2 ;;
    --sanitizer=*) SANITIZER=${1#*=}; shift ;;
    --timeout) TIMEOUT=${2:?--timeout needs seconds}; shift 2 ;;
    --timeout=*) TIMEOUT=${1#*=}; shift ;;
    --no-trace-compares) TRACE_CMP=no; shift ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) break ;;
  esac
done
case $SANITIZER in
  none|address) ;;
  *) echo "fuzz.sh: --sanitizer must be none or address, not '$SANITIZER'" >&2; exit 2 ;;
esac
BUDGET=${1:-60}
shift || true
# budget_args BUDGET: libFuzzer's options for that budget, or exit 2
budget_args() {
  if ! [[ ${1%x} =~ ^[0-9]+$ ]]; then
    echo "fuzz.sh: a budget must be seconds (600) or executions (1000000x), not '$1'" >&2
    exit 2
  fi
  case $1 in
    *x) echo "-runs=${1%x}" ;;
    *) echo "-max_total_time=$1" ;;
  esac
}
budget_args "$BUDGET" >/dev/null
ARGS=("$@")
if [ ${#ARGS[@]} -eq 0 ]; then
  ARGS=(motor_reader measurement_reader solver writers_round_trip calibrate diagnose diagnose_options diagnose_decision)
fi
TARGETS=()
for a in "${ARGS[@]}"; do
  TARGETS+=("${a%%:*}")
  [[ $a == *:* ]] && budget_args "${a#*:}" >/dev/null
done
SEED=${TRUM_FUZZ_SEED:-$(( $(date +%s) % 1000000007 ))}
BUILD=(cargo +nightly fuzz build --fuzz-dir fuzz/coverage -O -a -s "$SANITIZER")
TARGET_DIR=fuzz/coverage/target
if [ "$TRACE_CMP" = no ]; then
  # (other flags, so a directory of their own: the two builds do not rebuild each other)
  TARGET_DIR=fuzz/coverage/target-no-cmp
  BUILD+=(--no-trace-compares --target-dir "$TARGET_DIR")
fi
echo "fuzz seed: $SEED, budget $BUDGET per target (x: executions, else seconds), sanitizer $SANITIZER, comparison tracing $TRACE_CMP, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "replay a crash: ${BUILD[*]/build/run} TARGET ARTIFACT"
for t in "${TARGETS[@]}"; do
  "${BUILD[@]}" "$t"
done
BIN_DIR=$TARGET_DIR/$(rustc +nightly -vV | sed -n 's/^host: //p')/release
for a in "${ARGS[@]}"; do
  t=${a%%:*}
  b=$BUDGET
  [[ $a == *:* ]] && b=${a#*:}
  corpus=fuzz/coverage/corpus/$t
  mkdir -p "$corpus" "fuzz/coverage/artifacts/$t"
  # inputs up to the length a target can use, from the start (-len_control=0)
  case $t in
    motor_reader) seeds=fuzz/corpus/toml; max_len=8192 ;;
    measurement_reader) seeds=fuzz/corpus/csv; max_len=8192 ;;
    solver) seeds=; max_len=128 ;;
    writers_round_trip) seeds=; max_len=512 ;;
    calibrate|diagnose|diagnose_options) seeds=; max_len=64 ;;
    *) seeds=; max_len=4096 ;;
  esac
  echo "== $t, budget $b (load $(cut -d' ' -f1-3 /proc/loadavg))"
  log=$(mktemp)
  start=$(date +%s)
  # -rss_limit_mb bounds memory; -timeout reports a slow input as a hang
  rc=0
  # shellcheck disable=SC2086
  /usr/bin/time -f "wall %e s, max RSS %M kB" "$BIN_DIR/$t" "$corpus" $seeds \
      -artifact_prefix="fuzz/coverage/artifacts/$t/" \
      -seed="$SEED" "$(budget_args "$b")" -rss_limit_mb=4096 -timeout="$TIMEOUT" \
      -max_len="$max_len" -len_control=0 \
      -print_final_stats=1 >"$log" 2>&1 || rc=$?
  # a run stopped by hand (SIGINT to the target: libFuzzer prints its figures and exits
  # 72) is not a failure; its figures are of the executions so far
  interrupted=no
  if [ "$rc" -eq 72 ] && grep -q "libFuzzer: run interrupted" "$log"; then
    interrupted=yes
  fi
  if [ "$rc" -ne 0 ] && [ "$interrupted" = no ]; then
    tail -40 "$log"
    echo "FAILED: $t (seed $SEED; the input is in fuzz/coverage/artifacts/$t/)"
    rm -f "$log"
    exit 1
  fi
  secs=$(( $(date +%s) - start ))
  [ "$interrupted" = yes ] && echo "interrupted by hand: the figures below are of the run so far"
  grep -E "^#[0-9]+.*(DONE|cov:)" "$log" | tail -1
  grep -E "stat::number_of_executed_units|stat::average_exec_per_sec|stat::peak_rss_mb|^wall" "$log" || true
  echo "corpus: $(find "$corpus" -type f | wc -l) files, $(du -sh "$corpus" | cut -f1); ${secs} s"
  rm -f "$log"
done
