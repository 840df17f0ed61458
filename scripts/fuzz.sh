#!/usr/bin/env bash
# Builds the libFuzzer targets with clang, AddressSanitizer and UndefinedBehaviorSanitizer in
# build-fuzz/, then fuzzes each parser for SECONDS (default 60) from its corpus in fuzz/corpus/.
# A crash, a sanitizer report, a non-one-line error or an input running over 30 s (the largest
# legal inputs, a fleet of 10^6 cars, take 12 s under the sanitizers and 0.25 s in a release
# build) stops the target and leaves the input in build-fuzz/findings/; add it to
# fuzz/corpus/<target>/ once fixed, so the regression tests replay it. The random seed is fixed
# (FUZZ_SEED, default 1) so that a run can be repeated; give another seed for a new search.
# FUZZ_WITH_TESTS=ON also configures the test suite in build-fuzz (scripts/sanitize.sh runs it
# there: one sanitizer build for both); the test files themselves and the explicit instantiations
# of Eigen's decompositions compile without the sanitizers (DDEMAP_TESTS_UNINSTRUMENTED,
# DDEMAP_EIGEN_UNINSTRUMENTED: ddemap's library and program keep them), the test files in unity batches. --build-only configures and builds, fuzzes nothing.
# Usage: [FUZZ_SEED=N] scripts/fuzz.sh [SECONDS|--build-only] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
build_only=0
if [ "${1:-}" = --build-only ]; then build_only=1; shift; fi
seconds=${1:-60}
shift || true
scripts/install-deps.sh all
packages=(clang libclang-rt-14-dev)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
flags="-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=undefined -fno-omit-frame-pointer -gline-tables-only -O1"
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
generator=()
command -v ninja >/dev/null && [ ! -f build-fuzz/Makefile ] && generator=(-G Ninja)
CC=clang CXX=clang++ cmake -S . -B build-fuzz "${generator[@]}" "${launcher[@]}" -DCMAKE_BUILD_TYPE=None -DDDEMAP_BUILD_FUZZERS=ON -DDDEMAP_BUILD_PYTHON=OFF \
    -DDDEMAP_BUILD_TESTS="${FUZZ_WITH_TESTS:-OFF}" -DDDEMAP_TESTS_UNINSTRUMENTED=ON -DDDEMAP_EIGEN_UNINSTRUMENTED=ON -DDDEMAP_UNITY_TESTS=ON -DDDEMAP_BUILD_BENCH=OFF -DDDEMAP_WITH_OPENMP=OFF \
    -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(system_json fleet_csv fleet_pattern vehicles_csv trace_csv lead_csv chart_spec axis expression atlas_spec)
fi
cmake --build build-fuzz -j"$(nproc)" --target "${targets[@]/#/fuzz_}" >/dev/null
[ "$build_only" = 1 ] && exit 0
mkdir -p build-fuzz/findings
status=0
for t in "${targets[@]}"; do
    work=build-fuzz/corpus-$t
    mkdir -p "$work"
    echo "fuzz_$t: $seconds s"
    if ! build-fuzz/fuzz/fuzz_$t "$work" "fuzz/corpus/$t" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=4096 \
            -max_len=65536 -seed="${FUZZ_SEED:-1}" -artifact_prefix=build-fuzz/findings/$t- -print_final_stats=1 > "build-fuzz/fuzz_$t.log" 2>&1; then
        echo "fuzz_$t: FINDING (see build-fuzz/fuzz_$t.log and build-fuzz/findings/)"
        tail -30 "build-fuzz/fuzz_$t.log"
        status=1
    else
        grep -E "stat::number_of_executed_units" "build-fuzz/fuzz_$t.log" || true
    fi
done
exit $status
