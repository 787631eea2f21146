#!/usr/bin/env bash
# The README's test command: installs the dependencies (Debian packages),
# builds once, and runs the whole test suite with ctest on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
bash scripts/build.sh
cd build
ctest -j2 --output-on-failure --timeout 900
