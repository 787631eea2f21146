#!/usr/bin/env bash
# Benchmarks of the filters, written to docs/benchmarks/filters.md.
# Modular: one function per section, each appending its Markdown to the doc,
# so that sections can be added (e.g. the EKF-SLAM kf-slam_demo
# section) without touching the others. Run all sections, or name them:
#   scripts/bench-filters.sh            # every section
#   scripts/bench-filters.sh sim        # only the simulated-data section
# Environment: BUILD_DIR (default build-bench), SEEDS (default 3),
# MAX_FRAMES (default 0: whole loop), WORK (scratch folder).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD_DIR="${BUILD_DIR:-$ROOT/build-bench}"
DOC="$ROOT/docs/benchmarks/filters.md"
WORK="${WORK:-/tmp/codemark_bench_filters}"
SEEDS="${SEEDS:-3}"
MAX_FRAMES="${MAX_FRAMES:-0}"

build() # targets...
{
	cmake -S "$ROOT" -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
	cmake --build "$BUILD_DIR" -j"$(nproc)" --target "$@" >/dev/null
}

doc_header()
{
	mkdir -p "$(dirname "$DOC")"
	cat >"$DOC" <<HDR
# Filter benchmarks

Written by \`scripts/bench-filters.sh\` on $(date -u +%Y-%m-%d), commit
$(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo unknown), $(nproc) cores ($(uname -m)), Release build,
SEEDS=$SEEDS. Each section below is one function of the script.

HDR
}

# --- section: simulated datasets with images (ekf, ekf-pose, and ekf-slam /
# pf when their inis exist) and the EKF's cost against landmarks in view.
section_sim()
{
	build filters_sim
	{
		echo "## Simulated data"
		echo
		echo "Command: \`$(basename "$BUILD_DIR")/bench/filters_sim/filters_sim --seeds $SEEDS --max-frames $MAX_FRAMES\`"
		echo
		"$BUILD_DIR/bench/filters_sim/filters_sim" --work "$WORK/sim" --seeds "$SEEDS" \
			--max-frames "$MAX_FRAMES" --share "$ROOT/share/codemark"
		echo
		cat <<'NOTES'
How the section runs:
- Every filter reads the pipeline's calibrated C_P (no ini override) and
  drops coded sightings seen beyond `[stepper] max_view_angle_deg` from the
  landmark's normal (the range is biased short beyond the detector's
  validated range). The EKF ("ekf") uses the iterated update
  (`[ekf] iterations`); ekf-slam runs with the true map as its prior. The
  EKF configs keep the mirror-image fold (`[pose] fold_ambiguity`) off:
  the same far landmark, frame after frame, has its mirror image decided by
  the same detector bias, which the fold would count as independent.
- The largest errors are the first fix (one landmark far away and frontal,
  where phi2 is weakest) and turning steps without a usable sighting
  (MRPT's Gaussian odometry model).
- At noise 6, blur 1.2 px the detector's corners are worse than the
  calibrated sigma says, so the EKFs are over-confident; a calibration
  fitted to such images (`codemark-calibrate-noise`, docs/calibration.md)
  or `[ekf] measurement_cov_scale` corrects that.
- "first fix" is the time from the first frame to the first estimate; the
  EKFs fix at the first frame in which a mapped landmark is detected.
NOTES
		echo
	} >>"$DOC"
}

# --- section: MRPT's kf-slam_demo (our EKF-SLAM vs stock kf-slam), by
# scripts/bench-filters-slam.sh (its own doc,
# docs/benchmarks/filters-slam.md), copied in here below a heading.
section_kfslam()
{
	build bench_filters_slam
	"$ROOT/scripts/bench-filters-slam.sh" "$BUILD_DIR" >&2
	{
		echo "## MRPT's kf-slam_demo (from docs/benchmarks/filters-slam.md)"
		echo
		sed -e '1{/^# /d}' -e 's/^## /### /' "$ROOT/docs/benchmarks/filters-slam.md"
		echo
	} >>"$DOC"
}

main()
{
	local sections=("$@")
	if [[ ${#sections[@]} -eq 0 ]]; then
		sections=(sim)
		[[ -x "$ROOT/scripts/bench-filters-slam.sh" ]] && sections+=(kfslam)
	fi
	doc_header
	for s in "${sections[@]}"; do
		if ! declare -F "section_$s" >/dev/null; then
			echo "bench-filters.sh: unknown section '$s'" >&2
			exit 1
		fi
		echo "bench-filters.sh: section $s" >&2
		"section_$s"
	done
	echo "bench-filters.sh: wrote $DOC" >&2
}

main "$@"
