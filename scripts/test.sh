#!/usr/bin/env bash
# The README's test command (and CI's, through .ci/run): installs the
# dependencies (Debian packages), then
#   1. builds once (Release) and runs the whole test suite with ctest on 2 cores;
#   2. builds the libraries' unit tests with ASan + UBSan and runs them
#      (scripts/sanitize.sh);
#   3. builds the libFuzzer targets with clang and runs each for
#      CODEMARK_FUZZ_SECONDS (default 60) (scripts/fuzz.sh);
#   4. checks clang-format and clang-tidy (scripts/lint.sh).
# Set CODEMARK_TEST_QUICK=1 to run step 1 only. Every step runs; the script
# fails if any did, and prints the time of each.
set -uo pipefail
cd "$(dirname "$0")/.."
set -e
bash scripts/setup-deps.sh
set +e

status=0
declare -a summary
step() {
  local name=$1; shift
  local start=$SECONDS
  echo "=== test.sh: $name"
  if "$@"; then r=ok; else r=FAILED; status=1; fi
  summary+=("$(printf '%-12s %-6s %4d s' "$name" "$r" $((SECONDS - start)))")
}
tests() { bash scripts/build.sh && (cd build && ctest -j2 --output-on-failure --timeout 900); }

step tests tests
if [[ "${CODEMARK_TEST_QUICK:-0}" != 1 ]]; then
  step sanitizers bash scripts/sanitize.sh
  step fuzzing bash scripts/fuzz.sh "${CODEMARK_FUZZ_SECONDS:-60}"
  step lint bash scripts/lint.sh
fi
echo "=== test.sh: summary"
printf '%s\n' "${summary[@]}"
exit $status
