#!/usr/bin/env bash
# The per-camera benchmark (bench/camera: codemark-bench-camera): the
# detector and the shipped C_P on the POV-Ray single-landmark set
# (scripts/povray-sets.sh) and on the project's renderer at the same poses,
# each through the camera presets linear, webcam, phone and family; writes
# docs/benchmarks/camera.md and docs/benchmarks/camera-frames.csv (one row
# per frame). With --calibration FILE|NAME (docs/calibration.md) other than
# the tools' default (family), C_P comes from it and the report is camera-<name>.md.
#
# The set is rendered by scripts/povray-sets.sh into SETS (default
# $HOME/.cache/codemark/povray-sets); POV-Ray's renders are cached outside
# the repository, keyed by a hash of each scene (docs/povray.md), so a
# second run renders nothing. The first renders the set's 300 frames: 5-15 s
# a frame on one core.
#
# Usage: scripts/bench-camera.sh [--quick] [--presets linear,webcam,phone,family]
#        [--frames-per-group N] [--build-dir DIR] [--calibration FILE|NAME] [other options of
#        codemark-bench-camera]
# --quick: 2 frames per group, report on stdout only.
# Environment: BUILD_DIR (default build-bench), SETS.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
presets="linear,webcam,phone,family"
per_group=25
sets="${SETS:-$HOME/.cache/codemark/povray-sets}"
quick=0
calibration=family
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -h|--help) sed -n '2,24p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    --quick) quick=1; shift ;;
    --presets) presets="$2"; shift 2 ;;
    --frames-per-group) per_group="$2"; shift 2 ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    --calibration) calibration="$2"; args+=("$1" "$2"); shift 2 ;;
    *) args+=("$1"); shift ;;
  esac
done
if [[ $quick -eq 1 ]]; then per_group=2; sets="$sets-quick"; fi
if ! command -v povray >/dev/null; then
  echo "bench-camera.sh: povray not found: install it with 'apt-get install povray' (scripts/setup-deps.sh does)" >&2
  exit 1
fi
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-camera codemark-render codemark-simul
bash scripts/povray-sets.sh --preset linear --no-room --out "$sets" --build "$build_dir" \
  --frames-per-group "$per_group"
exe="$build_dir/bench/camera/codemark-bench-camera"
rev="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git diff --quiet HEAD -- libs bench 2>/dev/null; then rev="$rev with uncommitted changes in libs/ or bench/"; fi
run=("$exe" --set "$sets/linear/single" --source own,povray --preset "$presets" --revision "commit $rev" "${args[@]}")
if [[ $quick -eq 1 ]]; then
  "${run[@]}"
else
  mkdir -p docs/benchmarks
  # The default calibration's report is camera.md; another's camera-<name>.md.
  name=camera
  if [[ "$calibration" != family ]]; then name="camera-$(basename "$calibration" .ini)"; fi
  "${run[@]}" --out "docs/benchmarks/$name.md" --csv "docs/benchmarks/$name-frames.csv"
  echo "bench-camera.sh: wrote docs/benchmarks/$name.md and docs/benchmarks/$name-frames.csv"
fi
