#!/usr/bin/env bash
# The Python package as a user installs it: a fresh venv (Debian's python3, with the system's
# NumPy), `pip install --no-build-isolation .` into it (no download: CMake builds the module),
# then the quick Python tests (pytest -m "not slow"; scripts/test.sh runs them all against the
# build tree) against the installed package, from outside the source tree.
# Usage: [DDEMAP_BUILD_DIR=FOLDER] scripts/test-pip.sh [VENV_DIR]
#   VENV_DIR: default a temporary folder, removed afterwards;
#   DDEMAP_BUILD_DIR: a build folder of this tree with the Python module on (e.g. build/ after
#   scripts/test.sh): pip installs the module built there instead of compiling it again (CI does
#   this; without it pip compiles the library and the module from scratch, as a user's
#   `pip install .` does).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh all
src=$PWD
venv=${1:-}
if [ -z "$venv" ]; then
    venv=$(mktemp -d)/venv
    trap 'rm -rf "$(dirname "$venv")"' EXIT
fi
/usr/bin/python3 -m venv --system-site-packages "$venv"
# pip builds the module with CMake in its own folder (about 4 to 5 minutes on 2 cores), or brings
# it up to date in DDEMAP_BUILD_DIR
if [ -n "${DDEMAP_BUILD_DIR:-}" ]; then echo "pip install: the module of $DDEMAP_BUILD_DIR"; fi
DDEMAP_BUILD_JOBS=${BUILD_JOBS:-$(nproc)} "$venv/bin/pip" install --no-build-isolation --no-deps -q "$src"
cd "$(mktemp -d)"
"$venv/bin/python" -c 'import ddemap, sys; print("installed ddemap", ddemap.__version__, "at", ddemap.__file__)'
# the package imported is the installed one, not the source tree's
case "$("$venv/bin/python" -c 'import ddemap; print(ddemap.__file__)')" in "$venv"/*) ;; *) echo "not the installed package"; exit 1 ;; esac
"$venv/bin/python" -m pytest "$src/python/tests" -q -p no:cacheprovider -m "not slow"
