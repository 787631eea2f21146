#!/usr/bin/env bash
# codemark-detect prints spec section 5's fields, pose included, and its
# range agrees with the simulator's truth for the first image.
# usage: detect_json.sh CODEMARK_DETECT DATASET_DIR
set -euo pipefail
detect=$1 dir=$2
line=$("$detect" "$dir/dataset_Images/CAM_000000.png")
for key in '"image"' '"width"' '"height"' '"time_ms"' '"id"' '"corners"' '"P"' '"L"' '"C_L"' \
  '"pose_in_landmark"' '"C_R"'; do
  grep -q "$key" <<<"$line" || { echo "missing $key in: $line"; exit 1; }
done
# The first detection's range against the true horizontal distance from the
# camera (0.1 m ahead of the robot's first pose) to that landmark's centre.
id=$(sed -n 's/.*"detections": \[{"id": \([0-9]*\),.*/\1/p' <<<"$line")
l2=$(sed -n 's/.*"detections": \[{"id": [0-9]*,.*"L": \[\([-0-9.e]*\),.*/\1/p' <<<"$line")
read -r _ x y yaw < <(grep -v '^#' "$dir/gt_path.txt" | head -1)
truth=$(awk -v id="$id" -v x="$x" -v y="$y" -v a="$yaw" '!/^#/ && $1 == id {
  cx = x + 0.1 * cos(a); cy = y + 0.1 * sin(a); print sqrt(($2 - cx)^2 + ($3 - cy)^2) }' "$dir/map.txt")
echo "landmark $id: l2 $l2 m, truth $truth m"
awk -v a="$l2" -v b="$truth" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d < 0.02 * b) }'
# An unreadable input gives an error object and a failing exit code.
if "$detect" /nonexistent/none.png >/tmp/detect_json_err.$$ 2>/dev/null; then echo "exit 0 on a missing file"; exit 1; fi
grep -q '"error"' /tmp/detect_json_err.$$ && rm -f /tmp/detect_json_err.$$
