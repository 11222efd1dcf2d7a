#!/usr/bin/env bash
# Install what vdbhair needs to build, from Debian's packages; with --tests also what the tests
# run (Blender, for the interop tests and the add-on's). Quiet and fast when everything is already
# there (one dpkg query); uses sudo when not run as root.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config ccache
  libopenvdb-dev libboost-iostreams-dev libtbb-dev libeigen3-dev libopenimageio-dev libpng-dev libfreetype-dev
  catch2 libcli11-dev nlohmann-json3-dev libnanoflann-dev libnlopt-dev libnlopt-cxx-dev
  libopenvdb-tools python3-openvdb python3-numpy fonts-dejavu-core
  pybind11-dev python3-pybind11 python3-dev python3-pytest
)
# Debian's Blender 3.4 runs the system Python, so it loads the vdbhair module the build makes;
# xvfb gives it a window for the add-on's modal test (tests/blender/test_modal.py: progress, Esc).
[ "${1:-}" = --tests ] && PACKAGES+=(blender xvfb xauth)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
