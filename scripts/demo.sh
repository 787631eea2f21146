#!/usr/bin/env bash
# The README's demo command: installs the dependencies, builds, and runs the
# main job on the embedded default scene, writing into demo-out/ (or $1).
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-demo-out}"
bash scripts/setup-deps.sh
bash scripts/build.sh
mkdir -p "$OUT"
./build/apps/codemark-render/codemark-render --map share/codemark/example-map.txt --out "$OUT/render"
echo "demo: wrote $OUT/render"
