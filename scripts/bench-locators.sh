#!/usr/bin/env bash
# The edge-locator benchmark (bench/locators: codemark-bench-locators): each
# locator of the detector's sub-pixel stage on synthetic camera profiles
# with a known edge, through blur, sharpening and the transfer curves; its
# error over sub-pixel phases and its time per profile. Writes
# docs/benchmarks/locators.md.
#
# Usage: scripts/bench-locators.sh [--quick] [other options of
#        codemark-bench-locators]
# --quick: fewer timed passes, report on stdout only.
# Environment: BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
quick=0
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --quick) quick=1; shift ;;
    *) args+=("$1"); shift ;;
  esac
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-locators
exe="$build_dir/bench/locators/codemark-bench-locators"
rev="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git diff --quiet HEAD -- libs bench 2>/dev/null; then rev="$rev with uncommitted changes in libs/ or bench/"; fi
if [[ $quick -eq 1 ]]; then
  "$exe" --repeat 100 --revision "commit $rev" "${args[@]}"
else
  mkdir -p docs/benchmarks
  "$exe" --revision "commit $rev" --out docs/benchmarks/locators.md "${args[@]}"
  echo "bench-locators.sh: wrote docs/benchmarks/locators.md"
fi
