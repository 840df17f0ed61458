#!/usr/bin/env bash
# Installs the Debian packages ddemap needs. Idempotent: installs only what is missing, and runs
# apt-get update only then.
# Usage: scripts/install-deps.sh [build|all]
#   build: what building the library and the program needs (scripts/demo.sh)
#   all (default): also the Python module and what the tests and figures use (scripts/test.sh)
set -euo pipefail
what=${1:-all}
build=(g++ make cmake ninja-build pkg-config
       libeigen3-dev libspectra-dev libsuitesparse-dev
       libcli11-dev nlohmann-json3-dev libtomlplusplus-dev
       libhdf5-dev libopenmpi-dev openmpi-bin)  # ddemap atlas (HDF5, MPI)
rest=(python3 doctest-dev libxml2-utils librsvg2-bin strace time
      pybind11-dev python3-dev python3-numpy python3-pandas python3-pytest python3-matplotlib python3-venv
      python3-h5py hdf5-tools)
case "$what" in
    build) packages=("${build[@]}") ;;
    all) packages=("${build[@]}" "${rest[@]}") ;;
    *) echo "install-deps.sh: '$what': expected build or all" >&2; exit 2 ;;
esac
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
