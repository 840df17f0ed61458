#!/usr/bin/env bash
# CI checks beyond scripts/test.sh, in two steps (run by .ci/run after scripts/test.sh):
#  1. an AddressSanitizer + UndefinedBehaviorSanitizer build (g++, in build-asan/) running every
#     fast-labelled test through ctest (the slow ones take too long under the sanitizers for
#     every CI run: run `ctest --test-dir build-asan` in full before a release);
#  2. a short libFuzzer run of every fuzz target (scripts/fuzz.sh, clang), FUZZ_SECONDS per target
#     (default 45).
# Installs what it needs (idempotent). Usage: scripts/sanitize.sh [asan|fuzz|all]
set -euo pipefail
cd "$(dirname "$0")/.."
what=${1:-all}
scripts/install-deps.sh all
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
if [ "$what" = all ] || [ "$what" = asan ]; then
    start=$SECONDS
    flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -O1 -g1"
    cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=None -DDDEMAP_BUILD_BENCH=OFF -DDDEMAP_BUILD_PYTHON=OFF "${launcher[@]}" \
        -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
    cmake --build build-asan -j"$(nproc)" >/dev/null
    echo "sanitizer build: $((SECONDS - start)) s"
    start=$SECONDS
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
        ctest --test-dir build-asan -L fast --output-on-failure -j"$(nproc)"
    echo "sanitizer fast tests: $((SECONDS - start)) s"
fi
if [ "$what" = all ] || [ "$what" = fuzz ]; then
    start=$SECONDS
    scripts/fuzz.sh "${FUZZ_SECONDS:-45}"
    echo "fuzz runs: $((SECONDS - start)) s"
fi
