#!/usr/bin/env bash
# The README's demo command: installs the dependencies, builds, then runs the
# whole chain on the embedded default dataset, writing into demo-out/ (or $1):
#   simulate (a room with 12 landmarks, one loop, noisy odometry, rendered
#   images) -> annotate (detect + measure every image) -> localize with the
#   EKF and the particle filter -> a short summary and the plots.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
OUT="${1:-demo-out}"
bash scripts/setup-deps.sh
bash scripts/build.sh
BIN=$ROOT/build/apps
CFG=$ROOT/share/codemark/config
rm -rf "$OUT" && mkdir -p "$OUT"
start=$(date +%s)

echo "== 1/4 simulate: $OUT/dataset"
"$BIN/codemark-simul/codemark-simul" --config "$ROOT/share/codemark/simul.ini" --out "$OUT/dataset"
echo "== 2/4 annotate: detect and measure every image"
"$BIN/codemark-annotate/codemark-annotate" -i "$OUT/dataset/dataset.rawlog" \
  -o "$OUT/dataset/annotated.rawlog"
for method in ekf pf; do
  echo "== localize: $method"
  "$BIN/codemark-localize/codemark-localize" --config "$CFG/$method.ini" --method "$method" \
    --rawlog "$OUT/dataset/annotated.rawlog" --map "$OUT/dataset/map.txt" \
    --gt "$OUT/dataset/gt_path.txt" --out "$OUT/$method"
done

echo
echo "== summary (ground truth: $OUT/dataset/gt_path.txt)"
printf '%-6s %8s %10s %12s %10s %12s\n' method steps ATE[m] yawRMSE[deg] NEES ms/step
# A field of a summary.json (flat, one "key": value per line).
field() { sed -n "s/^ *\"$2\": *\([^,]*\),*$/\1/p" "$1"; }
for method in ekf pf; do
  j="$OUT/$method/summary.json"
  printf '%-6s %8s %10.4f %12.3f %10.2f %12.4f\n' "$method" "$(field "$j" steps)" \
    "$(field "$j" ate_rmse_m)" "$(field "$j" yaw_rmse_deg)" "$(field "$j" nees_mean)" \
    "$(field "$j" time_per_step_ms)"
done
echo
echo "plots: $OUT/ekf/trajectory.png $OUT/pf/trajectory.png"
echo "demo: done in $(( $(date +%s) - start )) s after the build; outputs in $OUT/"
