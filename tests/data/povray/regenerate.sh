#!/usr/bin/env bash
# Regenerates the committed POV-Ray renders of tests/data/povray (see
# docs/povray.md):
#  edge-high/, edge-low/: a small frame (240 x 200 px, principal point off
#    the centre, camera rolled and pitched) of landmark 37 under flat
#    ambient light, for the edge-placement and camera-mapping tests: the
#    fluorescent print at normal light (high contrast), and a dark green
#    print (B G R 25 45 25 against the black 25) at dim light (low
#    contrast: 7 grey levels);
#  set/: the first frame of six groups of the single-landmark set
#    (scripts/povray-sets.sh), linear renders with truth.
# Usage: regenerate.sh [BUILD_DIR] (default: build)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../../.." && pwd)
build=${1:-$root/build}
render="$build/apps/codemark-render/codemark-render"
if ! command -v povray >/dev/null 2>&1; then
	echo "$0: povray not found (install POV-Ray 3.7: apt-get install povray)" >&2
	exit 1
fi
[ -x "$render" ] || { echo "$0: $render not built" >&2; exit 1; }
export CODEMARK_SHARE_DIR="$root/share/codemark"
export CODEMARK_POVRAY_CACHE=${CODEMARK_POVRAY_CACHE:-$(mktemp -d)}

for kind in high low; do
	dir="$here/edge-$kind"
	mkdir -p "$dir"
	rm -f "$dir"/frame_*.png "$dir"/linear_*.png
	if [ $kind = high ]; then light=normal green="0 255 0"; else light=dim green="25 45 25"; fi
	cat >"$dir/edge.ini" <<INI
# Flat ambient light on a plain wall; no camera stage: the linear render is
# the test's input.
[RENDER]
background = Flat
background_grey = 128
distractors = 0
noise_sigma = 0
blur_sigma_px = 0
green_bgr = $green
INI
	"$render" --map "$here/map.txt" --camera "$here/camera-edge.ini" --poses "$here/edge-pose.txt" \
		--options "$dir/edge.ini" --out "$dir" --renderer povray --light "$light" \
		--light-type ambient --wall plain --linear --quiet
	rm -f "$dir"/frame_*.png
done

# The set's subset: one frame of six groups, the linear preset (the linear
# renders do not depend on it).
"$root/scripts/povray-sets.sh" --preset linear --out "$here/.set-tmp" --build "$build" \
	--frames-per-group 1 --no-room \
	--groups dim-fluorescent,normal-fluorescent,bright-fluorescent,gradient-fluorescent,normal-inkjet,dim-laser
rm -rf "$here/set"
mkdir -p "$here/set"
for g in "$here"/.set-tmp/linear/single/*/; do
	name=$(basename "$g")
	mkdir -p "$here/set/$name"
	cp "$g"/{linear_000.png,truth.jsonl,poses.txt,set.ini,render.ini,povray.ini,camera.ini} "$here/set/$name/"
done
cp "$here/.set-tmp/linear/single/map.txt" "$here/set/map.txt"
rm -rf "$here/.set-tmp"
echo "regenerate.sh: wrote $here/{edge-high,edge-low,set}"
