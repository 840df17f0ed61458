#!/usr/bin/env bash
# Installs the Debian packages ddemap needs to build and test. Idempotent: installs only
# what is missing, and runs apt-get update only then.
set -euo pipefail
packages=(g++ make cmake python3 pkg-config
          libeigen3-dev libspectra-dev libsuitesparse-dev doctest-dev
          libcli11-dev nlohmann-json3-dev libtomlplusplus-dev
          libxml2-utils librsvg2-bin
          pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
          libhdf5-dev libopenmpi-dev openmpi-bin python3-h5py hdf5-tools)  # ddemap atlas (HDF5, MPI)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    sudo_cmd=""
    if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
    $sudo_cmd apt-get -o DPkg::Lock::Timeout=600 update -qq
    DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}"
fi
