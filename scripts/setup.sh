#!/usr/bin/env bash
# Installs every Debian package clumpforge needs to build, test and run, including the
# real DEM engines the export tests load clumps into (LIGGGHTS, YADE) and HDF5's tools.
# Idempotent: a second run installs nothing new. Needs root (or sudo).
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
packages=(
  build-essential cmake ninja-build pkg-config git
  libcgal-dev libassimp-dev libopenvdb-dev libboost-iostreams-dev libtbb-dev
  libeigen3-dev libhdf5-dev libcli11-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libbenchmark-dev
  hdf5-tools python3-h5py python3-numpy
  python3-dev pybind11-dev python3-pytest python3-matplotlib
  libopenmpi-dev openmpi-bin
  liggghts yade
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -q
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "setup: all packages present"
fi
