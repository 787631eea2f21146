#!/usr/bin/env bash
# Renders the POV-Ray test sets (docs/povray.md):
#  (a) the single-landmark set: 12 groups (light dim / normal / bright /
#      graded x print fluorescent / inkjet / laser), each a codemark-render
#      output directory (frame_NNN.png after the camera preset, linear_NNN.png
#      the 16-bit linear renders, truth.jsonl, poses.txt, set.ini,
#      render.ini, povray.ini, camera.ini);
#  (b) the room loop: codemark-simul's generated room, two laps at 5 Hz,
#      in both rawlog formats (actions-observations and observations-only).
# POV-Ray's renders are cached (outside the repository, keyed by a hash of
# each frame's scene text and settings), so a second run with another
# preset only re-runs the camera pipeline.
set -euo pipefail

usage()
{
	cat <<EOF
Usage: $0 --preset NAME [options]

Renders the POV-Ray test sets with the camera pipeline preset NAME
(linear, machine-vision, webcam, phone, family) applied to the cached
linear renders.

Options:
  --preset NAME         camera pipeline preset (required)
  --out DIR             output directory (default /work/povray-sets); the
                        sets go to DIR/NAME/single and DIR/NAME/room
  --build DIR           build directory with the apps (default: build)
  --cache DIR           POV-Ray render cache (default: \$CODEMARK_POVRAY_CACHE,
                        else \$XDG_CACHE_HOME/codemark/povray, else
                        ~/.cache/codemark/povray)
  --frames-per-group N  single-landmark frames per group (default 25: 300 in all)
  --groups LIST         comma-separated group names (default: all 12, e.g.
                        dim-fluorescent,normal-inkjet,...)
  --room-frames N       room-loop frames (default 0: the whole trajectory, 2 laps)
  --no-single           skip the single-landmark set
  --no-room             skip the room loop
  --room-formats LIST   rawlog formats of the room loop: actions, obs-only or
                        both, comma-separated (default actions,obs-only)
  -h, --help            this help
EOF
}

here=$(cd "$(dirname "$0")/.." && pwd)
preset=""
out=/work/povray-sets
build="$here/build"
per_group=25
groups=""
room_frames=0
do_single=1
do_room=1
room_formats=actions,obs-only
while [ $# -gt 0 ]; do
	case "$1" in
		--preset) preset=$2; shift 2 ;;
		--out) out=$2; shift 2 ;;
		--build) build=$2; shift 2 ;;
		--cache) export CODEMARK_POVRAY_CACHE=$2; shift 2 ;;
		--frames-per-group) per_group=$2; shift 2 ;;
		--groups) groups=$2; shift 2 ;;
		--room-frames) room_frames=$2; shift 2 ;;
		--no-single) do_single=0; shift ;;
		--no-room) do_room=0; shift ;;
		--room-formats) room_formats=$2; shift 2 ;;
		-h|--help) usage; exit 0 ;;
		*) echo "$0: unknown argument '$1' (see --help)" >&2; exit 2 ;;
	esac
done
for fmt in ${room_formats//,/ }; do
	if [ "$fmt" != actions ] && [ "$fmt" != obs-only ]; then
		echo "$0: --room-formats: unknown format '$fmt' (actions or obs-only)" >&2
		exit 2
	fi
done
if [ -z "$preset" ]; then
	echo "$0: --preset NAME is required (see --help)" >&2
	exit 2
fi
if ! command -v povray >/dev/null 2>&1; then
	echo "$0: povray not found (install POV-Ray 3.7: apt-get install povray)" >&2
	exit 1
fi
render="$build/apps/codemark-render/codemark-render"
simul="$build/apps/codemark-simul/codemark-simul"
for exe in "$render" "$simul"; do
	if [ ! -x "$exe" ]; then
		echo "$0: $exe not built (cmake --build $build --target codemark-render codemark-simul)" >&2
		exit 1
	fi
done
export CODEMARK_SHARE_DIR="$here/share/codemark"

# One group's poses: N level cameras at 0.5-5 m, view angle 0-60 deg
# either side of the normal, bearing and height (above and below the
# landmark centre, alternately) drawn so that the sheet stays in view of the
# 640 x 480, f = 800 px camera. Body frame 'x y z yaw pitch roll' (m, deg)
# of a camera looking at landmark 37 at (0, 0, 0.5), facing +x.
poses()
{
	local n=$1 seed=$2
	awk -v n="$n" -v seed="$seed" 'BEGIN {
		pi = atan2(0, -1); s = seed;
		# A 31-bit LCG: the same numbers with every awk.
		for (i = 0; i < n; ++i) {
			s = (s * 1103515245 + 12345) % 2147483648; u1 = s / 2147483648;
			s = (s * 1103515245 + 12345) % 2147483648; u2 = s / 2147483648;
			s = (s * 1103515245 + 12345) % 2147483648; u3 = s / 2147483648;
			s = (s * 1103515245 + 12345) % 2147483648; u4 = s / 2147483648;
			d = 0.5 + 4.5 * u1;
			a = 60 * u2 * (i % 4 < 2 ? 1 : -1);
			half = atan2(0.11, d) * 180 / pi;
			bmax = 0.8 * (21.8 - half); if (bmax < 0) bmax = 0;
			b = bmax * (2 * u3 - 1);
			hmax = 0.8 * (d * 0.3 - 0.11); if (hmax < 0) hmax = 0; if (hmax > 0.4) hmax = 0.4;
			h = hmax * (0.2 + 0.8 * u4) * (i % 2 ? -1 : 1);
			ar = a * pi / 180;
			printf "%.9f %.9f %.9f %.9f 0 0\n", d * cos(ar), d * sin(ar), 0.5 + h, a + 180 - b;
		}
	}'
}

# The print's colours as linear reflectances x 255 (BGR): fluorescent
# paper, an office inkjet's green (sRGB 40 170 80), a laser's (60 160 90).
print_green()
{
	case "$1" in
		fluorescent) echo "0 255 0" ;;
		inkjet) echo "20.4 102.5 5.4" ;;
		laser) echo "26.1 89.6 11.5" ;;
	esac
}

canonical=""
for light in dim normal bright gradient; do
	for print in fluorescent inkjet laser; do
		canonical="$canonical $light-$print"
	done
done
all_groups=$canonical
[ -n "$groups" ] && all_groups=$(echo "$groups" | tr ',' ' ')

if [ "$do_single" = 1 ]; then
	single="$out/$preset/single"
	mkdir -p "$single"
	printf '37 0 0 0.5 0\n' >"$single/map.txt"
	total=$(($(echo $all_groups | wc -w) * per_group))
	done_frames=0
	for g in $all_groups; do
		# The group's place in the full list sets its walls, lamps and seeds.
		k=0
		for c in $canonical; do
			[ "$c" = "$g" ] && break
			k=$((k + 1))
		done
		light=${g%%-*}
		print=${g#*-}
		green=$(print_green "$print")
		if [ -z "$green" ] || ! echo " dim normal bright gradient " | grep -q " $light "; then
			echo "$0: unknown group '$g'" >&2
			exit 2
		fi
		dir="$single/$g"
		mkdir -p "$dir"
		# The group's seed from its name: the same poses in every run.
		gseed=$(printf '%s' "$g" | cksum | cut -d' ' -f1)
		poses "$per_group" "$gseed" >"$dir/poses.txt"
		# Walls, floors and lamps vary between the groups.
		case $((k % 3)) in 0) wall=plaster ;; 1) wall=brick ;; 2) wall=plaster ;; esac
		case $((k % 2)) in 0) floor=tiles ;; 1) floor=wood ;; esac
		case $((k % 4)) in 3) ltype=area ;; *) ltype=point ;; esac
		level=$light gradient=0
		if [ "$light" = gradient ]; then
			level=normal
			gradient=$([ $((k % 2)) = 0 ] && echo 0.35 || echo -0.35)
		fi
		cat >"$dir/set.ini" <<EOF
# The scene keys of group $g (the camera keys come from --preset $preset).
[RENDER]
background = Textured
background_grey = 150
distractors = 0
green_bgr = $green
EOF
		args=(--map "$single/map.txt" --out "$dir" --poses "$dir/poses.txt" --options "$dir/set.ini"
			--preset "$preset" --seed "$((k + 1))" --renderer povray --light "$level"
			--light-type "$ltype" --light-gradient "$gradient" --wall "$wall" --floor "$floor"
			--texture-seed "$((k + 1))" --linear --quiet)
		echo "codemark-render ${args[*]}" >"$dir/command.txt"
		"$render" "${args[@]}" >/dev/null
		done_frames=$((done_frames + per_group))
		echo "povray-sets: single-landmark set $done_frames/$total frames ($g)"
	done
fi

if [ "$do_room" = 1 ]; then
	room="$out/$preset/room"
	mkdir -p "$room"
	cat >"$room/room.ini" <<EOF
# The room loop: codemark-simul's generated 6 x 4 m room with 12 landmarks,
# two laps at 0.4 m/s, 5 Hz images; odometry from MRPT's Gaussian model.
[trajectory]
loops = 2
[dataset]
frame_rate_hz = 5
seed = 1
[render]
background = Textured
EOF
	for fmt in ${room_formats//,/ }; do
		flag=()
		[ "$fmt" = obs-only ] && flag=(--obs-only)
		echo "povray-sets: room loop ($fmt format)"
		"$simul" --config "$room/room.ini" --out "$room/$fmt" "${flag[@]}" --preset "$preset" \
			--renderer povray --light normal --wall plaster --floor tiles --max-frames "$room_frames"
	done
fi
echo "povray-sets: done: $out/$preset"
