#!/bin/sh
# MRPT's stock pf-localization, with LD_PRELOAD of the plugin
# and share/codemark/pf-localization.ini declaring our map, localizes on a
# simulated rawlog annotated with our observations.
#   stock_pf_localization.sh MODE SIMUL ANNOTATE PLUGIN INI WORKDIR [TRUTH_ANNOTATE]
# MODE: "detector" (codemark-annotate: the images through the detector) or
# "truth" (pf_truth_annotate: sightings from the ground truth + noise).
# Pass: the weighted mean of the last particle set within BOUND_M (0.3 m) of
# the ground truth's last pose, in at least 2 of 3 runs: stock
# pf-localization seeds MRPT's generator from the clock, so each run is a
# random draw (about one in five ends a global localization off by more).
set -eu
MODE=$1 SIMUL=$2 ANNOTATE=$3 PLUGIN=$4 INI=$5 WORK=$6 TRUTH=${7:-}
BOUND_M=0.3
rm -rf "$WORK" && mkdir -p "$WORK" && cd "$WORK"
"$SIMUL" -o sim --max-frames 100 -q
cd sim
if [ "$MODE" = truth ]; then
	"$TRUTH" dataset.rawlog gt_path.txt map.txt annotated.rawlog 3
else
	"$ANNOTATE" -i dataset.rawlog -o annotated.rawlog --map map.txt --drop-images -q \
		--calibration realistic
fi
command -v pf-localization >/dev/null || { echo "pf-localization not installed (mrpt-apps)"; exit 1; }
# One run of pf-localization; 0 when its final estimate is within the bound.
run_once() {
	rm -rf LOG_PF_*
	# pf-localization waits for a key after an error: stdin from /dev/null.
	LD_PRELOAD="$PLUGIN" pf-localization "$INI" annotated.rawlog </dev/null >pf.log 2>&1 || {
		tail -20 pf.log; echo "pf-localization failed"; exit 1; }
	grep -q "codedLandmarksMap\|CCodedLandmarksMap" pf.log || { echo "our map was not built"; tail -40 pf.log; exit 1; }
	OUT=$(ls -d LOG_PF_000_* | head -1)
	LAST=$(ls "$OUT"/particles/particles_[0-9][0-9][0-9][0-9][0-9].txt | sort | tail -1)
	ls "$OUT"/map_*landmarks.txt >/dev/null 2>&1 || { echo "no map representation written"; exit 1; }
	ls "$OUT"/3D/*.3Dscene >/dev/null
	# Weighted mean of the last particles (x y phi log_w) vs the last ground truth pose.
	awk -v bound="$BOUND_M" '
		FNR == NR { if ($1 !~ /^#/ && NF >= 4) { gx = $2; gy = $3 } next }
		$1 !~ /^%/ && NF >= 4 { w = exp($4); sw += w; sx += w * $1; sy += w * $2; n++ }
		END {
			if (n == 0 || sw == 0) { print "no particles read"; exit 1 }
			ex = sx / sw - gx; ey = sy / sw - gy; e = sqrt(ex * ex + ey * ey)
			printf "pf-localization: %d particles, final position error %.3f m (bound %.2f m)\n", n, e, bound
			exit (e < bound) ? 0 : 1
		}' gt_path.txt "$LAST"
}
pass=0 fail=0
while [ $pass -lt 2 ] && [ $fail -lt 2 ]; do
	if run_once; then pass=$((pass + 1)); else fail=$((fail + 1)); fi
done
echo "pf-localization: $pass of $((pass + fail)) runs within the bound"
[ $pass -ge 2 ]
