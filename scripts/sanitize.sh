#!/usr/bin/env bash
# Builds the libraries' unit tests with AddressSanitizer + UndefinedBehavior-
# Sanitizer (clang, build-asan/, shared with scripts/fuzz.sh: see
# scripts/asan-build.sh) and runs them with ctest;
# the first error stops the test that hit it (halt_on_error) and fails the run.
# The slow simulation suites (renders, Monte Carlo, filter runs), the filters
# (whose template-heavy EKF-SLAM takes minutes to compile) and the
# app-level tests stay in the normal build to keep CI under 30 minutes; so
# do test_detect and test_pipeline by default (the detector runs under ASan
# + UBSan in fuzz_detector; pass them as arguments to include them).
#   scripts/sanitize.sh [TEST_TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
TARGETS=("$@")
[[ ${#TARGETS[@]} -eq 0 ]] && TARGETS=(test_landmark test_print test_sim test_pose test_mrpt_plugin)
# shellcheck source=scripts/asan-build.sh
source scripts/asan-build.sh
BUILD=$ASAN_BUILD_DIR

# Leak reports from MRPT's and OpenCV's one-time static allocations are
# suppressed in scripts/lsan.supp (see there); everything else fails.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"

# The fuzz targets are built with them (2 cores kept busy, scripts/fuzz.sh
# then finds them built) unless FUZZ_TARGETS is set empty.
read -r -a FUZZ <<<"${FUZZ_TARGETS-fuzz_detector fuzz_map fuzz_camera fuzz_deserialize}"
asan_build "${TARGETS[@]}" "${FUZZ[@]}"
# Only the tests whose command is one of the executables built here (the
# app-level tests and the other suites register too, but are not built).
regex=$(ctest --test-dir "$BUILD" --show-only=json-v1 | python3 -c '
import json, os, re, sys
targets = set(sys.argv[1:])
names = [t["name"] for t in json.load(sys.stdin)["tests"]
         if t.get("command") and os.path.basename(t["command"][0]) in targets]
print("^(" + "|".join(re.escape(n) for n in names) + ")$")' "${TARGETS[@]}")
ctest --test-dir "$BUILD" -j2 --output-on-failure --timeout 900 -R "$regex"
