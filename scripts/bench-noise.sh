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
# Then the NIS verdict over SEEDS seeds (default 10) of the same loop in the
# project's renderer's linear light, for every filter, with that source's
# own calibration (realistic) and with it 5x too small (C_P / 25) and 3x too
# large (C_P x 9). Writes docs/benchmarks/noise.md.
#
# Usage: scripts/bench-noise.sh [--presets LIST] [--no-povray]
# Environment: BUILD_DIR (default build-bench), WORK (scratch folder),
# START_DIVISOR, SEEDS.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
WORK="${WORK:-/tmp/codemark_bench_noise}"
START_DIVISOR="${START_DIVISOR:-3}"
SEEDS="${SEEDS:-10}"
DOC="$ROOT/docs/benchmarks/noise.md"
presets="webcam,phone"
povray=1
while [[ $# -gt 0 ]]; do
	case "$1" in
		-h|--help) sed -n '2,21p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
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
cmake --build "$BUILD_DIR" -j"$(nproc)" --target codemark-simul codemark-annotate \
	codemark-localize codemark-calibrate-noise >/dev/null
bin="$BUILD_DIR/apps"
share="$ROOT/share/codemark"
mkdir -p "$WORK"
start_time=$SECONDS

# The fine odometry, for both renderers.
odometry="$(cat "$ROOT/bench/fine_odometry.ini")"
echo "$odometry" >"$WORK/own.ini"
printf '[trajectory]\nloops = 2\n[dataset]\nframe_rate_hz = 5\n[render]\nbackground = Textured\n%s\n' \
	"$odometry" >"$WORK/povray.ini"

# A shipped calibration with every sigma multiplied: scaled NAME FACTOR OUT.
scaled() {
	"$bin/codemark-calibrate-noise/codemark-calibrate-noise" --calibration "$1" --scale "$2" \
		-o "$3" >/dev/null
}
# The start: the default calibration with every sigma divided.
start="$WORK/start.ini"
scaled family "$(awk -v d="$START_DIVISOR" 'BEGIN { print 1 / d }')" "$start"

# summary.json's value of KEY (a list's items joined by ", ").
json() {
	python3 -c 'import json, sys
v = json.load(open(sys.argv[1])).get(sys.argv[2])
print(", ".join(map(str, v)) if isinstance(v, list) else ("" if v is None else v))' "$1" "$2"
}

# summary.json's nis_components as "range / bearing / orientation", each
# "NIS (share %)".
components() {
	python3 -c 'import json, sys
c = json.load(open(sys.argv[1])).get("nis_components") or {}
f = lambda v: "-" if v is None else "%.2f (%.0f%%)" % (v["nis"], 100 * (v["sighting_share"] or 0))
print(" / ".join(f(c.get(k)) for k in ("range", "bearing", "orientation")))' "$1"
}

# Runs COMMAND with a scratch directory as its last argument and renames
# that to DIR once COMMAND is done, so that an interrupted run leaves no
# dataset a later run would reuse; nothing to do when DIR exists.
build_once() { # DIR COMMAND...
	local dir="$1"
	shift
	[[ -d "$dir" ]] && return 0
	rm -rf "$dir.partial" && mkdir -p "$dir.partial"
	"$@" "$dir.partial"
	mv "$dir.partial" "$dir"
}

simulate() { # renderer preset seed out
	if [[ $1 == own ]]; then
		"$bin/codemark-simul/codemark-simul" -q -c "$WORK/own.ini" -s "$3" --preset "$2" -o "$4" >&2
	else
		"$bin/codemark-simul/codemark-simul" -q -c "$WORK/povray.ini" -s "$3" --preset "$2" \
			--renderer povray --light normal --wall plaster --floor tiles -o "$4" >&2
	fi
}

# The linear-light loop of one seed, annotated with its source's own calibration.
simulate_annotated() { # seed out
	"$bin/codemark-simul/codemark-simul" -q -c "$WORK/own.ini" -s "$1" -o "$2" >&2
	"$bin/codemark-annotate/codemark-annotate" -q -i "$2/dataset.rawlog" -o "$2/annotated.rawlog" \
		--map "$2/map.txt" --calibration realistic --drop-images >&2
}

rows=()
fit_rows=()
run_set() { # name renderer preset
	local name="$1" renderer="$2" preset="$3" dir="$WORK/$1"
	for seed in 1 2; do
		build_once "$dir/run$seed" simulate "$renderer" "$preset" "$seed"
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
				rows+=("| $name | $seed | $cal | $method | $(awk -v a="$(json "$s" ate_rmse_m)" 'BEGIN{printf "%.2f", 100*a}') | $(awk -v a="$(json "$s" nees_mean)" 'BEGIN{printf "%.2f", a}') [${band/, /, }] | $(awk -v a="$(json "$s" nis_mean)" -v d="$(json "$s" nis_dof)" 'BEGIN{printf "%.2f", a/d}') | $(awk -v a="$(json "$s" nis_visit_ratio)" 'BEGIN{printf "%.2f", a}') | $(components "$s") | $(json "$s" nis_verdict) | $(awk -v a="$(json "$s" gated_fraction)" 'BEGIN{printf "%.1f", 100*a}') |")
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

# The verdicts over the seeds: linear light (realistic is that source's
# own calibration), every filter, three calibrations.
scaled realistic 0.2 "$WORK/realistic-small.ini"
scaled realistic 3 "$WORK/realistic-large.ini"
declare -A verdicts ratios
for seed in $(seq 1 "$SEEDS"); do
	dir="$WORK/linear/seed$seed"
	build_once "$dir" simulate_annotated "$seed"
	for cal in own small large; do
		c=realistic
		[[ $cal == small ]] && c="$WORK/realistic-small.ini"
		[[ $cal == large ]] && c="$WORK/realistic-large.ini"
		for method in ekf ekf-pose ekf-slam pf; do
			out="$dir/out-$cal-$method"
			"$bin/codemark-localize/codemark-localize" -q -c "$share/config/$method.ini" \
				--method "$method" -r "$dir/annotated.rawlog" -m "$dir/map.txt" \
				-g "$dir/gt_path.txt" --calibration "$c" -o "$out" >/dev/null
			v=$(json "$out/summary.json" nis_verdict)
			case "$v" in
				consistent) v=consistent ;;
				"covariances too small"*) v=small ;;
				"covariances too large"*) v=large ;;
				*) v=other ;;
			esac
			verdicts[$method,$cal]+="$v "
			ratios[$method,$cal]+="$(awk -v a="$(json "$out/summary.json" nis_mean)" \
				-v d="$(json "$out/summary.json" nis_dof)" 'BEGIN{printf "%.2f", a/d}') "
		done
	done
	echo "bench-noise.sh: verdicts, seed $seed done" >&2
done
verdict_rows=()
for method in ekf ekf-pose ekf-slam pf; do
	for cal in own small large; do
		read -r -a v <<<"${verdicts[$method,$cal]}"
		count() { local n=0 x; for x in "${v[@]}"; do [[ $x == "$1" ]] && n=$((n + 1)); done; echo "$n"; }
		label="realistic (own)"
		want=consistent
		[[ $cal == small ]] && label="realistic / 5 (C_P / 25)" && want=small
		[[ $cal == large ]] && label="realistic x 3 (C_P x 9)" && want=large
		range=$(tr ' ' '\n' <<<"${ratios[$method,$cal]}" | sed '/^$/d' | sort -g | sed -n '1p;$p' | paste -sd- -)
		verdict_rows+=("| $method | $label | $(count "$want") / ${#v[@]} | $(count consistent) | $(count small) | $(count large) | $range |")
	done
done

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
	echo "same over the first sightings of each landmark visit inside the gate, which carry"
	echo "the sightings' errors that persist from frame to frame (docs/calibration.md); gated:"
	echo "the sightings beyond the gate, outliers the filter rejects. Per component:"
	echo "the mean NIS of the range, the bearing and the relative orientation, each with"
	echo "the sightings' share of its variance (a component with a small share shows the"
	echo "prediction's error, not the sightings')."
	echo
	echo "| dataset | run | calibration | method | ATE [cm] | NEES [95% band] | NIS/DoF | visits | per component: range / bearing / orientation | verdict | gated [%] |"
	echo "|---|---|---|---|---|---|---|---|---|---|---|"
	printf '%s\n' "${rows[@]}"
	echo
	echo "## The verdict over $SEEDS seeds"
	echo
	echo "codemark-simul's room loop (one lap, 5 Hz, the fine odometry above) in the"
	echo "project's renderer's linear light, seeds 1 to $SEEDS, annotated with that source's"
	echo "own calibration (\`realistic\`) and localized by every filter from an unknown"
	echo "start with it, with every sigma 5x smaller and 3x larger (\`codemark-localize"
	echo "--calibration\` measures each sighting again). \"right\": runs whose"
	echo "verdict says what the calibration is (consistent, too small, too large)."
	echo
	echo "| filter | calibration | right | consistent | too small | too large | NIS/DoF range |"
	echo "|---|---|---|---|---|---|---|"
	printf '%s\n' "${verdict_rows[@]}"
} >"$DOC"
echo "bench-noise.sh: wrote $DOC" >&2
