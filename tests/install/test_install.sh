#!/usr/bin/env bash
# The installable package: `cmake --install` into a temporary prefix, then a project outside
# the source tree (tests/install/consumer: find_package(ddemap), ddemap::ddemap) configured,
# built and run against that prefix alone.
# With the Python module built (PYTHON given): also the installed package imported and used.
# Usage: test_install.sh BUILD_DIR SOURCE_DIR [CXX_COMPILER [PYTHON [CXX_FLAGS [EXE_LINKER_FLAGS]]]]
# (the flags of the build being installed: a sanitizer build's libraries need its runtime in the consumer too)
set -euo pipefail
build=$1
source=$2
compiler=${3:-}
python=${4:-}
cxx_flags=${5:-}
linker_flags=${6:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" >/dev/null
# the public headers exactly: include/ddemap of the source tree, nothing from src/
diff <(cd "$source/include" && find ddemap -type f | sort) <(cd "$tmp/prefix/include" && find ddemap -type f | sort) ||
    fail "the installed headers differ from include/ddemap"
! grep -rn '#include "[a-z]*/internal/' "$tmp/prefix/include" || fail "an installed header includes a private header"
for f in ddemapConfig.cmake ddemapConfigVersion.cmake ddemapTargets.cmake; do
    [ -n "$(find "$tmp/prefix" -name "$f")" ] || fail "no $f installed"
done
[ "$("$tmp/prefix/bin/ddemap" --version)" = "$("$build/ddemap" --version)" ] || fail "the installed ddemap program does not run"
echo "installed: headers, libraries, bin/ddemap, the CMake package"
if [ -n "$python" ]; then
    (cd "$tmp" && PYTHONPATH="$tmp/prefix/lib/python3/dist-packages" "$python" -c '
import ddemap, os, sys
assert ddemap.__file__.startswith(sys.argv[1]), ddemap.__file__
r = ddemap.string(k1=0.2, k2=0.2, th=1.5, tau=0.1)
assert r.converged and r["string_stable"] is False
print("python: the installed package imports and runs (ddemap %s)" % ddemap.version)' "$tmp/prefix") ||
        fail "the installed Python package does not import"
fi

args=(-DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release -DDDEMAP_TESTS_DIR="$source/tests")
[ -n "$compiler" ] && args+=(-DCMAKE_CXX_COMPILER="$compiler")
[ -n "$cxx_flags" ] && args+=(-DCMAKE_CXX_FLAGS="$cxx_flags")
[ -n "$linker_flags" ] && args+=(-DCMAKE_EXE_LINKER_FLAGS="$linker_flags")
command -v ccache >/dev/null && args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$source/tests/install/consumer" -B "$tmp/consumer" "${args[@]}" >"$tmp/configure.log" ||
    { cat "$tmp/configure.log"; fail "the consumer does not configure"; }
cmake --build "$tmp/consumer" -j2 >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "the consumer does not build"; }
"$tmp/consumer/consumer" || fail "the consumer's roots are not the closed form"
echo "consumer: configured, built and run against the installed package"
