#!/usr/bin/env bash
# Builds and runs the particle-filter benchmark (bench/filters_pf): time per
# update against the number of particles (10^2..10^5) with our
# CCodedLandmarksMap and with a constant-likelihood map in the same run (its
# time is MRPT's own overhead), and frames with sightings to convergence from
# a uniform start (shipped pf.ini, 10 seeds), and what the likelihood's
# inflation (sigma_scale and the floors of pf.ini) does on codemark-simul's
# room loop (seeds 1-10; its own image model with the source's calibration
# `realistic`, and the webcam and phone presets) against the neutral
# values, with the EKF on the same runs as the peer. Writes
# docs/benchmarks/filters-pf.md. About 8 minutes on 2 cores.
#
# Usage: scripts/bench-filters-pf.sh [--quick] [--build-dir DIR]
# Environment: BUILD_DIR (default build-bench).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${BUILD_DIR:-build-bench}"
args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) args+=("$1"); shift ;;
  esac
done
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DCODEMARK_BUILD_BENCH=ON >/dev/null
cmake --build "$build_dir" -j"$(nproc)" --target codemark-bench-filters-pf codemark-simul \
  codemark-annotate codemark-localize >/dev/null
exe="$build_dir/bench/filters_pf/codemark-bench-filters-pf"
doc=docs/benchmarks/filters-pf.md
tmp="$(mktemp)"
work="$(mktemp -d)"
trap 'rm -rf "$tmp" "$work"' EXIT
apps="$build_dir/apps"
config=share/codemark/config

# One run of METHOD with CONFIG on DIR's loop, measured with CALIBRATION;
# prints ATE [cm], NEES / DoF and NIS / DoF from its summary.json.
localize() {
  local method=$1 cfg=$2 dir=$3 calibration=$4 out="$work/out-$RANDOM$RANDOM"
  "$apps/codemark-localize/codemark-localize" -q -c "$cfg" --method "$method" \
    -r "$dir/annotated.rawlog" -m "$dir/map.txt" -g "$dir/gt_path.txt" \
    --calibration "$calibration" -o "$out" >/dev/null
  python3 -c 'import json, sys
s = json.load(open(sys.argv[1]))
print(100 * s["ate_rmse_m"], s["nees_mean"] / 3, s["nis_mean"] / s["nis_dof"])' "$out/summary.json"
}

# The inflation section: per camera preset, one row per pf.ini variant
# (sigma_scale, floors) and the EKF's.
inflation() {
  local seeds=10 seed source preset calibration variant
  echo "## The likelihood's inflation"
  echo
  echo "codemark-simul's room loop (one lap, 5 Hz, fine wheel odometry: 0.5% of the distance), seeds 1"
  echo "to $seeds: \"default\" is the renderer's own image model in linear light (no preset;"
  echo "annotated and localized with that source's own calibration, \`realistic\`), \"webcam\" and"
  echo "\"phone\" its frames through those presets (the default calibration); every run starts unknown. The particle filter runs with the shipped"
  echo "\`pf.ini\` (\`sigma_scale\` 1, floors 1 cm and 0.5 deg), with \`sigma_scale\` 1.5, and with the floors"
  echo "removed (each \`sigma_scale\`); the"
  echo "EKF (shipped \`ekf.ini\`) on the same runs is the peer. ATE: mean over the seeds of each run's"
  echo "RMS position error; NEES / DoF: median over the seeds of each run's mean (1 when the covariance"
  echo "is honest); NIS / DoF: the range over the seeds, and the runs whose verdict is \`consistent\`"
  echo "([0.5, 2])."
  echo
  echo "| source | filter | sigma_scale | floors (range, angles) | ATE [cm] | ATE / EKF's | NEES / DoF | NIS / DoF | consistent |"
  echo "|---|---|---:|---|---:|---:|---:|---|---:|"
  for source in "default realistic" "webcam family" "phone family"; do
    read -r preset calibration <<<"$source"
    for seed in $(seq 1 $seeds); do
      local dir="$work/$preset$seed"
      mkdir -p "$dir"
      local flags=(--preset "$preset")
      [[ $preset == default ]] && flags=()
      "$apps/codemark-simul/codemark-simul" -q -c bench/fine_odometry.ini -s "$seed" "${flags[@]}" \
        -o "$dir" >/dev/null
      "$apps/codemark-annotate/codemark-annotate" -q -i "$dir/dataset.rawlog" \
        -o "$dir/annotated.rawlog" --map "$dir/map.txt" --calibration "$calibration" \
        --drop-images >/dev/null
    done
    # The EKF's runs, once: its row and every row's ATE ratio.
    local ekf_runs="$work/ekf-$preset.txt" ekf_ate
    for seed in $(seq 1 $seeds); do
      localize ekf "$config/ekf.ini" "$work/$preset$seed" "$calibration"
    done >"$ekf_runs"
    ekf_ate=$(awk '{ a += $1 } END { print a / NR }' "$ekf_runs")
    for variant in "ekf - -" "pf 1.5 0.01,0.5" "pf 1 0.01,0.5" "pf 1.5 0,0" "pf 1 0,0"; do
      read -r method scale floors <<<"$variant"
      if [[ $method == ekf ]]; then
        cat "$ekf_runs"
      else
        local cfg="$work/pf-$scale-$floors.ini"
        sed -e "s/^sigma_scale .*/sigma_scale = $scale/" \
          -e "s/^min_std_range_m .*/min_std_range_m = ${floors%,*}/" \
          -e "s/^min_std_angle_deg .*/min_std_angle_deg = ${floors#*,}/" "$config/pf.ini" >"$cfg"
        for seed in $(seq 1 $seeds); do
          localize pf "$cfg" "$work/$preset$seed" "$calibration"
        done
      fi | sort -k2,2g | awk -v src="$preset" -v m="$method" -v s="$scale" -v f="$floors" \
        -v e="$ekf_ate" '
        { ate += $1; nees[NR] = $2; nis[NR] = $3; ok += ($3 >= 0.5 && $3 <= 2) }
        END {
          lo = nis[1]; hi = nis[1]
          for (i = 2; i <= NR; ++i) { if (nis[i] < lo) lo = nis[i]; if (nis[i] > hi) hi = nis[i] }
          med = NR % 2 ? nees[(NR + 1) / 2] : (nees[NR / 2] + nees[NR / 2 + 1]) / 2
          split(f, fl, ",")
          fs = m == "ekf" ? "-" : (fl[1] == 0 && fl[2] == 0 ? "none" : sprintf("%g m, %g deg", fl[1], fl[2]))
          printf "| %s | %s | %s | %s | %.2f | %.2f | %.3g | %.2f-%.2f | %d / %d |\n",
            src, m, (m == "ekf" ? "-" : s), fs, ate / NR, ate / NR / e, med, lo, hi, ok, NR
        }'
    done
    echo "bench-filters-pf.sh: inflation, $preset done" >&2
  done
  echo
  echo "Without the floors a near sighting's C_L (a bearing known to hundredths of a milliradian) is"
  echo "narrower than the particles' spacing: the cloud collapses onto a few particles and its NEES"
  echo "leaves every band. With the floors the cloud is wider than the sightings alone warrant,"
  echo "which the NIS verdict reads as covariances too large."
}
{
  echo "# Particle filter benchmark"
  echo
  echo "Written by \`scripts/bench-filters-pf.sh${args[*]:+ ${args[*]}}\` on $(date -u +%Y-%m-%d),"
  echo "commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(nproc) cores ($(uname -m)), Release build:"
  echo "\`$(basename "$build_dir")/bench/filters_pf/codemark-bench-filters-pf${args[*]:+ ${args[*]}}\`."
  echo
  "$exe" "${args[@]+"${args[@]}"}"
  echo
  inflation
} >"$tmp"
mkdir -p docs/benchmarks
mv "$tmp" "$doc"
trap - EXIT
echo "bench-filters-pf.sh: wrote $doc" >&2
