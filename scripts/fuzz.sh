#!/usr/bin/env bash
# Builds codemark's libFuzzer targets with clang-14 (build-asan/, shared with
# scripts/sanitize.sh: see scripts/asan-build.sh)
# and runs each for SECONDS (default 60) from its seed corpus in
# fuzz/corpus/<target>/. Fails on the first crash, leak, timeout or
# out-of-memory; the reproducer is left in fuzz/crashes/<target>/.
#   scripts/fuzz.sh [SECONDS] [TARGET...]      e.g. scripts/fuzz.sh 600 fuzz_map
# Environment:
# ASAN_BUILD_DIR (default build-asan), FUZZ_NO_BUILD=1 to skip the build.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=60
if [[ $# -gt 0 && "$1" =~ ^[0-9]+$ ]]; then SECONDS_PER_TARGET=$1; shift; fi
TARGETS=("$@")
[[ ${#TARGETS[@]} -eq 0 ]] && TARGETS=(fuzz_detector fuzz_map fuzz_camera fuzz_deserialize)
# shellcheck source=scripts/asan-build.sh
source scripts/asan-build.sh
BUILD=$ASAN_BUILD_DIR
[[ "${FUZZ_NO_BUILD:-0}" == 1 ]] || asan_build "${TARGETS[@]}"

# OpenCV and MRPT are not instrumented; their one-time allocations are not leaks of ours.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
# The targets run side by side (FUZZ_PARALLEL=0 runs them one after the
# other): each still runs SECONDS of wall time, and CI spends SECONDS in all.
run_one() {
  local t=$1
  local corpus_seed=fuzz/corpus/$t
  local work=$BUILD/corpus/$t           # grows during the run; the committed seeds stay small
  local crashes=fuzz/crashes/$t
  mkdir -p "$work" "$crashes"
  if ! "$BUILD/fuzz/$t" "$work" "$corpus_seed" -max_total_time="$SECONDS_PER_TARGET" \
      -timeout=10 -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
      -artifact_prefix="$crashes/" \
      >"$BUILD/$t.log" 2>&1; then
    echo "fuzz.sh: $t FAILED; reproducer(s) in $crashes/, log $BUILD/$t.log:"
    grep -E "ERROR|SUMMARY|Test unit written" "$BUILD/$t.log" | head -5
    return 1
  fi
  echo "fuzz.sh: $t ran ${SECONDS_PER_TARGET} s: $(grep -E "stat::number_of_executed_units" "$BUILD/$t.log" | tail -1)"
}
status=0
declare -a pids
for t in "${TARGETS[@]}"; do
  echo "fuzz.sh: $t for ${SECONDS_PER_TARGET} s"
  if [[ "${FUZZ_PARALLEL:-1}" == 1 ]]; then
    run_one "$t" & pids+=($!)
  else
    run_one "$t" || status=1
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
exit $status
