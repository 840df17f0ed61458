#!/usr/bin/env bash
# Configures and builds ddemap (Release) in ./build with Ninja, showing its progress.
# Usage: scripts/build.sh [TARGET...]
#   no target: everything (library, program, tests, benchmarks, Python module);
#   ddemap_cli: the program only, with only the packages it needs (what scripts/demo.sh runs; a
#   later full build adds the rest to the same folder).
# BUILD_DIR (default build) and BUILD_JOBS (default: the number of cores) can be set.
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${BUILD_DIR:-build}
options=()
if [ "${*:-}" = ddemap_cli ]; then
    scripts/install-deps.sh build
    # a new folder is configured for the program alone (no test framework or pybind11 needed)
    [ -f "$dir/CMakeCache.txt" ] || options=(-DDDEMAP_BUILD_TESTS=OFF -DDDEMAP_BUILD_BENCH=OFF -DDDEMAP_BUILD_PYTHON=OFF)
else
    scripts/install-deps.sh all
    options=(-DDDEMAP_BUILD_TESTS=ON -DDDEMAP_BUILD_BENCH=ON -DDDEMAP_BUILD_PYTHON=ON)
    # a new folder compiles the test files in unity batches (16 % less CPU from scratch); a folder
    # configured before keeps its choice (-DDDEMAP_UNITY_TESTS=OFF: one file per change)
    [ -f "$dir/CMakeCache.txt" ] || options+=(-DDDEMAP_UNITY_TESTS=ON)
fi
# a folder configured earlier with another generator: configure it anew for Ninja
if [ -f "$dir/CMakeCache.txt" ] && ! grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$dir/CMakeCache.txt"; then
    rm -rf "$dir/CMakeCache.txt" "$dir/CMakeFiles"
fi
if command -v ccache >/dev/null; then options+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
start=$SECONDS
if [ ! -f "$dir/build.ninja" ] || [ ${#options[@]} -gt 0 ]; then
    echo "configuring $dir (Release, Ninja)"
    cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${options[@]}" >/dev/null
fi
targets=()
for t in "$@"; do targets+=(--target "$t"); done
echo "building ${*:-everything} in $dir with ${BUILD_JOBS:-$(nproc)} jobs"
cmake --build "$dir" -j"${BUILD_JOBS:-$(nproc)}" "${targets[@]}"
echo "built in $((SECONDS - start)) s"
