#!/usr/bin/env bash
# The sighting noise identified from a recorded run, without ground truth
# (codemark-calibrate-noise), on room loops through camera presets: the
# project's renderer (codemark-simul's room, two runs: seeds 1 and 2) and
# the POV-Ray room loop of scripts/povray-sets.sh (two laps; two runs:
# seeds 1 and 2, other odometry and sensor noise over the same path). Each
# fit starts from the default calibration with every sigma divided by
# START_DIVISOR (default 3: C_P / 9) and uses run 1 only; the EKF and the
# particle filter then localize both runs with the fitted calibration, and
# with the start and the default for reference. The loops' odometry is a
# fine wheel odometry (0.5% of the distance; floors 0.5 mm, 0.02 deg per
# reading), where the innovations see the sightings' noise (docs/design.md).
# Writes docs/benchmarks/noise.md.
#
# Usage: scripts/bench-noise.sh [--presets LIST] [--no-povray]
# Environment: BUILD_DIR (default build-bench), WORK (scratch folder),
# START_DIVISOR.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
WORK="${WORK:-/tmp/codemark_bench_noise}"
START_DIVISOR="${START_DIVISOR:-3}"
DOC="$ROOT/docs/benchmarks/noise.md"
presets="webcam,phone"
povray=1
while [[ $# -gt 0 ]]; do
	case "$1" in
		-h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
		--presets) presets="$2"; shift 2 ;;
		--no-povray) povray=0; shift ;;
		*) echo "bench-noise.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
	esac
done
if [[ $povray -eq 1 ]] && ! command -v povray >/dev/null; then
	echo "bench-noise.sh: povray not found: install it with 'apt-get install povray' (scripts/setup-deps.sh does), or pass --no-povray" >&2
	exit 1
fi
cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target codemark-simul codemark-localize \
	codemark-calibrate-noise >/dev/null
bin="$BUILD_DIR/apps"
share="$ROOT/share/codemark"
mkdir -p "$WORK"
start_time=$SECONDS

# The fine odometry, for both renderers.
odometry='[odometry]
motion_model = gaussian
gaussian_alpha_1 = 0.005
gaussian_alpha_2 = 0.001
gaussian_alpha_3 = 0.005
gaussian_alpha_4 = 0.01
gaussian_min_std_xy = 0.0005
gaussian_min_std_phi_deg = 0.02'
echo "$odometry" >"$WORK/own.ini"
printf '[trajectory]\nloops = 2\n[dataset]\nframe_rate_hz = 5\n[render]\nbackground = Textured\n%s\n' \
	"$odometry" >"$WORK/povray.ini"

# The start: the default calibration with every sigma divided.
start="$WORK/start.ini"
awk -v f="$START_DIVISOR" '
	/^(sigma_px|sigma_y_px|growth_x_px|growth_y_px|clipped_side_sigma_px) = / { print $1 " = " $3 / f; next }
	/^(sigma_x_table|sigma_y_table|noise_sigma_x_table|noise_sigma_y_table) = ./ {
		line = $1 " ="; for (i = 3; i <= NF; ++i) { split($i, p, ":"); line = line " " p[1] ":" p[2] / f }
		print line; next }
	{ print }' "$share/calibration/family.ini" >"$start"

# summary.json's value of KEY (a list's items joined by ", ").
json() {
	python3 -c 'import json, sys
v = json.load(open(sys.argv[1])).get(sys.argv[2])
print(", ".join(map(str, v)) if isinstance(v, list) else ("" if v is None else v))' "$1" "$2"
}

rows=()
fit_rows=()
run_set() { # name renderer preset
	local name="$1" renderer="$2" preset="$3" dir="$WORK/$1"
	for seed in 1 2; do
		if [[ ! -f "$dir/run$seed/dataset.rawlog" ]]; then
			mkdir -p "$dir/run$seed"
			if [[ $renderer == own ]]; then
				"$bin/codemark-simul/codemark-simul" -q -c "$WORK/own.ini" -s "$seed" \
					--preset "$preset" -o "$dir/run$seed" >&2
			else
				"$bin/codemark-simul/codemark-simul" -q -c "$WORK/povray.ini" -s "$seed" \
					--preset "$preset" --renderer povray --light normal --wall plaster --floor tiles \
					-o "$dir/run$seed" >&2
			fi
		fi
	done
	local t0=$SECONDS frames
	"$bin/codemark-calibrate-noise/codemark-calibrate-noise" -q -r "$dir/run1/dataset.rawlog" \
		-m "$dir/run1/map.txt" --calibration "$start" -o "$dir/fit.ini" >"$dir/fit.log" 2>&1
	frames=$(sed -n 's/^codemark-calibrate-noise: \([0-9]*\) frames.*/\1/p' "$dir/fit.log")
	fit_rows+=("| $name | $frames | $((SECONDS - t0)) | $(grep -c warning "$dir/fit.log" || true) |")
	sed -n 's/^  \(sigma_px\|growth_x_px\|sigma_y_px\|growth_y_px\) *\([^ ]*\) *\([^ ]*\) *\([^ ]*\) *\(.*\)$/\1 \2 \3 \4 \5/p' \
		"$dir/fit.log" >"$dir/scales.txt"
	for seed in 1 2; do
		for cal in fit start family; do
			local c="$dir/fit.ini"
			[[ $cal == start ]] && c="$start"
			[[ $cal == family ]] && c=family
			for method in ekf pf; do
				local out="$dir/out-$seed-$cal-$method"
				"$bin/codemark-localize/codemark-localize" -q -c "$share/config/$method.ini" \
					--method "$method" -r "$dir/run$seed/dataset.rawlog" -m "$dir/run$seed/map.txt" \
					-g "$dir/run$seed/gt_path.txt" --calibration "$c" -o "$out" >/dev/null
				local s="$out/summary.json" band
				band=$(json "$s" nees_band_95)
				rows+=("| $name | $seed | $cal | $method | $(awk -v a="$(json "$s" ate_rmse_m)" 'BEGIN{printf "%.2f", 100*a}') | $(awk -v a="$(json "$s" nees_mean)" 'BEGIN{printf "%.2f", a}') [${band/, /, }] | $(awk -v a="$(json "$s" nis_mean)" -v d="$(json "$s" nis_dof)" 'BEGIN{printf "%.2f", a/d}') | $(awk -v a="$(json "$s" nis_visit_ratio)" 'BEGIN{printf "%.2f", a}') | $(json "$s" nis_verdict) | $(awk -v a="$(json "$s" gated_fraction)" 'BEGIN{printf "%.1f", 100*a}') |")
			done
		done
	done
	echo "bench-noise.sh: $name done" >&2
}

IFS=',' read -r -a names <<<"$presets"
for p in "${names[@]}"; do run_set "own-$p" own "$p"; done
if [[ $povray -eq 1 ]]; then
	for p in "${names[@]}"; do run_set "povray-$p" povray "$p"; done
fi

mkdir -p "$(dirname "$DOC")"
{
	echo "# Sighting noise calibrated from a run"
	echo
	echo "Written by \`scripts/bench-noise.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores,"
	echo "$(uname -m)), commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown); $((SECONDS - start_time)) s."
	echo "Datasets \"own-PRESET\": codemark-simul's room loop (one lap, 5 Hz) through the"
	echo "camera preset; \"povray-PRESET\": the POV-Ray room loop (two laps, 5 Hz). Run 1"
	echo "and run 2 are seeds 1 and 2 (other odometry and sensor noise); the loops'"
	echo "odometry is a fine wheel odometry (0.5% of the distance, floors 0.5 mm and"
	echo "0.02 deg per reading). \`codemark-calibrate-noise\` fits the sighting noise on"
	echo "run 1 alone, from the default calibration with every sigma divided by"
	echo "$START_DIVISOR (\"start\"); both runs are then localized with the fit, the start and"
	echo "the default (\"family\"), from an unknown start pose with the shipped configs."
	echo
	echo "## The fits"
	echo
	echo "| dataset | frames | fit time [s] | warnings |"
	echo "|---|---|---|---|"
	printf '%s\n' "${fit_rows[@]}"
	echo
	for p in "${names[@]}"; do
		for r in own povray; do
			f="$WORK/$r-$p/scales.txt"
			[[ -f $f ]] || continue
			echo "$r-$p: $(awk '{printf "%s%s %s -> %s (x%s, +-%s)", (NR>1?"; ":""), $1, $2, $3, $4, $5}' "$f")"
			echo
		done
	done
	echo "## Localization"
	echo
	echo "ATE: RMS position error. NEES: mean over the run with its two-sided 95% band."
	echo "NIS/DoF: mean NIS over its degrees of freedom (consistent in [0.5, 2]); visits: the"
	echo "same over the first sightings of each landmark visit, which carry the sightings'"
	echo "errors that persist from frame to frame (docs/calibration.md)."
	echo
	echo "| dataset | run | calibration | method | ATE [cm] | NEES [95% band] | NIS/DoF | visits | verdict | gated [%] |"
	echo "|---|---|---|---|---|---|---|---|---|---|"
	printf '%s\n' "${rows[@]}"
} >"$DOC"
echo "bench-noise.sh: wrote $DOC" >&2
