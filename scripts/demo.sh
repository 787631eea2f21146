#!/usr/bin/env bash
# The README's demo command: installs the dependencies, builds, then runs the
# whole chain on the embedded default dataset, writing into demo-out/ (or $1):
#   simulate (a room with 12 landmarks, one loop, noisy odometry, rendered
#   images) -> annotate (detect + measure every image) -> localize with the
#   EKF and the particle filter -> benchmark view of both runs (errors over
#   time against the filters' 3-sigma bounds) -> a short summary and the plots.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
OUT="${1:-demo-out}"
bash scripts/setup-deps.sh
bash scripts/build.sh
BIN=$ROOT/build/apps
CFG=$ROOT/share/codemark/config
rm -rf "$OUT" && mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
start=$(date +%s)

echo "== 1/4 simulate: $OUT/dataset"
"$BIN/codemark-simul/codemark-simul" --config "$ROOT/share/codemark/simul.ini" --out "$OUT/dataset"
echo "== 2/4 annotate: detect and measure every image"
# The simulated images are linear light without a camera's pipeline: the
# calibration fitted on such renders (docs/calibration.md).
"$BIN/codemark-annotate/codemark-annotate" -i "$OUT/dataset/dataset.rawlog" \
  -o "$OUT/dataset/annotated.rawlog" --calibration realistic
for method in ekf pf; do
  echo "== 3/4 localize: $method"
  "$BIN/codemark-localize/codemark-localize" --config "$CFG/$method.ini" --method "$method" \
    --rawlog "$OUT/dataset/annotated.rawlog" --map "$OUT/dataset/map.txt" \
    --gt "$OUT/dataset/gt_path.txt" --out "$OUT/$method"
done
echo "== 4/4 benchmark view: codemark-bench over the same rawlog (ekf, pf)"
cat > "$OUT/bench.ini" <<INI
# codemark-bench's ini for the demo dataset (share/codemark/bench.ini documents the keys).
[bench]
config_dir = $CFG
[dataset:demo]
rawlog = dataset/annotated.rawlog
map    = dataset/map.txt
gt     = dataset/gt_path.txt
INI
"$BIN/codemark-bench/codemark-bench" --config "$OUT/bench.ini" --out "$OUT/bench" --methods ekf,pf

# The summary, on stdout and as a report (summary.md).
summary() {
	echo "== summary (ground truth: $OUT/dataset/gt_path.txt; RPE over 1 s; NEES 95% band of a consistent filter)"
	printf '%-6s %6s %9s %9s %9s %13s %16s %10s %9s %8s\n' method steps ATE[m] max[m] RPE[m] yawRMSE[deg] \
		"NEES [band]" fix[s] ms/step NIS/DoF
	# results.csv: one row per method; the columns are named in its header.
	awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
	  { printf "%-6s %6d %9.4f %9.4f %9.4f %13.3f %6.2f [%.2f,%.2f] %10.1f %9.4f %8.2f\n", $c["method"],
	    $c["steps"], $c["ate_m"], $c["max_error_m"], $c["rpe_trans_m"], $c["yaw_rmse_deg"],
	    $c["nees_mean"], $c["nees_low_95"], $c["nees_high_95"], $c["first_fix_s"],
	    $c["filter_ms_per_step"], $c["nis_mean"] / $c["nis_dof"] }' "$OUT/bench/results.csv"
}
echo
summary
{
	echo "# codemark demo"
	echo
	echo "Written by \`scripts/demo.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC') ($(nproc) cores, $(uname -m)),"
	echo "commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown)."
	echo
	echo '```'
	summary
	echo '```'
} >"$OUT/summary.md"
echo "(codemark-bench seeds each job; codemark-localize's pf line above draws other random numbers)"
echo
echo "plots: $OUT/ekf/trajectory.png $OUT/pf/trajectory.png (estimate, truth, 95% ellipses)"
echo "       $OUT/bench/demo-error.png (position error against time with the 3-sigma bound)"
echo "       $OUT/bench/demo-trajectories.png (both estimates over the ground truth)"
echo "report: $OUT/bench/report.md; this summary: $OUT/summary.md"
echo "demo: done in $(( $(date +%s) - start )) s after the build; outputs in $OUT/"
