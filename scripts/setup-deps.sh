#!/usr/bin/env bash
# Installs codemark's build and test dependencies from Debian bookworm packages.
# Idempotent: packages already installed are skipped, and apt-get is not called
# at all when nothing is missing. Needs root (or sudo) only when something is missing.
set -euo pipefail

PACKAGES=(
  cmake g++ make pkg-config
  libmrpt-dev mrpt-apps mrpt-common
  libopencv-dev libopencv-contrib-dev
  libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev
  libapriltag-dev libcairo2-dev libtclap-dev nlohmann-json3-dev
  xvfb xdotool imagemagick
  povray
  python3 clang-14 libclang-rt-14-dev clang-tidy-14 clang-format-14 clang-tools-14
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#PACKAGES[@]} packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup-deps: done"
