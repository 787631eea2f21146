#!/usr/bin/env bash
# The filters per camera: the simulated room loops (bench/filters_sim) with
# the project's renderer through each camera preset (SEEDS seeds), and the
# POV-Ray room loop (scripts/povray-sets.sh: two laps, 5 Hz) through each
# preset; every method (ekf, ekf-pose, ekf-slam, pf) from an unknown start.
# Writes docs/benchmarks/filters-cameras.md.
#
# The POV-Ray loop is rendered once into SETS (default
# $HOME/.cache/codemark/povray-sets) and its renders cached (docs/povray.md):
# the first run ray-traces its frames (5-15 s each on one core), later runs
# and other presets only re-run the camera pipeline.
#
# With --calibration FILE|NAME other than the tools' default (family), C_P comes from it
# (docs/calibration.md) and the report is filters-cameras-<name>.md.
#
# Usage: scripts/bench-filters-cameras.sh [--presets LIST] [--no-povray] [--calibration FILE|NAME]
# Environment: BUILD_DIR (default build-bench), SEEDS (default 3), SETS,
# WORK (scratch folder for the own renderer's datasets).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
SEEDS="${SEEDS:-3}"
SETS="${SETS:-$HOME/.cache/codemark/povray-sets}"
WORK="${WORK:-/tmp/codemark_bench_filters_cameras}"
DOC="$ROOT/docs/benchmarks/filters-cameras.md"
presets="linear,webcam,phone,family"
povray=1
calibration=family
while [[ $# -gt 0 ]]; do
	case "$1" in
		-h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
		--presets) presets="$2"; shift 2 ;;
		--no-povray) povray=0; shift ;;
		--calibration) calibration="$2"; shift 2 ;;
		*) echo "bench-filters-cameras.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
	esac
done
if [[ $povray -eq 1 ]] && ! command -v povray >/dev/null; then
	echo "bench-filters-cameras.sh: povray not found: install it with 'apt-get install povray' (scripts/setup-deps.sh does), or pass --no-povray" >&2
	exit 1
fi
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target filters_sim codemark-render codemark-simul >/dev/null
datasets=()
if [[ $povray -eq 1 ]]; then
	IFS=',' read -r -a names <<<"$presets"
	for p in "${names[@]}"; do
		bash "$ROOT/scripts/povray-sets.sh" --preset "$p" --no-single --room-formats actions \
			--out "$SETS" --build "$BUILD_DIR" >&2
		datasets+=(--dataset "POV-Ray room, preset $p=$SETS/$p/room/actions")
	done
fi
start=$SECONDS
body=$("$BUILD_DIR/bench/filters_sim/filters_sim" --work "$WORK" --seeds "$SEEDS" --preset "$presets" \
	--no-phi2-table --calibration "$calibration" "${datasets[@]}")
if [[ "$calibration" != family ]]; then
	DOC="$ROOT/docs/benchmarks/filters-cameras-$(basename "$calibration" .ini).md"
fi
mkdir -p "$(dirname "$DOC")"
{
	echo "# Filter benchmarks per camera"
	echo
	echo "Written by \`scripts/bench-filters-cameras.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores,"
	echo "$(uname -m)), commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown); $((SECONDS - start)) s."
	echo "Rows \"preset NAME\": the project's renderer, codemark-simul's default room"
	echo "loop ($SEEDS seeds) through that camera preset (docs/camera-pipeline.md). Rows"
	echo "\"POV-Ray room\": the POV-Ray room loop of scripts/povray-sets.sh (one run, two"
	echo "laps, no odometry scale error) through that preset. The detector and the"
	echo "filters' configs are the shipped ones; C_P comes from the calibration"
	echo "\`$calibration\` (docs/calibration.md)."
	echo
	echo "$body" | sed 's/^### /## /'
} >"$DOC"
echo "bench-filters-cameras.sh: wrote $DOC" >&2
