#!/usr/bin/env bash
# Which camera stage costs the detector how much accuracy: the error of the
# primary measurement P = [x1 y1 x2 y2] (codemark-bench-pose-calib's
# per-detection CSV: detected against the renderer's exact P) per apparent
# width of the reference square and per print, on the project's renderer's textured wall
# with the prints and lights varied (--realistic --vary-scene), through
#  - "sensor": the linear preset with the webcam's sensor (full well 8000 e-,
#    read noise 6 e-), the peer of every other row;
#  - that sensor with one stage of docs/camera-pipeline.md added (the
#    webcam's and the phone's settings, each demosaicing algorithm);
#  - the webcam preset with one stage removed (the sensor's noise too: what
#    is left is the processing's own, the same in every frame of a still
#    camera);
#  - the presets webcam, phone and family whole, and phone without the
#    sensor's noise.
# Every row renders the same poses, prints, lights and noise seeds, so the
# rows differ by their stages alone. Writes docs/benchmarks/pipeline-stages.md.
#
# Usage: scripts/bench-pipeline-stages.sh [--renders N] [--seed N]
# Environment: BUILD_DIR (default build-bench), WORK (scratch folder).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
WORK="${WORK:-/tmp/codemark_bench_stages}"
DOC="$ROOT/docs/benchmarks/pipeline-stages.md"
renders=500
seed=11
while [[ $# -gt 0 ]]; do
	case "$1" in
		-h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
		--renders) renders="$2"; shift 2 ;;
		--seed) seed="$2"; shift 2 ;;
		*) echo "bench-pipeline-stages.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
	esac
done
if ! [[ $renders =~ ^[0-9]+$ && $renders -ge 50 && $seed =~ ^[0-9]+$ ]]; then
	echo "bench-pipeline-stages.sh: expected --renders >= 50 and a whole --seed" >&2
	exit 2
fi
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target codemark-bench-pose-calib >/dev/null
calib="$BUILD_DIR/bench/pose_calib/codemark-bench-pose-calib"
rm -rf "$WORK"
mkdir -p "$WORK"
start_time=$SECONDS

sensor='preset = linear;full_well_e = 8000;read_noise_e = 6'
# name|label|[render] keys (;-separated)
rows=(
	"sensor|sensor (linear preset, full well 8000 e-, read 6 e-)|$sensor"
	"optics|+ optics: blur sigma 0.6 px|$sensor;blur_sigma_px = 0.6"
	"defocus|+ optics: defocus radius 1.5 px|$sensor;defocus_radius_px = 1.5"
	"ca|+ chromatic aberration +-0.3 px|$sensor;ca_red_px = 0.3;ca_blue_px = -0.3"
	"vignetting|+ vignetting 0.2|$sensor;vignetting = 0.2"
	"wb|+ white balance R 1.05, B 0.95|$sensor;wb_red = 1.05;wb_blue = 0.95"
	"bilinear|+ RGGB, bilinear demosaicing|$sensor;bayer = RGGB;demosaic = bilinear"
	"vng|+ RGGB, VNG demosaicing|$sensor;bayer = RGGB;demosaic = vng"
	"edge-aware|+ RGGB, edge-aware demosaicing|$sensor;bayer = RGGB;demosaic = edge-aware"
	"srgb|+ sRGB transfer|$sensor;transfer = srgb"
	"filmic|+ filmic 0.25 transfer|$sensor;transfer = filmic;filmic_strength = 0.25"
	"unsharp05|+ unsharp sigma 1.0, amount 0.5|$sensor;unsharp_sigma_px = 1.0;unsharp_amount = 0.5"
	"unsharp09|+ unsharp sigma 1.0, amount 0.9|$sensor;unsharp_sigma_px = 1.0;unsharp_amount = 0.9"
	"jpeg85|+ JPEG 85|$sensor;jpeg_quality = 85"
	"jpeg75|+ JPEG 75|$sensor;jpeg_quality = 75"
	"chroma422|+ chroma 4:2:2, uncompressed (YUYV)|$sensor;chroma_subsampling = 422"
	"chroma420|+ chroma 4:2:0, uncompressed (NV12)|$sensor;chroma_subsampling = 420"
	"webcam|webcam (every stage)|preset = webcam"
	"webcam-bayer|webcam without the mosaic|preset = webcam;bayer = none"
	"webcam-srgb|webcam with linear transfer|preset = webcam;transfer = linear"
	"webcam-unsharp|webcam without unsharp masking|preset = webcam;unsharp_amount = 0"
	"webcam-jpeg|webcam without JPEG|preset = webcam;jpeg_quality = 0"
	"webcam-noise|webcam without the sensor's noise|preset = webcam;full_well_e = 0"
	"phone|phone (every stage)|preset = phone"
	"phone-noise|phone without the sensor's noise|preset = phone;full_well_e = 0"
	"family|family (every stage drawn per frame)|preset = family"
)

run_row() { # index
	local name label keys
	IFS='|' read -r name label keys <<<"${rows[$1]}"
	printf '[render]\n%s\n' "${keys//;/$'\n'}" >"$WORK/$name.ini"
	"$calib" --renders "$renders" --seed "$seed" --realistic --vary-scene \
		--render-config "$WORK/$name.ini" --max-bearing 0.35 --max-height 0.5 \
		--max-distance 6 --max-angle 60 --uniform-distance --csv "$WORK/$name.csv" \
		>"$WORK/$name.log" 2>&1 || {
		echo "bench-pipeline-stages.sh: $name failed:" >&2
		tail -3 "$WORK/$name.log" >&2
		return 1
	}
}
jobs_max=$(nproc)
for i in "${!rows[@]}"; do
	while [[ $(jobs -rp | wc -l) -ge $jobs_max ]]; do wait -n; done
	run_row "$i" &
	printf '\rbench-pipeline-stages.sh: %d / %d configurations started' $((i + 1)) ${#rows[@]} >&2
done
wait
echo >&2

table_args=()
for r in "${rows[@]}"; do
	IFS='|' read -r name label _ <<<"$r"
	table_args+=("$name" "$label")
done
{
	echo "# Accuracy per camera stage"
	echo
	echo "Written by \`scripts/bench-pipeline-stages.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores,"
	echo "$(uname -m)), commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown); $((SECONDS - start_time)) s; do not edit by hand."
	echo
	echo "The project's renderer, a textured wall, one landmark at 0.5-6 m (uniform"
	echo "in distance), view angles up to 60 deg, bearings within 0.35 rad, camera"
	echo "heights within 0.5 m; prints (fluorescent, inkjet, laser green) and lights"
	echo "(normal, dim, bright, graded) cycled; $renders renders per row, seed $seed: every row"
	echo "draws the same poses, prints, lights and noise seeds and differs from the"
	echo "first by its stages alone (docs/camera-pipeline.md). \"x\" is the RMS error"
	echo "of P's x1 and x2 (an edge's position), \"y\" of y1 and y2 (an edge's"
	echo "half-length), against the renderer's exact P [px], per apparent width of"
	echo "the reference square; \"x 25-80 px\" is that error over the widths 25-80 px"
	echo "as a ratio to the sensor row's (the peer in this run)."
	echo
	echo "## Per apparent width"
	echo
	python3 "$ROOT/scripts/pipeline-stages-table.py" "$WORK" "${table_args[@]}"
} >"$DOC.tmp"
mv "$DOC.tmp" "$DOC"
echo "bench-pipeline-stages.sh: wrote $DOC ($((SECONDS - start_time)) s)" >&2
