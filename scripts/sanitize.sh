#!/usr/bin/env bash
# CI checks beyond scripts/test.sh, on one clang build (build-fuzz/) with AddressSanitizer,
# UndefinedBehaviorSanitizer and libFuzzer's coverage instrumentation, so that the library is
# compiled once for both steps:
#  1. every fast-labelled test through ctest under the sanitizers (the test files themselves are
#     compiled without them: scripts/fuzz.sh), but for three command-line
#     parts that run calibrations and travelling waves through the program (cli_calibrate,
#     cli_shortdelay, cli_waves3, and cli_chain, now slow: 693 s of CPU on CI's machine under the sanitizers,
#     a third of the step; their library code runs under the sanitizers in the unit tests, and they
#     run in full in scripts/test.sh). Before a release run `ctest --test-dir build-fuzz` in
#     full (slow ones included);
#  2. a short libFuzzer run of every fuzz target (scripts/fuzz.sh), FUZZ_SECONDS per target
#     (default 20: a smoke run for CI; give more for a search).
# OpenMP is off in this build (clang's runtime is another package): parallel loops run serially.
# Installs what it needs (idempotent). Usage: scripts/sanitize.sh [asan|fuzz|all]
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
export FUZZ_WITH_TESTS=ON  # scripts/fuzz.sh configures build-fuzz with the tests too
if [ "$what" = all ] || [ "$what" = asan ]; then
    start=$SECONDS
    scripts/fuzz.sh --build-only
    cmake --build build-fuzz -j"$(nproc)"
    echo "sanitizer build (tests and fuzz targets, clang): $((SECONDS - start)) s"
    start=$SECONDS
    # DDEMAP_SANITIZED: the tests skip their wall-clock bounds (the build is several times slower)
    DDEMAP_SANITIZED=1 ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        ctest --test-dir build-fuzz -L fast -E '^cli_(chain|calibrate|shortdelay|waves3)$' --output-on-failure -j"$(nproc)"
    echo "sanitizer fast tests: $((SECONDS - start)) s"
fi
if [ "$what" = all ] || [ "$what" = fuzz ]; then
    start=$SECONDS
    scripts/fuzz.sh "${FUZZ_SECONDS:-20}"
    echo "fuzz runs: $((SECONDS - start)) s"
fi
