#!/usr/bin/env bash
# Builds and runs the particle-filter benchmark (bench/filters_pf): time per
# update against the number of particles (10^2..10^5) with our
# CCodedLandmarksMap and with a constant-likelihood map in the same run (its
# time is MRPT's own overhead), and frames with sightings to convergence from
# a uniform start (shipped pf.ini, 10 seeds). Writes
# docs/benchmarks/filters-pf.md. About 1 minute on 2 cores.
#
# Usage: scripts/bench-filters-pf.sh [--quick] [--build-dir DIR]
# Environment: BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) args+=("$1"); shift ;;
  esac
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-filters-pf >/dev/null
exe="$build_dir/bench/filters_pf/codemark-bench-filters-pf"
doc=docs/benchmarks/filters-pf.md
tmp="$(mktemp)"
trap 'rm -f "$tmp"' EXIT
{
  echo "# Particle filter benchmark"
  echo
  echo "Written by \`scripts/bench-filters-pf.sh${args[*]:+ ${args[*]}}\` on $(date -u +%Y-%m-%d),"
  echo "commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(nproc) cores ($(uname -m)), Release build:"
  echo "\`$(basename "$build_dir")/bench/filters_pf/codemark-bench-filters-pf${args[*]:+ ${args[*]}}\`."
  echo
  "$exe" "${args[@]+"${args[@]}"}"
} >"$tmp"
mkdir -p docs/benchmarks
mv "$tmp" "$doc"
trap - EXIT
echo "bench-filters-pf.sh: wrote $doc" >&2
