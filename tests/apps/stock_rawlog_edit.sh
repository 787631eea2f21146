#!/usr/bin/env bash
# Stock rawlog-edit with our plugin lists our class once per image.
# usage: stock_rawlog_edit.sh PLUGIN_SO DATASET_DIR
set -euo pipefail
plugin=$1 dir=$2
cd "$dir"  # stock tools resolve external images relative to the current folder
images=$(grep -c . gt_path.txt)
images=$((images - 1))  # header line
rm -f out.txt
rawlog-edit -p "$plugin" --list-timestamps -i annotated.rawlog >/dev/null
ours=$(grep -c ' codemark::CObservationCodedLandmarks$' out.txt || true)
echo "rawlog-edit listed $ours codemark::CObservationCodedLandmarks for $images images"
test "$ours" -eq "$images"
# Without the plugin rawlog-edit stops at our first object (MRPT 2.5.8 still
# exits 0): the file must not look complete to it.
rm -f out.txt
rawlog-edit --list-timestamps -i annotated.rawlog >/dev/null 2>&1 || true
without=$(grep -c ' codemark::CObservationCodedLandmarks$' out.txt 2>/dev/null || true)
echo "without the plugin: ${without:-0}"
test "${without:-0}" -eq 0
