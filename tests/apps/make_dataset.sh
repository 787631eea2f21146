#!/usr/bin/env bash
# Fixture: a small simulated dataset, annotated with the BearingRange twin.
# usage: make_dataset.sh CODEMARK_SIMUL CODEMARK_ANNOTATE OUT_DIR FRAMES
set -euo pipefail
simul=$1 annotate=$2 out=$3 frames=$4
rm -rf "$out"
"$simul" -q --out "$out" --max-frames "$frames" --seed 5
"$annotate" -q -i "$out/dataset.rawlog" -o "$out/annotated.rawlog" --bearing-range
"$annotate" -q -i "$out/dataset.rawlog" -o "$out/br_only.rawlog" --bearing-range --drop-images
test -s "$out/annotated.rawlog"
