#!/usr/bin/env bash
# Builds and runs the detection benchmark (bench/detect: codemark vs OpenCV
# ArUco and AprilTag 3 on the same rendered scenes) and writes its report to
# docs/benchmarks/detect.md (machine, date, tables). About 10 minutes on 2
# cores; `--quick` is a smoke run (< 1 min) that prints the report without
# overwriting the committed one unless --out is given.
#
# Usage: scripts/bench-detect.sh [--quick] [--build-dir DIR] [--preset NAME]
#        [other options of codemark-bench-detect, e.g. --positions N
#        --clutter N, --dump-misses DIR to keep codemark's missed frames as PNG]
# --preset NAME renders every frame through that camera preset
# (docs/camera-pipeline.md) and writes docs/benchmarks/detect-NAME.md;
# without it the frames have blur 0.8 px and noise 2 in linear light.
# Environment: BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
args=()
quick=0
report=docs/benchmarks/detect.md
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    --quick) quick=1; args+=("$1"); shift ;;
    --preset) report="docs/benchmarks/detect-$2.md"; args+=("$1" "$2"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-detect
exe="$build_dir/bench/detect/codemark-bench-detect"
rev="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git diff --quiet HEAD -- libs bench 2>/dev/null; then rev="$rev with uncommitted changes in libs/ or bench/"; fi
args+=(--revision "commit $rev")
if [[ $quick -eq 1 ]]; then
  "$exe" "${args[@]}"
else
  mkdir -p docs/benchmarks
  "$exe" --out "$report" "${args[@]}"
fi
