#!/usr/bin/env bash
# Stock kf-slam (CRangeBearingKFSLAM2D) runs on the BearingRange twin of a
# simulated dataset; its landmark map is compared with the true map by
# kf-slam itself (ground_truth_file: x y z . . . ID per row, in the frame of
# the robot's start, where kf-slam's map lives; z = 0: kf-slam's 2D map is
# at z = 0 but it compares in 3D).
# kf-slam has no plugin option: LD_PRELOAD makes it read our classes.
# usage: stock_kfslam.sh PLUGIN_SO KFSLAM_INI DATASET_DIR MAX_MEAN_ERROR_M
set -euo pipefail
plugin=$1 ini=$2 dir=$3 bound=$4
cd "$dir"
# The robot's start pose (first ground-truth row) and the map in its frame.
read -r _ x0 y0 yaw0 < <(grep -v '^#' gt_path.txt | head -1)
grep -v '^#' map.txt | awk -v x0="$x0" -v y0="$y0" -v a="$yaw0" 'NF >= 5 {
  dx = $2 - x0; dy = $3 - y0;
  printf "%.6f %.6f 0 0 0 0 %d\n", cos(a)*dx + sin(a)*dy, -sin(a)*dx + cos(a)*dy, $1 }' > kfslam_gt_map.txt
sed -e "s|^ground_truth_file *=.*|ground_truth_file = kfslam_gt_map.txt|" "$ini" > kfslam_run.ini
LD_PRELOAD="$plugin" kf-slam kfslam_run.ini br_only.rawlog </dev/null > kfslam.log 2>&1
mean=$(sed -n 's/.*Mean Error: \([0-9.eE+-]*\) meters.*/\1/p' kfslam.log | tail -1)
test -n "$mean" || { echo "kf-slam printed no landmark error"; tail -20 kfslam.log; exit 1; }
lms=$(sed -n 's/.*# of landmarks in the map: \([0-9]*\).*/\1/p' kfslam.log | tail -1)
echo "kf-slam: $lms landmarks, mean error against the true map $mean m (bound $bound m)"
awk -v m="$mean" -v b="$bound" 'BEGIN { exit !(m <= b) }'
