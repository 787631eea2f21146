#!/usr/bin/env bash
# Builds and runs the pose benchmarks: the calibration of C_P
# (codemark-bench-pose-calib, the data behind the shipped calibrations
# share/codemark/calibration/*.ini) and the accuracy map
# (codemark-accuracy-map: the paper's survey grid on renders, closed form,
# general 6-DoF path and AprilTag 3), writing
# bench/accuracy_map/results/, copying the heat maps to docs/images/ and
# writing docs/benchmarks/pose.md (scripts/accuracy-report.py). About 15
# minutes on 2 cores; `--quick` runs a small map into a scratch folder
# instead.
#
# Usage: scripts/bench-accuracy.sh [--quick] [--build-dir DIR]
#        [--presets LIST [--renders N] [--renderer own|povray]]
# --presets LIST (comma-separated camera presets, docs/camera-pipeline.md)
# runs, instead of the above, the calibration tool and the accuracy map
# once per preset (codemark's renders through that camera; AprilTag's keep
# noise 2 and blur 0.8) and writes
# bench/accuracy_map/results/presets/NAME/ (summary.txt, cells.csv,
# heat maps, calibration.txt); --renders sets the map's renders per cell
# (default 4); --renderer povray renders the map's frames with POV-Ray
# (docs/povray.md; cached, so the other presets reuse the first one's
# renders) into bench/accuracy_map/results/presets-povray/NAME/
# (the map only: the calibration tool renders with the project's renderer).
# Environment: BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
quick=0
presets=""
renders=4
renderer=own
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    --quick) quick=1; shift ;;
    --presets) presets="$2"; shift 2 ;;
    --renders) renders="$2"; shift 2 ;;
    --renderer) renderer="$2"; shift 2 ;;
    *) echo "bench-accuracy.sh: unknown option $1" >&2; exit 1 ;;
  esac
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-pose-calib codemark-accuracy-map codemark-uncertainty
calib="$build_dir/bench/pose_calib/codemark-bench-pose-calib"
map="$build_dir/bench/accuracy_map/codemark-accuracy-map"
if [[ -n "$presets" ]]; then
  IFS=',' read -r -a names <<<"$presets"
  for p in "${names[@]}"; do
    if [[ "$renderer" == povray ]]; then
      dir="bench/accuracy_map/results/presets-povray/$p"
      mkdir -p "$dir"
      echo "== preset $p: accuracy map rendered by POV-Ray ($renders renders a cell)"
      "$map" --out "$dir" --renders "$renders" --preset "$p" --renderer povray
      continue
    fi
    dir="bench/accuracy_map/results/presets/$p"
    mkdir -p "$dir"
    echo "== preset $p: C_P calibration data (realistic scenes) and accuracy map ($renders renders a cell)"
    "$calib" --renders 1200 --seed 7 --realistic --preset "$p" --max-bearing 0.35 --max-height 0.5 \
      --max-distance 6 --max-angle 60 --uniform-distance --averaged >"$dir/calibration.txt"
    "$map" --out "$dir" --renders "$renders" --preset "$p"
  done
  exit 0
fi
if [[ $quick -eq 1 ]]; then
  "$calib" --renders 200 --realistic --max-bearing 0.35 --max-height 0.5
  "$map" --out "$build_dir/accuracy-map-quick" --renders 1 --max-distance 2
  exit 0
fi
echo "== C_P calibration (realistic scenes, the shipped values: clipped and unclipped sides averaged)"
"$calib" --renders 1200 --seed 7 --realistic --max-bearing 0.35 --max-height 0.5 --max-distance 6 --max-angle 60 --uniform-distance --averaged --noise-split 4
echo "== C_P calibration (realistic scenes, clipped sides apart)"
"$calib" --renders 1200 --seed 7 --realistic --max-bearing 0.35 --max-height 0.5 --max-distance 6 --max-angle 75 --uniform-distance
echo "== C_P calibration (the accuracy map's flat background: its C_P, calibration plain)"
"$calib" --renders 3000 --seed 7 --uniform-distance --noise-split 4
echo "== accuracy map"
"$map" --out bench/accuracy_map/results --renders 10
echo "== accuracy map with the shipped C_P of the textured, lit scenes (for comparison)"
"$map" --out bench/accuracy_map/results/realistic-calibration --renders 10 --no-apriltag --calibration realistic
"$build_dir/apps/codemark-uncertainty/codemark-uncertainty" --out apps/codemark-uncertainty/results/fig3.png
mkdir -p docs/images
for f in heat_l2 heat_phi2 heat_x heat_y; do
  cp "bench/accuracy_map/results/$f.png" "docs/images/accuracy-$f.png"
done
cp apps/codemark-uncertainty/results/fig3.png docs/images/uncertainty-fig3.png
python3 scripts/accuracy-report.py scripts/bench-accuracy.sh bench/accuracy_map/results \
  bench/accuracy_map/results/realistic-calibration >docs/benchmarks/pose.md
echo "bench-accuracy.sh: wrote docs/benchmarks/pose.md" >&2
