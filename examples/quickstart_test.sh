#!/usr/bin/env bash
# Renders one view of the example map and runs the README's example on it:
# it must read every landmark in view and put the robot near the rendered
# camera's pose.
# usage: quickstart_test.sh QUICKSTART CODEMARK_RENDER SHARE_DIR
set -euo pipefail
example=$1 render=$2 share=$3
tmp=$(mktemp -d "${TMPDIR:-/tmp}/codemark-quickstart.XXXX")
trap 'rm -rf "$tmp"' EXIT
"$render" -q -m "$share/example-map.txt" -c "$share/camera-paper.ini" -n 1 -s 3 -o "$tmp/render" >/dev/null
image=$(ls "$tmp"/render/*.png | head -1)
out=$("$example" "$image" "$share/camera-paper.ini" "$share/example-map.txt" "$share/config/ekf.ini")
echo "$out"
grep -q "^landmark [0-9]*: range" <<<"$out"
grep -q "^robot at x" <<<"$out"
# The robot (its origin under the camera) within 5 cm and 1 deg of the
# rendered camera's planar pose.
python3 - "$tmp/render/truth.jsonl" "$out" <<'PY'
import json, math, re, sys
truth = json.loads(open(sys.argv[1]).readline())["camera_pose"]
m = re.search(r"robot at x (\S+) m, y (\S+) m, yaw (\S+) rad", sys.argv[2])
x, y, yaw = map(float, m.groups())
err = math.hypot(x - truth[0], y - truth[1])
dyaw = abs((yaw - truth[3] + math.pi) % (2 * math.pi) - math.pi)
assert err < 0.05 and dyaw < math.radians(1), f"robot {x} {y} {yaw} vs camera {truth}"
PY
