#!/usr/bin/env bash
# Sourced by scripts/sanitize.sh and scripts/fuzz.sh: the one instrumented
# build both use (clang-14, ASan + UBSan + libFuzzer's coverage hooks,
# CODEMARK_FUZZ=ON, tests on, benchmarks off) in $ASAN_BUILD_DIR (default
# build-asan). One build instead of a gcc ASan build and a clang fuzz build
# compiles the shared libraries once: CI's budget is 30 minutes on 2 cores.
# -O1 and line tables only: the sanitizers' reports keep file:line, and the
# build takes a fraction of -O2 -g's time.
#   asan_build TARGET...     configures if needed, builds TARGET...
ASAN_BUILD_DIR=${ASAN_BUILD_DIR:-build-asan}
asan_build() {
  local cxx
  cxx=$(command -v clang++-14 || command -v clang++)
  cmake -S . -B "$ASAN_BUILD_DIR" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only -DNDEBUG" \
    -DCODEMARK_FUZZ=ON -DCODEMARK_BUILD_TESTS=ON -DCODEMARK_BUILD_BENCH=OFF >/dev/null
  cmake --build "$ASAN_BUILD_DIR" -j"$(nproc)" --target "$@"
}
