#!/usr/bin/env bash
# `ddemap atlas` end to end on maps/atlas-example.toml: a serial run, a run on two threads, a run
# under `mpirun -np 2`, and a run killed (kill -9) after its first finished chunk then resumed
# must give the same HDF5 datasets bit for bit; every point must agree with `ddemap sweep` on the
# same point (tests/cli/atlas_check.py, h5py); bad specs are refused before any work.
set -u
bin="${DDEMAP:?set DDEMAP to the ddemap binary}"
src="${SOURCE_DIR:?set SOURCE_DIR to the source tree}"
spec="$src/maps/atlas-example.toml"
check="$src/tests/cli/atlas_check.py"
fail=0
pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# a Python with h5py (python3-h5py is Debian's; a python3 earlier on PATH may lack it)
py=""
for p in python3 /usr/bin/python3; do
    if "$p" -c "import h5py, tomllib" 2>/dev/null; then py="$p"; break; fi
done
[ -n "$py" ] || { echo "FAIL: no python3 with h5py (scripts/install-deps.sh installs python3-h5py)"; exit 1; }

# serial (one thread): the reference
if OMP_NUM_THREADS=1 "$bin" atlas "$spec" --out "$tmp/serial" --quiet >"$tmp/serial.out" 2>"$tmp/serial.err"; then
    [ -f "$tmp/serial/atlas.h5" ] && [ -f "$tmp/serial/atlas.svg" ] && [ ! -e "$tmp/serial/atlas.chunks" ] && ok ||
        bad "atlas: expected atlas.h5 and atlas.svg (and the chunk store removed): $(ls "$tmp/serial")"
    grep -q "1 process x 1 thread" "$tmp/serial.out" && ok || bad "atlas: serial summary: $(cat "$tmp/serial.out")"
    xmllint --noout "$tmp/serial/atlas.svg" && ok || bad "atlas.svg is not well-formed"
    [ ! -s "$tmp/serial.err" ] && ok || bad "atlas --quiet wrote to stderr: $(cat "$tmp/serial.err")"
else
    bad "atlas serial exit status: $(cat "$tmp/serial.err")"
fi

# every point against `ddemap sweep` on the same point
mkdir -p "$tmp/sweeps"
"$py" "$check" sweep "$tmp/serial/atlas.h5" "$bin" "$tmp/sweeps" >"$tmp/check.out" && grep -q "ring method winding" "$tmp/check.out" && ok ||
    bad "atlas points differ from ddemap sweep (or not on the winding path): $(cat "$tmp/check.out")"

# the per-mode ring path (ring_method = "modes") on one (k1, k2) plane per ring size: every point
# against the sweep with boundaries (which uses that path)
sed -e 's/^values = \[0.1, 0.4\]/values = [0.4]/' -e 's/^values = \[1.0, 2.0\]/values = [1.0]/' -e 's/^chunk = 16 /ring_method = "modes"\nchunk = 16 /' \
    "$spec" >"$tmp/modes.toml"
grep -q '^ring_method = "modes"' "$tmp/modes.toml" && ok || bad "atlas: the modes spec was not made"
if OMP_NUM_THREADS=2 "$bin" atlas "$tmp/modes.toml" --out "$tmp/modes" --quiet >/dev/null 2>"$tmp/modes.err"; then
    "$py" "$check" sweep "$tmp/modes/atlas.h5" "$bin" "$tmp/sweeps" && ok || bad "atlas (ring method modes) points differ from ddemap sweep"
else
    bad "atlas with ring_method = modes: exit status: $(cat "$tmp/modes.err")"
fi

# two threads
OMP_NUM_THREADS=2 "$bin" atlas "$spec" --out "$tmp/threads" --quiet >/dev/null 2>&1 && ok || bad "atlas on two threads: exit status"
"$py" "$check" same "$tmp/serial/atlas.h5" "$tmp/threads/atlas.h5" && ok || bad "atlas: two threads differ from serial"

# two MPI processes (rank 0 hands out chunks, both compute)
if command -v mpirun >/dev/null; then
    # in a sanitizer build: OpenMPI's own allocations kept until exit are not ddemap's leaks (tests/lsan-openmpi.supp)
    LSAN_OPTIONS="suppressions=$src/tests/lsan-openmpi.supp:fast_unwind_on_malloc=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}" \
    mpirun -np 2 --oversubscribe --allow-run-as-root "$bin" atlas "$spec" --out "$tmp/mpi" --quiet >"$tmp/mpi.out" 2>"$tmp/mpi.err"
    rc=$?
    if [ $rc -eq 2 ] && grep -q "built without MPI" "$tmp/mpi.err"; then
        echo "note: ddemap built without MPI (DDEMAP_WITH_MPI=OFF): the mpirun run is refused, as it should be"
        ok
    elif [ $rc -eq 0 ]; then
        grep -q "2 processes" "$tmp/mpi.out" && ok || bad "atlas under mpirun -np 2 did not run on 2 processes: $(cat "$tmp/mpi.out")"
        "$py" "$check" same "$tmp/serial/atlas.h5" "$tmp/mpi/atlas.h5" && ok || bad "atlas: mpirun -np 2 differs from serial"
        cmp -s "$tmp/serial/atlas.h5" "$tmp/mpi/atlas.h5" && ok || bad "atlas: the HDF5 files of serial and mpirun differ in bytes"
    else
        bad "atlas under mpirun -np 2: exit $rc: $(cat "$tmp/mpi.err")"
    fi
else
    bad "mpirun not found (scripts/install-deps.sh installs openmpi-bin)"
fi

# killed (kill -9) after the first finished chunk, then --resume: nothing finished is recomputed
# and the result is the same. On the per-mode ring path (the example with ring_method = "modes"),
# whose run lasts seconds: on the winding path the example can finish before the kill arrives.
slow="$tmp/slow.toml"
sed -e 's/^chunk = 16 /ring_method = "modes"\nchunk = 16 /' "$spec" >"$slow"
OMP_NUM_THREADS=2 "$bin" atlas "$slow" --out "$tmp/slowref" --quiet >/dev/null 2>&1 && ok || bad "atlas (ring method modes): exit status"
mkdir -p "$tmp/killed"
OMP_NUM_THREADS=1 "$bin" atlas "$slow" --out "$tmp/killed" --quiet >/dev/null 2>&1 &
pid=$!
header=48                # the store's header
record=$((24 + 16 * 16 * 8 + 8))  # one chunk of 16 points x 16 values, with its head and checksum
for _ in $(seq 1 3000); do
    size=$(stat -c %s "$tmp/killed/atlas.chunks" 2>/dev/null || echo 0)
    [ "$size" -ge $((header + record)) ] && break
    kill -0 $pid 2>/dev/null || break
    sleep 0.005
done
kill -9 $pid 2>/dev/null
wait $pid 2>/dev/null
if [ -f "$tmp/killed/atlas.chunks" ] && [ ! -e "$tmp/killed/atlas.h5" ]; then
    finished=$(( ($(stat -c %s "$tmp/killed/atlas.chunks") - header) / record ))
    [ "$finished" -ge 1 ] && ok || bad "atlas: no chunk finished before the kill"
    "$bin" atlas "$slow" --out "$tmp/killed" --resume >"$tmp/resume.out" 2>"$tmp/resume.err" && ok || bad "atlas --resume: exit status: $(cat "$tmp/resume.err")"
    grep -q "resumed $finished of 128 chunks" "$tmp/resume.err" && ok || bad "atlas --resume did not take the $finished finished chunks: $(cat "$tmp/resume.err")"
    grep -q "($((128 - finished)) computed, $finished resumed)" "$tmp/resume.out" && ok || bad "atlas --resume recomputed finished chunks: $(cat "$tmp/resume.out")"
    "$py" "$check" same "$tmp/slowref/atlas.h5" "$tmp/killed/atlas.h5" && ok || bad "atlas: killed and resumed differs from an uninterrupted run"
    # --resume once more: the finished atlas is recognised, nothing is computed or rewritten
    cp "$tmp/killed/atlas.h5" "$tmp/finished.h5"
    "$bin" atlas "$slow" --out "$tmp/killed" --resume 2>&1 | grep -q "is complete for this spec: nothing to compute" && ok ||
        bad "atlas --resume of a finished atlas recomputed it"
    cmp -s "$tmp/finished.h5" "$tmp/killed/atlas.h5" && ok || bad "atlas --resume of a finished atlas changed it"
else
    bad "atlas: the run ended before it could be killed after its first chunk"
fi
# interrupted (SIGINT, as Ctrl-C): the store stays, no result and no temporary file; a store of
# another spec is not resumed
mkdir -p "$tmp/other"
sed 's/^chunk = 16 /chunk = 8 /' "$slow" >"$tmp/other.toml"
set -m  # job control: the background job does not ignore SIGINT (as a non-interactive shell's would)
OMP_NUM_THREADS=1 "$bin" atlas "$tmp/other.toml" --out "$tmp/other" --quiet >/dev/null 2>&1 &
pid=$!
set +m
for _ in $(seq 1 3000); do [ "$(stat -c %s "$tmp/other/atlas.chunks" 2>/dev/null || echo 0)" -gt $header ] && break; sleep 0.005; done
kill -INT $pid 2>/dev/null
wait $pid 2>/dev/null
[ "$(ls -A "$tmp/other")" = "atlas.chunks" ] && ok || bad "atlas after SIGINT: expected only the chunk store: $(ls -A "$tmp/other")"
if [ -f "$tmp/other/atlas.chunks" ]; then
    "$bin" atlas "$spec" --out "$tmp/other" --resume >"$tmp/o.out" 2>"$tmp/o.err"
    rc=$?
    [ $rc -eq 2 ] && grep -q "written for another spec" "$tmp/o.err" && [ ! -s "$tmp/o.out" ] && ok ||
        bad "atlas --resume of another spec's store: exit $rc: $(cat "$tmp/o.err")"
else
    bad "atlas: the other spec's run ended before it could be killed"
fi

# bad specs: exit 2, one line naming the line and key, nothing on stdout, nothing written
expect_error() {  # expect_error PATTERN SPEC_TEXT
    printf '%s\n' "$2" >"$tmp/bad.toml"
    rm -rf "$tmp/bad"
    "$bin" atlas "$tmp/bad.toml" --out "$tmp/bad" >"$tmp/e.out" 2>"$tmp/e.err"
    local rc=$?
    if [ $rc -eq 2 ] && [ ! -s "$tmp/e.out" ] && [ "$(wc -l <"$tmp/e.err")" -eq 1 ] && grep -qF -- "$1" "$tmp/e.err" &&
        [ ! -e "$tmp/bad/atlas.h5" ] && [ ! -e "$tmp/bad/atlas.chunks" ]; then
        ok
    else
        bad "atlas bad spec ($1): exit $rc: $(cat "$tmp/e.err")"
    fi
}
axes='[[axis]]
name = "k1"
lo = 0.1
hi = 1.0
count = 3
[[axis]]
name = "k2"
lo = 0.1
hi = 1.0
count = 3'
expect_error "bad.toml:1: chunk: expected an integer from 1 to 1000000" "chunk = 2.5
[fixed]
tau = 0.1
th = 1.5
$axes"
expect_error "bad.toml:1: rings: expected integers N from 2" "rings = [1]
[fixed]
tau = 0.1
th = 1.5
$axes"
expect_error "unknown key 'ring'" "ring = 22
$axes"
expect_error "expected 2 to 5 swept parameters" "[fixed]
tau = 0.1
th = 1.5
[[axis]]
name = \"k1\"
values = [0.1]"
expect_error "estimated run time" "rings = [1000]
ring_method = \"modes\"
[fixed]
tau = 0.1
th = 1.5
[[axis]]
name = \"k1\"
lo = 0.1
hi = 1.0
count = 400
[[axis]]
name = \"k2\"
lo = 0.1
hi = 1.0
count = 400"
expect_error "expected at most 1000000 cars on the per-mode ring path" "rings = [2000000]
ring_method = \"modes\"
[fixed]
tau = 0.1
th = 1.5
$axes"
expect_error "ring_method: expected \"auto\", \"winding\" or \"modes\"" "ring_method = \"fast\"
[fixed]
tau = 0.1
th = 1.5
$axes"
# --out on a file is refused
touch "$tmp/afile"
"$bin" atlas "$spec" --out "$tmp/afile" >/dev/null 2>"$tmp/f.err"
[ $? -eq 2 ] && grep -q "is a file, not a folder" "$tmp/f.err" && ok || bad "atlas --out FILE: $(cat "$tmp/f.err")"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
