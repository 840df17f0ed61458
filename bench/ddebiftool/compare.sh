#!/usr/bin/env bash
# Side by side: the 10-car IDM ring's branch of periodic orbits (degree 4, 40 intervals, Floquet
# multipliers of every orbit) with DDE-BIFTOOL under Octave (idm_ring_orbits.m, ORBITS orbits with
# its own step control) and with ddemap (bench_orbits --model idm, one thread) over the same
# stretch of the branch: from the Hopf point to the gap of DDE-BIFTOOL's last orbit, at most
# ORBITS orbits, steps up to MAX_STEP in ddemap's weighted norm (PeriodicOrbitOptions::max_step).
# DDE-BIFTOOL is not part of ddemap: give the folder of its repository
# (https://github.com/DDE-BifTool/DDE-Biftool) in DDEBIFTOOL_DIR; without it only ddemap runs, to
# the gap 22.17044689 that DDE-BIFTOOL's 100 orbits reached (BENCHMARKS.md).
#   DDEBIFTOOL_DIR=/path/to/DDE-Biftool [MAX_STEP=0.75] [REPEATS=3] bench/ddebiftool/compare.sh [ORBITS]
# (from the repository root, after a build). With DDEBIFTOOL_DIR, the stability of every
# DDE-BIFTOOL orbit is compared with ddemap's at the same gap (compare_stability.py).
set -euo pipefail
orbits=${1:-100}
max_step=${MAX_STEP:-0.75}
repeats=${REPEATS:-3}
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
bench="$root/build/bench/bench_orbits"
[ -x "$bench" ] || { echo "compare.sh: build bench_orbits first (cmake --build build --target bench_orbits)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
to=22.17044689
theirs=
if [ -z "${DDEBIFTOOL_DIR:-}" ]; then
    echo "== DDE-BIFTOOL: skipped (DDEBIFTOOL_DIR is not set); ddemap to gap $to"
elif ! command -v octave >/dev/null; then
    echo "== DDE-BIFTOOL: skipped (octave is not installed: apt-get install -y octave); ddemap to gap $to"
else
    echo "== DDE-BIFTOOL under Octave (CPU time of br_contn and of GetStability)"
    line=$(cd "$here" && DDEBIFTOOL_DIR="$DDEBIFTOOL_DIR" ORBITS="$orbits" DDEBIFTOOL_POINTS="$work/ddebiftool.csv" \
           octave --no-gui --quiet idm_ring_orbits.m 2>/dev/null | grep '^ddebiftool orbits' || true)
    echo "$line"
    [ -n "$line" ] || { echo "compare.sh: DDE-BIFTOOL did not finish the branch" >&2; exit 1; }
    theirs=$(echo "$line" | sed 's/.* cpu \([0-9.]*\) .*/\1/')
    to=$(echo "$line" | sed 's/.* gap [0-9.]*\.\.\([0-9.]*\) .*/\1/')
fi
echo "== ddemap to gap $to, at most $orbits orbits, max step $max_step (CPU time of the branch, Hopf point not timed)"
OMP_NUM_THREADS=1 "$bench" --model idm --points "$orbits" --to "$to" --max-step "$max_step" --repeats "$repeats" --csv "$work/ddemap.csv" 10 |
    tee "$work/ddemap.txt"
grep -q 'stop: bound' "$work/ddemap.txt" || echo "compare.sh: ddemap's $orbits orbits did not reach gap $to (try a larger MAX_STEP)" >&2
if [ -n "$theirs" ]; then
    ours=$(awk -F'|' '/^\| 10 /{gsub(/ /, "", $6); print $6}' "$work/ddemap.txt")
    awk -v a="$ours" -v b="$theirs" 'BEGIN { printf "ratio      DDE-BIFTOOL / ddemap CPU time = %.1f (%s s / %s s)\n", b / a, b, a }'
    echo "== stability, point by point"
    python3 "$here/compare_stability.py" "$work/ddebiftool.csv" "$work/ddemap.csv"
fi
