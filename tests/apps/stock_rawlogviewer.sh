#!/usr/bin/env bash
# Stock RawLogViewer (-l plugin) opens an annotated rawlog under Xvfb; a
# click on our observation shows its description. Keeps the screenshots.
# usage: stock_rawlogviewer.sh PLUGIN_SO DATASET_DIR ARTEFACT_DIR
set -euo pipefail
plugin=$1 dir=$2 art=$3
mkdir -p "$art"
display=":$(( 90 + $$ % 100 ))"
Xvfb "$display" -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
xvfb=$!
viewer=
cleanup() { [ -n "$viewer" ] && kill "$viewer" 2>/dev/null; kill "$xvfb" 2>/dev/null; true; }
trap cleanup EXIT
export DISPLAY=$display
sleep 1
cd "$dir"
RawLogViewer -l "$plugin" annotated.rawlog >"$art/rawlogviewer.log" 2>&1 &
viewer=$!
main=
for _ in $(seq 1 60); do
  main=$(xdotool search --name "RawlogViewer - Part of the MRPT project" 2>/dev/null | head -1 || true)
  [ -n "$main" ] && break
  sleep 0.5
done
test -n "$main" || { echo "RawLogViewer did not open a window"; exit 1; }
sleep 4  # loading
xdotool windowsize "$main" 1270 1000
xdotool windowmove "$main" 0 0
sleep 1
# Close the "Did you know" tip (it starts on top of the tree), then select
# the first codemark observation: the third row of entry [1].
xdotool mousemove 570 239 click 1
sleep 1
import -window root "$art/rawlogviewer_loaded.png"
xdotool mousemove 160 191 click 1
sleep 2
import -window root "$art/rawlogviewer.png"
# The description pane (right of the tree) must now hold text: compare its
# ink before and after selecting our observation.
crop=850x330+410+100
before=$(convert "$art/rawlogviewer_loaded.png" -crop $crop -colorspace Gray -format "%[fx:mean]" info:)
after=$(convert "$art/rawlogviewer.png" -crop $crop -colorspace Gray -format "%[fx:mean]" info:)
echo "description pane mean grey: before $before, after $after"
awk -v b="$before" -v a="$after" 'BEGIN { exit !(a < b - 0.01) }'
# The tree region is not blank either.
tree=$(convert "$art/rawlogviewer.png" -crop 380x700+0+100 -colorspace Gray -format "%[fx:standard_deviation]" info:)
echo "tree region grey stddev: $tree"
awk -v t="$tree" 'BEGIN { exit !(t > 0.05) }'
