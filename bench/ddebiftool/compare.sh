#!/usr/bin/env bash
# Side by side: the 10-car IDM ring's branch of 100 periodic orbits (degree 4, 40 intervals,
# Floquet multipliers of every orbit) with ddemap (bench_orbits --model idm, one thread) and
# with DDE-BIFTOOL under Octave (idm_ring_orbits.m). DDE-BIFTOOL is not part of ddemap: give the
# folder of its repository (https://github.com/DDE-BifTool/DDE-Biftool) in DDEBIFTOOL_DIR.
#   DDEBIFTOOL_DIR=/path/to/DDE-Biftool bench/ddebiftool/compare.sh [ORBITS]   (from the repository root, after a build)
set -euo pipefail
orbits=${1:-100}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bench="$root/build/bench/bench_orbits"
[ -x "$bench" ] || { echo "compare.sh: build bench_orbits first (cmake --build build --target bench_orbits)" >&2; exit 2; }
echo "== ddemap (CPU time of the branch, Hopf point not timed)"
OMP_NUM_THREADS=1 "$bench" --model idm --points "$orbits" 10 | tee /tmp/ddemap-bench-orbits.$$
if [ -z "${DDEBIFTOOL_DIR:-}" ]; then
    echo "== DDE-BIFTOOL: skipped (DDEBIFTOOL_DIR is not set)"
    exit 0
fi
command -v octave >/dev/null || { echo "== DDE-BIFTOOL: skipped (octave is not installed: apt-get install -y octave)"; exit 0; }
echo "== DDE-BIFTOOL under Octave (CPU time of br_contn and of GetStability)"
line=$(cd "$here" && DDEBIFTOOL_DIR="$DDEBIFTOOL_DIR" ORBITS="$orbits" octave --no-gui --quiet idm_ring_orbits.m 2>/dev/null | grep '^ddebiftool orbits' || true)
echo "$line"
[ -n "$line" ] || { echo "compare.sh: DDE-BIFTOOL did not finish the branch" >&2; exit 1; }
ours=$(awk -F'|' '/^\| 10 /{gsub(/ /, "", $6); print $6}' /tmp/ddemap-bench-orbits.$$)
theirs=$(echo "$line" | sed 's/.* cpu \([0-9.]*\) .*/\1/')
rm -f /tmp/ddemap-bench-orbits.$$
awk -v a="$ours" -v b="$theirs" 'BEGIN { printf "ratio      DDE-BIFTOOL / ddemap CPU time = %.1f (%s s / %s s)\n", b / a, b, a }'
