#!/usr/bin/env bash
# Command-line tests: JSON keys, exit codes, one-line errors, no NaN in output.
set -u
bin="${DDEMAP:?set DDEMAP to the ddemap binary}"
fail=0
pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }

json_has() {  # json_has FILE key1 key2 ...
    python3 - "$@" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
for k in ("command", "version", "inputs", "solver", "status", "message", "result"):  # the one envelope
    assert k in d, "envelope lacks " + k
missing = [k for k in sys.argv[2:] if k not in d and k not in d["result"]]
if missing:
    print("missing keys:", missing); sys.exit(1)
PY
}

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# The tests come in parts (CLI_PARTS="basics files ...": only those; unset: all), so that ctest
# runs them as separate tests (cli_<part>, tests/CMakeLists.txt), in parallel, fast or slow.
part() { [ -z "${CLI_PARTS:-}" ] || [[ " $CLI_PARTS " == *" $1 "* ]]; }
expect_error() {  # expect_error PATTERN args...
    local pattern="$1"; shift
    "$bin" "$@" >"$tmp/o.txt" 2>"$tmp/e.txt"
    local rc=$?
    if [ $rc -ne 2 ]; then bad "exit $rc (expected 2) for: $*"; return; fi
    if [ -s "$tmp/o.txt" ]; then bad "stdout not empty for: $*"; return; fi
    if [ "$(wc -l <"$tmp/e.txt")" -ne 1 ]; then bad "stderr not one line for: $*"; cat "$tmp/e.txt"; return; fi
    if ! grep -q -- "$pattern" "$tmp/e.txt"; then bad "stderr lacks '$pattern' for: $*: $(cat "$tmp/e.txt")"; return; fi
    ok
}
expect_code() {  # expect_code CODE args...
    local code="$1"; shift
    "$bin" "$@" >"$tmp/o.txt" 2>"$tmp/e.txt"
    local rc=$?
    [ $rc -eq "$code" ] && ok || bad "exit $rc (expected $code) for: $*: $(cat "$tmp/e.txt")"
}
rows() { awk '/^  #/{t=1; next} t && NF' "$1" | wc -l; }
crlf() { python3 -c "import sys; t=sys.stdin.read().replace('\n','\r\n'); sys.stdout.buffer.write(b'\xef\xbb\xbf'+t.encode())" >"$1"; }
ms_now() { echo $(( $(date +%s%N) / 1000000 )); }
pgcount() {  # pgcount FILE REGEX: the number of lines of FILE matching REGEX
    grep -c -E "$2" "$1"
}
# files that several parts read (made here, so that any part runs alone)
excerpt="$(dirname "$0")/../data/openacc_excerpt_rav4_to_etron.csv"
fio="$tmp/fio"
mkdir -p "$fio"
orb="$tmp/orbits"; mkdir -p "$orb"
echo '{"variables": ["y"], "parameters": {"alpha": 1}, "equations": ["-alpha*y(t - 1)*(1 + y)"], "equilibrium": [0]}' >"$orb/wright.json"
echo '{"variables": ["x"], "parameters": {"p": 1}, "equations": ["p - x(t - 1)^2"], "equilibrium": [1]}' >"$tmp/fold.json"
echo '{"variables": ["y"], "parameters": {"alpha": 1, "b": 1}, "equations": ["-alpha*y(t - 1)*(1 + b*y)"]}' >"$tmp/wright.json"
# a real 20-dimensional cyclic system
python3 - >"$tmp/cyc.json" <<'PY'
import json
n = 20
print(json.dumps({"dimension": n, "delays": [1.0, 0.4], "A0": {"triplets": [[i, i, -1.0] for i in range(n)]},
                  "A": [{"triplets": [[i, (i - 1) % n, 0.9] for i in range(n)]}, {"triplets": [[i, (i + 1) % n, 0.3] for i in range(n)]}]}))
PY
# the calibration of the excerpt, for the parts that read what calibrate writes
fixture_cal() { [ -s "$tmp/cal.csv" ] || "$bin" calibrate "$excerpt" --quiet --format json --out "$tmp/cal" >/dev/null 2>&1; }

if part basics; then
# roots --format json
if "$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 22 --format json >"$tmp/r.json"; then
    json_has "$tmp/r.json" roots spectral_abscissa ring_stable degree && ok || bad "roots json keys"
    python3 - "$tmp/r.json" <<'PY' && ok || bad "roots json content"
import json, sys
d = json.load(open(sys.argv[1]))["result"]
r = d["roots"]
assert len(r) >= 6, r
for x in r:
    for k in ("re", "im", "mode", "residual"):
        assert k in x, k
    assert x["residual"] < 1e-12
assert d["ring_stable"] is False          # the paper's example is ring unstable at N = 22
assert abs(d["spectral_abscissa"] - r[0]["re"]) == 0
assert isinstance(d["degree"], int) and d["degree"] > 0
PY
else
    bad "roots json exit status"
fi

# string --format json
if "$bin" string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --format json >"$tmp/s.json"; then
    json_has "$tmp/s.json" plant_stable sup_gamma omega_peak lowfreq_margin string_stable && ok || bad "string json keys"
    python3 - "$tmp/s.json" <<'PY' && ok || bad "string json content"
import json, sys
d = json.load(open(sys.argv[1]))["result"]
assert d["plant_stable"] is True and d["string_stable"] is False
assert d["sup_gamma"] > 1 and d["omega_peak"] > 0 and d["lowfreq_margin"] < 0
PY
else
    bad "string json exit status"
fi

# table and csv formats, ring inf, tau = 0, k1 = 0, idm
for args in "roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1" \
            "roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring inf --format csv" \
            "roots --k1 0 --k2 0.2 --th 1.5 --tau 0.1 --ring 5" \
            "roots --k1 0.3 --k2 0.2 --th 1.5 --tau 0 --ring 1000 --count 3" \
            "string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 50 --format csv" \
            "string --model idm --th 1.5 --tau 0.3 --speed 15" \
            "roots --model idm --th 1.5 --tau 0.3 --format json"; do
    if "$bin" $args >"$tmp/o.txt" 2>"$tmp/e.txt"; then
        if grep -qi -E 'nan|-inf|inf,|: inf' "$tmp/o.txt"; then bad "NaN/inf in output of: $args"; else ok; fi
    else
        bad "exit status of: $args"; cat "$tmp/e.txt"
    fi
done

# bad input: exit 2, one line on stderr naming the value, nothing on stdout
expect_error "k1 = -0.5" roots --k1 -0.5 --k2 0.2 --th 1.5 --tau 0.1
expect_error "tau = -1" roots --k1 0.5 --k2 0.2 --th 1.5 --tau -1
expect_error "'abc'" roots --k1 abc --k2 0.2 --th 1.5 --tau 0.1
expect_error "'nan'" string --k1 nan --k2 0.2 --th 1.5 --tau 0.1
expect_error "'inf'" string --k1 0.1 --k2 inf --th 1.5 --tau 0.1
expect_error "'1e999'" string --k1 0.1 --k2 1e999 --th 1.5 --tau 0.1
expect_error "--ring = '1'" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 1
expect_error "--ring = 'x'" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring x
expect_error "--count = '0'" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --count 0
expect_error "--model = 'bando'" roots --model bando --th 1 --tau 0.1
expect_error "needs tau" roots --k1 0.2 --k2 0.2 --th 1.5
expect_error "--format = 'xml'" string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --format xml
expect_error "does not belong" roots --model idm --k1 0.2 --th 1.5 --tau 0.1
expect_error "--bogus" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --bogus 3
expect_error "speed = 40" string --model idm --th 1.5 --tau 0.2 --speed 40

# sweep: files, columns, valid SVG, bitwise identical for 1 and 2 threads
if OMP_NUM_THREADS=1 "$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:30 --k2 0.01:1:25 --out "$tmp/s1" >/dev/null &&
   OMP_NUM_THREADS=2 "$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:30 --k2 0.01:1:25 --out "$tmp/s2" >/dev/null; then
    cmp -s "$tmp/s1.csv" "$tmp/s2.csv" && ok || bad "sweep CSV differs between 1 and 2 threads"
    [ "$(wc -l <"$tmp/s1.csv")" -eq 751 ] && ok || bad "sweep CSV rows"
    head -1 "$tmp/s1.csv" | grep -q '^k1_per_s2,k2_per_s,spectral_abscissa_per_s,unstable_roots,sup_gamma,omega_peak_rad_per_s,plant_stable,ring_stable,string_stable' && ok || bad "sweep CSV header"
    xmllint --noout "$tmp/s1.svg" && ok || bad "sweep SVG is not valid XML"
    grep -q '<text' "$tmp/s1.svg" && grep -q 'id="panel1-boundaries"' "$tmp/s1.svg" && ok || bad "sweep SVG layers"
    json_has "$tmp/s1.json" model fixed x y ring degree seconds version && ok || bad "sweep JSON keys"
    head -1 "$tmp/s1-boundaries.csv" | grep -q '^branch,kind,subkind,mode,k1_per_s2,k2_per_s,omega_rad_per_s' && ok || bad "boundaries CSV header"
else
    bad "sweep exit status"
fi
expect_error "exactly two swept" sweep --th 1.5 --tau 0.5 --k1 0.01:1:30 --out "$tmp/x"
expect_error "LO:HI:COUNT" sweep --th 1.5 --tau 0.5 --k1 0.01:1:1 --k2 0:1:4 --out "$tmp/x"
expect_error "k1 = -1" sweep --th 1.5 --tau 0.5 --k1 -1:1:4 --k2 0:1:4 --out "$tmp/x"
: >"$tmp/afile"
expect_error "is a file, not a folder" sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$tmp/afile/x"
[ ! -e "$tmp/x.csv" ] && ok || bad "a failed sweep left output"

# boundary
if "$bin" boundary --th 1.5 --tau 0.5 --k1 0.01:1 --k2 0.01:1 --seed-grid 21 --out "$tmp/b" >/dev/null; then
    grep -q ',hopf,ring,' "$tmp/b.csv" && grep -q ',string,lowfreq,' "$tmp/b.csv" && ok || bad "boundary kinds"
else
    bad "boundary exit status"
fi
expect_error "LO:HI" boundary --th 1.5 --tau 0.5 --k1 0.01:1:5 --k2 0.01:1 --out "$tmp/b2.csv"

fi  # part basics

if part classify; then
# classify: built in, from a file, errors naming line and column
"$bin" classify --format csv >"$tmp/c.csv" && [ "$(grep -c ',false,false,false,' "$tmp/c.csv")" -eq 0 ] && ok || bad "classify csv"
[ "$(tail -n +2 "$tmp/c.csv" | wc -l)" -eq 14 ] && ok || bad "classify rows"
[ "$(cut -d, -f9 "$tmp/c.csv" | grep -c false)" -eq 14 ] && ok || bad "all 14 string unstable"
# --peak: the peak (L-infinity) verdict and ||h||_1 as the last columns; a string-stable car that
# overshoots, a monotone one, one whose plant is unstable (infinite norm: "inf" in the table,
# empty CSV fields, null in JSON)
printf 'name,k1,k2,th,tau\nover,0.05,0.3,3.0,0.1\nmono,0.05,0.8,2.0,0.1\nwild,1,0.1,0.5,1.5\n' >"$tmp/pk.csv"
"$bin" classify "$tmp/pk.csv" --peak --format csv >"$tmp/pk.out" && head -1 "$tmp/pk.out" | grep -q ',peak_verdict,peak_norm,peak_norm_error$' &&
    grep -q '^over,.*,true,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*,unstable,1\.01629' "$tmp/pk.out" && grep -q '^mono,.*,stable,1\.000000000[0-9]*,' "$tmp/pk.out" && grep -q '^wild,.*,unstable,,$' "$tmp/pk.out" &&
    ok || bad "classify --peak csv: $(cat "$tmp/pk.out")"
"$bin" classify "$tmp/pk.csv" --peak | grep -q '^wild .*UNSTABLE  *inf$' && ok || bad "classify --peak table: the unstable plant's norm"
"$bin" classify "$tmp/pk.csv" --peak --format json | python3 -c "
import json,sys; v={r['name']: r for r in json.load(sys.stdin)['result']['vehicles']}
assert v['wild']['peak_norm'] is None and v['mono']['peak_stable'] is True and v['over']['peak_stable'] is False and v['over']['string_stable'] is True, v" &&
    ok || bad "classify --peak json"
"$bin" classify "$tmp/pk.csv" --no-peak --format csv | head -1 | grep -q 'peak_verdict' && bad "classify --no-peak has peak columns" || ok
"$bin" classify "$tmp/pk.csv" --format csv | head -1 | grep -q ',peak_verdict,peak_norm,peak_norm_error$' && ok || bad "classify: peak columns by default"
expect_error "--peak and --no-peak: expected one of them" classify --peak --no-peak
# --distance: the relative change that flips the verdict; the parameters at the flip, written
# back as a car, get the other verdict (a second run of the certified verdicts)
"$bin" classify "$tmp/pk.csv" --distance --format json >"$tmp/dist.json" && python3 - "$tmp/dist.json" "$tmp/flip.csv" <<'PY' && ok || bad "classify --distance json: $(head -c 600 "$tmp/dist.json")"
import json, sys
d = json.load(open(sys.argv[1]))
v = {r["name"]: r for r in d["result"]["vehicles"]}
assert d["status"] == "converged", d["message"]
o, w = v["over"]["verdict_distance"], v["wild"]["verdict_distance"]
assert o["status"] == "converged" and o["to"] == "string unstable" and o["boundary"] == "low-frequency" and 0.03 < o["distance"] < 0.08, o
assert w["status"] == "converged" and w["to"] == "string stable" and 1 < w["distance"] < 2.5, w
rows = "".join("%s,%r,%r,%r,%r\n" % (name, x["at"]["k1"], x["at"]["k2"], x["at"]["th"], x["at"]["tau"]) for name, x in (("flipover", o), ("flipwild", w)))
open(sys.argv[2], "w").write("name,k1,k2,th,tau\n" + rows)
PY
"$bin" classify "$tmp/flip.csv" --no-peak --format csv >"$tmp/flip.out" && grep -q '^flipover,.*,false,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*$' "$tmp/flip.out" &&
    grep -q '^flipwild,.*,true,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*,[^,]*$' "$tmp/flip.out" && ok || bad "classify: the flip points have the other verdicts: $(cat "$tmp/flip.out")"
"$bin" classify "$tmp/pk.csv" --distance 2>/dev/null | grep -q '^over .* 5\.1 %$' && ok || bad "classify --distance table"
"$bin" classify "$tmp/pk.csv" --distance --format csv 2>/dev/null | head -1 | grep -q ',verdict_distance,verdict_distance_boundary,verdict_distance_omega_rad_per_s$' && ok || bad "classify --distance csv header"
printf 'name,k1,k2,th,tau,eta
mine,0.2,0.6,1.5,0.1,10
' >"$tmp/v.csv"
"$bin" classify "$tmp/v.csv" --format json >"$tmp/v.json" && python3 -c "
import json,sys; d=json.load(open('$tmp/v.json')); v=d['result']['vehicles'][0]
assert v['name']=='mine' and v['string_stable'] is True, v" && ok || bad "classify file"
printf 'name,k1,k2,th,tau
A,0.1,0.2,1,0.3
B,0.1,abc,1,0.3
' >"$tmp/bad.csv"
expect_error "bad.csv:3: column 'k2' = 'abc'" classify "$tmp/bad.csv"
printf 'name,k1,k2,th
A,0.1,0.2,1
' >"$tmp/bad2.csv"
expect_error "bad2.csv:2: car 'A': model ovrv needs tau" classify "$tmp/bad2.csv"
printf 'name,k1,k2,th,tau
A,0.1,0.2,1
' >"$tmp/bad3.csv"
expect_error "bad3.csv:2: 4 fields, expected 5" classify "$tmp/bad3.csv"
printf 'name,k1,k2,th,tau
A,-0.1,0.2,1,0.3
' >"$tmp/bad4.csv"
expect_error "bad4.csv:2: car 'A': k1 = -0.1" classify "$tmp/bad4.csv"
expect_error "cannot open" classify "$tmp/none.csv"

# chart spec errors
printf 'model = "ovrv"
[x]
name = "k1"
lo = 0
hi = 1
count = 1
' >"$tmp/bad.toml"
expect_error "bad.toml:2: x: expected lo < hi" chart "$tmp/bad.toml" --out "$tmp/bad.svg"

# simulate: files, JSON keys, events
if "$bin" simulate --fleet 'B_min*6' --lead-profile dip --out "$tmp/sim" >/dev/null; then
    head -1 "$tmp/sim.csv" | grep -q '^time_s,car,position_m,speed_mps,gap_m$' && ok || bad "simulate CSV header"
    python3 - "$tmp/sim.json" <<'PY' && ok || bad "simulate JSON"
import json, sys
d = json.load(open(sys.argv[1]))["result"]
cars = d["cars"]
assert len(cars) == 6
for c in cars:
    for k in ("lowest_speed", "speed_drop", "min_gap", "events"):
        assert k in c, k
assert any(e["type"] == "collision" for c in cars for e in c["events"])  # B_min fails within 6 cars
PY
    xmllint --noout "$tmp/sim.svg" && ok || bad "simulate SVG"
else
    bad "simulate exit status"
fi
printf 'time_s,lead_speed_mps
0,20
10,20
20,18
40,20
' >"$tmp/lead.csv"
"$bin" simulate --fleet 'E_min*2,A_max' --lead "$tmp/lead.csv" --out "$tmp/sim2" >/dev/null && ok || bad "simulate with a lead file"
expect_error "'Z_min'" simulate --fleet 'Z_min' --out "$tmp/sim3"
expect_error "--on-event = 'maybe'" simulate --fleet A_min --on-event maybe --out "$tmp/sim3"
expect_error "--lead-profile = 'wave'" simulate --fleet A_min --lead-profile wave --out "$tmp/sim3"
printf 'time_s,lead_speed_mps
0,20
0,21
' >"$tmp/badlead.csv"
expect_error "badlead.csv:3: time_s = 0" simulate --fleet A_min --lead "$tmp/badlead.csv" --out "$tmp/sim3"

# growth
"$bin" growth --format csv >"$tmp/g.csv" && head -1 "$tmp/g.csv" | grep -q '^name,position,speed_drop_mps,amplification,min_gap_m,failure$' && ok || bad "growth csv"

fi  # part classify

if part calibrate; then
# calibrate: an excerpt of real data (tests/data), JSON keys, the table goes into classify
if "$bin" calibrate "$excerpt" --format json --out "$tmp/cal" >"$tmp/cal.json"; then
    python3 -c "import json,sys; f=json.load(open('$tmp/cal.json'))['result']['fits'][0]; missing=[k for k in 'k1 k2 th tau eta rmse_speed rmse_gap status'.split() if k not in f]; sys.exit(1 if missing else 0)" && ok || bad "calibrate JSON keys"
    # the uncertainty keys scripts rely on: ci95 per parameter (lo <= value <= hi where given),
    # a symmetric (exactly, as printed) 5 x 5 covariance with a non-negative diagonal, warnings as a list of strings
    python3 - "$tmp/cal.json" <<'PY' && ok || bad "calibrate JSON uncertainty keys"
import json, sys
f = json.load(open(sys.argv[1]))['result']['fits'][0]
names = ['k1', 'k2', 'th', 'tau', 'eta']
assert all(k in f for k in ['ci95', 'covariance', 'warnings', 'naive_rmse_speed', 'objective', 'starts', 'status'])
for n in names:
    lo, hi = f['ci95'][n]
    assert lo is None or hi is None or lo <= f[n] <= hi, n
c = f['covariance']
assert len(c) == 5 and all(len(r) == 5 for r in c)
assert all(c[i][i] is None or c[i][i] >= 0 for i in range(5))
assert all(c[i][j] == c[j][i] for i in range(5) for j in range(5))
assert isinstance(f['warnings'], list) and all(isinstance(w, str) for w in f['warnings'])
assert f['starts'] >= 1 and f['objective'] >= 0
# the lead noise allowed for (one run), and the standard errors without it never larger
assert len(f['lead_noise']) == 1 and 0 <= f['lead_noise'][0] < 0.01
se, sx = f['standard_errors'], f['standard_errors_exact_lead']
assert all(sx[n] <= se[n] * (1 + 1e-12) for n in names if se[n] is not None and sx[n] is not None)
# the bias correction applied (an evenly sampled run with some lead noise): it lowers what is minimised
assert f['lead_noise_corrected'] is True and f['minimised_objective'] <= f['objective']
PY
    "$bin" classify "$tmp/cal.csv" --format csv >/dev/null && ok || bad "calibrate table into classify"
    xmllint --noout "$tmp/cal.svg" && ok || bad "calibrate SVG"
else
    bad "calibrate exit status"
fi
printf 'time_s,lead_speed_mps,follower_speed_mps,gap_m
0,1,1,1
0.1,1,x,1
' >"$tmp/badtrace.csv"
expect_error "badtrace.csv:3: column 'follower_speed_mps' = 'x'" calibrate "$tmp/badtrace.csv"
expect_error "--bounds item 'eta=15'" calibrate "$excerpt" --bounds eta=15
expect_error "--train = '5'" calibrate "$excerpt" --train 5
expect_error "--lead-noise = -1: expected auto, or 0 to 10 m/s" calibrate "$excerpt" --lead-noise -1
expect_error "--lead-noise-correction" calibrate "$excerpt" --lead-noise-correction maybe
"$bin" calibrate "$excerpt" --lead-noise-correction off --format json 2>/dev/null |
    python3 -c "import json, sys; f = json.load(sys.stdin)['result']['fits'][0]; assert f['lead_noise_corrected'] is False and f['minimised_objective'] == f['objective']" &&
    ok || bad "calibrate --lead-noise-correction off"

# calibrate on several files: one progress line per finished fit on stderr, always {"fits": [...]}
cp "$excerpt" "$tmp/run2.csv"
if DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" calibrate "$excerpt" "$tmp/run2.csv" --format json >"$tmp/cal2.json" 2>"$tmp/cal2.err"; then
    grep -q '^ddemap: calibrate: fits 1/2 done, \(run2\|openacc_excerpt_rav4_to_etron\) in [0-9.e-]* s ([^)]*, about [^)]* left)$' "$tmp/cal2.err" &&
        grep -q '^ddemap: calibrate: fits 2/2 done, \(run2\|openacc_excerpt_rav4_to_etron\) in [0-9.e-]* s ([^)]*)$' "$tmp/cal2.err" && ok || bad "calibrate progress lines: $(cat "$tmp/cal2.err")"
    python3 -c "import json; r=json.load(open('$tmp/cal2.json'))['result']; assert len(r['fits']) == 2 and r['fits'][1]['name'] == 'run2'" && ok || bad "calibrate two files JSON"
else
    bad "calibrate two files exit status"
fi
# --joint: one fit of the same shape, with its runs
if "$bin" calibrate --joint --car rav4 "$excerpt" "$tmp/run2.csv" --format json >"$tmp/calj.json" 2>/dev/null; then
    python3 - "$tmp/calj.json" <<'PY' && ok || bad "calibrate --joint JSON"
import json, sys
r = json.load(open(sys.argv[1]))['result']
assert len(r['fits']) == 1
f = r['fits'][0]
assert f['name'] == 'rav4' and len(f['train_runs']) == 2 and f['tests'] == []
assert all(k in f for k in ['k1', 'ci95', 'covariance', 'warnings', 'rmse_speed', 'naive_rmse_speed', 'objective', 'starts', 'status'])
PY
else
    bad "calibrate --joint exit status"
fi
# --runs with a test run and --report: the tables and a figure per run; a test run that is the
# training file itself has the training run's whole-file errors
printf 'car,file,role,type\nrav4,%s,train,\nrav4,%s,test,same\n' "$excerpt" "$tmp/run2.csv" >"$tmp/runs.csv"
if "$bin" calibrate --runs "$tmp/runs.csv" --report "$tmp/report" --format json >"$tmp/calr.json" 2>/dev/null; then
    python3 - "$tmp/calr.json" "$tmp/report" <<'PY' && ok || bad "calibrate --runs --report"
import csv, json, sys
f = json.load(open(sys.argv[1]))['result']['fits'][0]
t = f['tests'][0]
assert t['type'] == 'same' and t['rmse_speed'] == f['train_runs'][0]['rmse_speed'] and t['rmse_gap'] == f['train_runs'][0]['rmse_gap']
rows = list(csv.DictReader(open(sys.argv[2] + '/table.csv')))
assert len(rows) == 1 and rows[0]['car'] == 'rav4' and float(rows[0]['same_rmse_speed_mps']) == t['rmse_speed']
assert float(rows[0]['k1_per_s2']) == f['k1'] and float(rows[0]['k1_lo_per_s2']) == f['ci95']['k1'][0]
j = json.load(open(sys.argv[2] + '/table.json'))
assert j['test_types'] == ['same'] and j['cars'][0]['test']['same']['rmse_gap'] == t['rmse_gap']
md = open(sys.argv[2] + '/table.md').read()
assert '| car | train runs | k1 [1/s^2]' in md and '| car | speed train [m/s] | speed same / naive | spacing train [m] | spacing same |' in md
PY
    for svg in "$tmp"/report/fit_rav4_*.svg; do xmllint --noout "$svg" || bad "report figure $svg"; done
    [ "$(ls "$tmp"/report/fit_rav4_*.svg | wc -l)" -eq 2 ] && ok || bad "report: one figure per run"
else
    bad "calibrate --runs exit status"
fi
printf 'car,file,role\nrav4,%s,fit\n' "$excerpt" >"$tmp/badruns.csv"
expect_error "badruns.csv:2: column 'role' = 'fit': expected train or test" calibrate --runs "$tmp/badruns.csv"
printf 'car,file,role\nrav4,%s,test\n' "$excerpt" >"$tmp/badruns2.csv"
expect_error "car 'rav4' has no run with role train" calibrate --runs "$tmp/badruns2.csv"
expect_error "--joint: not with --runs" calibrate --joint --runs "$tmp/runs.csv"
expect_error "expected at least one trace" calibrate
touch "$tmp/notadir"
expect_error "--report = '$tmp/notadir': the folder does not exist and cannot be created" calibrate "$excerpt" --report "$tmp/notadir"

fi  # part calibrate

if part system; then
# roots --system: any linear DDE from JSON
cat >"$tmp/sys.json" <<'JSON'
{"dimension": 2, "delays": [1.0, 0.3], "A0": [[0, 0], [0, 0]],
 "A": [{"triplets": [[0, 0, -1]]}, {"triplets": [[1, 1, [0, 0.5]]]}]}
JSON
"$bin" roots --system "$tmp/sys.json" --format json >"$tmp/sys.out" && json_has "$tmp/sys.out" roots spectral_abscissa stable degree status && ok || bad "roots --system"
printf '{"dimension": 2, "A0": [[1, 2], [3]]}' >"$tmp/bad.json"
expect_error "bad.json: A0\[1\]: expected 2 entries" roots --system "$tmp/bad.json"
expect_error "expected no model parameters" roots --system "$tmp/sys.json" --k1 0.3
expect_error "the sparse path needs real coefficients" roots --system "$tmp/sys.json" --solver sparse
expect_error "solver product goes with --fleet rings" roots --system "$tmp/sys.json" --solver product
printf '{"dimension": 1, "delays": [1], "A0": [[1e400]], "A": [[[0.5]]]}' >"$tmp/huge.json"
expect_error "a number outside the range of doubles" roots --system "$tmp/huge.json"
# a real 20-dimensional cyclic system: auto takes the sparse path; the dense path agrees
"$bin" roots --system "$tmp/cyc.json" --count 6 --format json >"$tmp/cyc_s.json" &&
    "$bin" roots --system "$tmp/cyc.json" --count 6 --solver dense --format json >"$tmp/cyc_d.json" &&
    python3 - "$tmp/cyc_s.json" "$tmp/cyc_d.json" <<'PY' && ok || bad "roots --system: sparse (auto) against dense"
import json, sys
s, d = (json.load(open(f)) for f in sys.argv[1:3])
assert s["solver"]["used"] == "sparse" and d["solver"]["used"] == "dense", (s["solver"], d["solver"])
assert s["status"] == d["status"] == "converged"
zs = [complex(r["re"], r["im"]) for r in s["result"]["roots"]]
zd = [complex(r["re"], r["im"]) for r in d["result"]["roots"]]
assert len(zs) >= 6 and all(min(abs(z - w) for w in zd) < 1e-9 for z in zs), (zs, zd)
PY

# a stiff 400-state delayed diffusion u' = 0.05 u_xx + 0.5 u - u(t - 2) on (0, 1): the sparse path's
# output is bitwise identical for 1 and 2 threads, and its roots are the Lambert-W closed form
# (mode k: lambda + mu_k - 0.5 = -exp(-2 lambda), mu_k = 0.05 (n+1)^2 4 sin^2(k pi / (2 (n+1))))
python3 - >"$tmp/diff.json" <<'PY'
import json
n, c = 400, 0.05 * 401 ** 2
a0 = [[i, i, -2 * c + 0.5] for i in range(n)] + [[i, i + 1, c] for i in range(n - 1)] + [[i + 1, i, c] for i in range(n - 1)]
print(json.dumps({"dimension": n, "delays": [2.0], "A0": {"triplets": a0}, "A": [{"triplets": [[i, i, -1.0] for i in range(n)]}]}))
PY
OMP_NUM_THREADS=1 "$bin" roots --system "$tmp/diff.json" --count 6 --solver sparse --format json >"$tmp/diff1.json" &&
    OMP_NUM_THREADS=2 "$bin" roots --system "$tmp/diff.json" --count 6 --solver sparse --format json >"$tmp/diff2.json" &&
    cmp -s "$tmp/diff1.json" "$tmp/diff2.json" && ok || bad "roots --system (sparse): output depends on the number of threads"
python3 - "$tmp/diff1.json" <<'PY' && ok || bad "roots --system (sparse, stiff diffusion) against the Lambert-W closed form"
import json, sys, cmath, math
e = json.load(open(sys.argv[1]))
assert e["status"] == "converged" and e["solver"]["used"] == "sparse", (e["status"], e["solver"])
n = 400
def branch(mu, z):  # Newton on lambda + mu - 0.5 + exp(-2 lambda) = 0 from z
    for _ in range(100):
        f = z + mu - 0.5 + cmath.exp(-2 * z)
        z -= f / (1 - 2 * cmath.exp(-2 * z))
    return z
ref = []
for k in range(1, 6):
    mu = 0.05 * 401 ** 2 * 4 * math.sin(k * math.pi / 802) ** 2
    for z0 in (complex(0.3, 0.6), complex(0, 1.0), complex(-0.3, 3.5)):
        z = branch(mu, z0)
        if abs(z + mu - 0.5 + cmath.exp(-2 * z)) < 1e-12 and all(abs(z - w) > 1e-8 for w in ref):
            ref += [z, z.conjugate()]
zs = [complex(r["re"], r["im"]) for r in e["result"]["roots"]]
assert len(zs) >= 6, zs
# every listed root is a closed-form root (the stiff tolerance: rounding eps ||A0|| ~ 1e-11)
assert all(min(abs(z - w) for w in ref) < 1e-8 for z in zs), (zs, sorted(ref, key=lambda z: -z.real)[:8])
PY

fi  # part system

if part fleet; then
# mixed fleets: roots --fleet-pattern / --fleet, bad fleet files, mix
"$bin" roots --fleet-pattern "A_min,E_min*2" --ring 12 --count 4 --format json >"$tmp/fleet.json" &&
    json_has "$tmp/fleet.json" roots spectral_abscissa ring_stable trivial_root_found product_residual strip_floor status degree_reason && ok || bad "roots --fleet-pattern json"
python3 - "$tmp/fleet.json" <<'PY' && ok || bad "roots --fleet-pattern content"
import json, sys
e = json.load(open(sys.argv[1]))
d = e["result"]
assert e["status"] == "converged" and d["ring"] == 12, d
assert len(d["roots"]) >= 4 and all(r["residual"] < 1e-12 for r in d["roots"]), d["roots"]
assert d["product_residual"] < 1e-10, d["product_residual"]
PY
printf 'vehicle,model,k1,k2,th,tau,k3,tau2,count
A_min,,,,,,,,4
,ccc,0.2,0.4,1.2,0.4,0.2,0.2,4
' >"$tmp/fleet.csv"
"$bin" roots --fleet "$tmp/fleet.csv" --length 300 --format json >"$tmp/fleet2.json" && json_has "$tmp/fleet2.json" roots speed length && ok || bad "roots --fleet"
printf 'vehicle,k1
A_min,0.1
B_mx,0.2
' >"$tmp/badfleet.csv"
expect_error "badfleet.csv:3: column 'vehicle' = 'B_mx'" roots --fleet "$tmp/badfleet.csv"
expect_error "car 'Q': expected a setting of the paper's table" roots --fleet-pattern "A_min,Q" --ring 4
# the product path (automatic for cars of the car ahead) against the sparse path
"$bin" roots --fleet-pattern "A_min,C_max*2,E_min" --ring 40 --count 6 --format json >"$tmp/prod.json" &&
    "$bin" roots --fleet-pattern "A_min,C_max*2,E_min" --ring 40 --count 6 --solver sparse --format json >"$tmp/spar.json" &&
    python3 - "$tmp/prod.json" "$tmp/spar.json" <<'PY' && ok || bad "roots --fleet-pattern: product against sparse"
import json, sys
p, s = (json.load(open(f)) for f in sys.argv[1:3])
assert p["status"] == s["status"] == "converged"
assert p["solver"]["used"] == "product" and s["solver"]["used"] == "sparse", (p["solver"], s["solver"])
p, s = p["result"], s["result"]
assert p["shifts"] == 0 and s["shifts"] > 0, (p["shifts"], s["shifts"])
zp = [complex(r["re"], r["im"]) for r in p["roots"]]
zs = [complex(r["re"], r["im"]) for r in s["roots"]]
assert len(zp) == len(zs) >= 6 and all(abs(a - b) < 1e-10 for a, b in zip(zp, zs)), (zp, zs)
PY
"$bin" roots --fleet "$tmp/fleet.csv" --solver product --format json | python3 -c "import json,sys; sys.exit(0 if json.load(sys.stdin)['solver']['used'] == 'product' else 1)" && ok || bad "--solver product with ccc cars"
expect_error "the product path has no collocation degree" roots --fleet-pattern "A_min,E_min" --ring 6 --solver product --degree 20
"$bin" roots --fleet-pattern "A_min,E_min" --ring 6 --degree 20 --format json | python3 -c "import json,sys; sys.exit(0 if json.load(sys.stdin)['result']['degree'] == 20 else 1)" && ok || bad "--degree selects a collocation path"
expect_error "expected at least" roots --fleet-pattern "A_min" --ring 4 --length 5
# a ring smaller than its fleet is refused (its last cars were dropped without a word)
expect_error "--ring 2: fewer cars than --fleet has (4): expected at least 4" roots --fleet "A_min*3,B_min" --ring 2
"$bin" roots --fleet "A_min*3,B_min" --ring 6 --count 2 >/dev/null 2>"$tmp/cut.err" && grep -q "not a multiple of the fleet's 4 cars: the last repetition has only its first 2" "$tmp/cut.err" && ok || bad "roots --ring cut repetition note: $(cat "$tmp/cut.err")"
if "$bin" mix --x E_min --y A_min --ring 10 --p 0:1:3 --out "$tmp/mix" >/dev/null && [ -s "$tmp/mix.csv" ] && xmllint --noout "$tmp/mix.svg"; then
    python3 - "$tmp/mix.csv" <<'PY' && ok || bad "mix csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["x_cars"] for r in rows] == ["0", "5", "10"], rows
assert all(r["status"] == "converged" for r in rows), rows
PY
else bad "mix"; fi
expect_error "--p = '0:1.5:3': the fraction 1.5: expected fractions of X in \[0, 1\]" mix --x E_min --y A_min --ring 10 --p 0:1.5:3 --out "$tmp/mix2"
[ ! -e "$tmp/mix2.csv" ] && ok || bad "mix wrote output after an error"

fi  # part fleet

if part exits; then
# exit codes (README "Exit codes"): 0 success, 2 bad input, 3 internal error, 4 not converged, 5 write failed
expect_code 0 string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1
expect_code 2 string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --format xml
DDEMAP_TEST_FAULT=internal expect_code 3 string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1
grep -q 'internal error' "$tmp/e.txt" && ok || bad "internal error message"
# a collocation degree far too low for a 20-state system: printed, undecided, exit 4
expect_code 4 roots --system "$tmp/cyc.json" --degree 2 --count 10 --format json
python3 - "$tmp/o.txt" <<'PY' && ok || bad "not converged: status and message in the envelope"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["status"] == "max_degree_reached" and d["message"], d
assert d["result"]["stable"] is False
PY
"$bin" roots --system "$tmp/cyc.json" --degree 2 --count 10 > "$tmp/cyc.txt"
grep -q 'UNDECIDED' "$tmp/cyc.txt" && ok || bad "not converged: the table says undecided"
# ... and its message row is not labelled "trusted"
grep -q '^why not    ' "$tmp/cyc.txt" && ! grep -q '^trusted' "$tmp/cyc.txt" && ok || bad "not converged: the message row says why not"
# the folder is fine, but PREFIX.json is a folder: refused before any work (exit 2); a move that
# fails after the computation (test hook) is exit 5 with nothing half-written
mkdir -p "$tmp/w.json"
expect_error "w.json' is a folder, expected a file" classify --out "$tmp/w"
mkdir -p "$tmp/wf"
DDEMAP_TEST_FAULT=move:2 expect_code 5 roots --k1 0.2 --k2 0.4 --th 1.5 --tau 0.3 --out "$tmp/wf/w"
grep -q "cannot write .*w.json: Input/output error" "$tmp/e.txt" && ok || bad "write failure message"
[ -z "$(ls -A "$tmp/wf")" ] && ok || bad "a failed write left files"

# --format on every command; a format without meaning is a clear error naming the accepted ones
for c in roots string classify sweep boundary chart paper simulate growth calibrate mix; do
    "$bin" $c --help | grep -q -- '--format' && ok || bad "$c has no --format"
done
expect_error "--format = 'csv': this command has no csv output; expected table or json" chart "$tmp/bad.toml" --out "$tmp/c" --format csv
expect_error "--format = 'csv'" paper --out "$tmp/p" --format csv
# --out PREFIX: folders created as needed; the old file spelling --out FILE.csv still writes FILE.csv
"$bin" boundary --th 1.5 --tau 0.5 --k1 0.01:1 --k2 0.01:1 --seed-grid 11 --out "$tmp/new/dir/b.csv" >/dev/null &&
    [ -s "$tmp/new/dir/b.csv" ] && [ -s "$tmp/new/dir/b.json" ] && ok || bad "--out creates folders"
"$bin" string --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --out "$tmp/st" >/dev/null && [ -s "$tmp/st.csv" ] && json_has "$tmp/st.json" sup_gamma && ok || bad "string --out"
# the old spelling --cars of a ring size still works
"$bin" roots --fleet-pattern "A_min,E_min" --cars 6 --format json | python3 -c "import json,sys; sys.exit(0 if json.load(sys.stdin)['result']['ring'] == 6 else 1)" && ok || bad "--cars (old spelling of --ring)"
expect_error "--ring = 'inf'" mix --x E_min --y A_min --ring inf --out "$tmp/mix3"
# JSON on every command: the envelope
"$bin" growth --followers 2 --format json >"$tmp/g.json" && json_has "$tmp/g.json" vehicles lead && ok || bad "growth json"
"$bin" classify --format json >"$tmp/c.json" && json_has "$tmp/c.json" vehicles ring && ok || bad "classify json"
"$bin" mix --x E_min --y A_min --ring 6 --p 0:1:2 --out "$tmp/mixj" --format json >"$tmp/m.json" && json_has "$tmp/m.json" points &&
    python3 -c "import json; d=json.load(open('$tmp/m.json')); assert d['solver']['used'] == 'product' and 'spectral_abscissa' in d['result']['points'][0]" && ok || bad "mix json"

# verdicts (issue 15): the low-frequency boundary, tiny delays, the computable range, MARGINAL,
# --count on every path, UNDECIDED with its reason on stderr and exit 4
"$bin" string --k1 0.2 --k2 0.6423077 --th 1.5 --tau 0.2 --ring inf --format json >"$tmp/v1.json" && python3 - "$tmp/v1.json" <<'PY' && ok || bad "string at c2 = +4e-9: stable, positive margin"
import json, sys
r = json.load(open(sys.argv[1]))["result"]
assert 0 < r["lowfreq_margin"] < 1e-8, r["lowfreq_margin"]
assert r["string_stable"] is True and r["string_verdict"] == "stable" and r["peak_margin"] > 0, r
assert r["ring_stable"] is True and r["ring_verdict"] == "stable" and r["spectral_abscissa"] == 0, r
PY
"$bin" string --k1 0.2 --k2 0.64230769 --th 1.5 --tau 0.2 --ring inf --format json >"$tmp/v2.json" && python3 - "$tmp/v2.json" <<'PY' && ok || bad "string at c2 = -1.2e-9: unstable, negative margin"
import json, sys
r = json.load(open(sys.argv[1]))["result"]
assert -1e-8 < r["lowfreq_margin"] < 0, r["lowfreq_margin"]
assert r["string_stable"] is False and r["string_verdict"] == "unstable" and r["peak_margin"] < 0, r
assert r["ring_verdict"] == "unstable" and r["spectral_abscissa"] > 0, r
PY
"$bin" string --k1 0.2 --k2 0.2 --th 1.5 --tau 1e-9 >"$tmp/v3.txt" 2>"$tmp/v3.err" && grep -q '^plant  *stable' "$tmp/v3.txt" && [ ! -s "$tmp/v3.err" ] &&
    ok || bad "string --tau 1e-9: plant stable, exit 0"
# peak (L-infinity) string stability: keys, an unstable plant (infinite norm: null, never inf),
# a delay too short to integrate within the step budget (undecided, exit 4, one line)
"$bin" string --k1 0.1 --k2 0.2 --th 1.5 --tau 0.3 --format json >"$tmp/pk.json" &&
    python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['result']; sys.exit(0 if r['peak_verdict'] == 'unstable' and r['peak_stable'] is False and abs(r['peak_norm'] - 1.4901573) < 1e-6 and r['peak_norm_error'] < 1e-7 and r['sup_gamma'] <= r['peak_norm'] else 1)" "$tmp/pk.json" &&
    ok || bad "string: peak keys $(head -c 300 "$tmp/pk.json")"
"$bin" string --k1 0.05 --k2 0.8 --th 2 --tau 0.1 --format csv | tail -1 | grep -q ',true,stable,1\.0*[0-9]*,' && ok || bad "string --format csv: a peak-stable car"
"$bin" string --k1 1 --k2 0.1 --th 0.5 --tau 1.5 --format json >"$tmp/pk2.json"
python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['result']; sys.exit(0 if not r['plant_stable'] and r['peak_verdict'] == 'unstable' and r['peak_norm'] is None else 1)" "$tmp/pk2.json" &&
    ok || bad "string: an unstable plant has peak_norm null: $(grep -o '"peak[a-z_]*": [^,]*' "$tmp/pk2.json" | tr '\n' ' ')"
"$bin" string --k1 0.2 --k2 0.6 --th 1.5 --tau 1e-5 >"$tmp/pk3.txt" 2>"$tmp/pk3.err"
rc=$?
[ $rc -eq 4 ] && [ "$(wc -l <"$tmp/pk3.err")" -eq 1 ] && grep -q "peak undecided (budget_exhausted): the step response would need" "$tmp/pk3.err" &&
    grep -q "peak UNDECIDED" "$tmp/pk3.txt" && ok || bad "string --tau 1e-5: exit $rc, $(cat "$tmp/pk3.err")"
for t in 1e-300 1e-12 1e-9; do
    "$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau $t --count 3 --format json >"$tmp/v4.json" &&
        "$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0 --count 3 --format json >"$tmp/v5.json" && python3 - "$tmp/v4.json" "$tmp/v5.json" <<'PY' && ok || bad "roots --tau $t continuous with tau = 0"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:])
assert a["status"] == "converged", a["status"]
assert abs(a["result"]["spectral_abscissa"] - b["result"]["spectral_abscissa"]) < 1e-8
assert a["result"]["ring_verdict"] == b["result"]["ring_verdict"] == "unstable"
PY
done
expect_error "computable range" roots --k1 1e6 --k2 0.2 --th 1.5 --tau 0.2
expect_error "computable range" roots --k1 0.2 --k2 0.2 --th 1e10 --tau 0.2
expect_error "computable range" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 1e6
expect_error "expected <= 1e+08" roots --k1 1e10 --k2 0.2 --th 1.5 --tau 0.2
expect_error "expected <= 1e+08" string --k1 0.2 --k2 1e11 --th 1.5 --tau 0.2
# beyond any meaning (and the products of the analyses): named with the unit, never a nan
expect_error "k1 = 1e+300: expected at most 1e12 \[1/s^2\] in magnitude" roots --k1 1e300 --k2 0.2 --th 1.5 --tau 0.2
expect_error "th = 1e+308: expected at most 1e12 \[s\]" classify 'ovrv:k1=0.1,k2=0.2,th=1e308,tau=0.1'
expect_error "speed = 1e+308: expected at most 1e12" roots --fleet A_min,B_min --speed 1e308
expect_error "expected <= 10" string --k1 19.9 --k2 0.2 --th 1.5 --tau 0.2
"$bin" roots --k1 19.8 --k2 0.2 --th 1.5 --tau 0.2 --count 3 >"$tmp/v6.txt" && grep -q 'verdict    ring STABLE' "$tmp/v6.txt" &&
    ok || bad "roots just inside the computable range"
"$bin" roots --k1 0 --k2 0.2 --th 1.5 --tau 0.2 --count 6 >"$tmp/v7.txt" && grep -q 'verdict    ring MARGINAL' "$tmp/v7.txt" &&
    [ "$(rows "$tmp/v7.txt")" -eq 6 ] && ok || bad "roots --k1 0: MARGINAL and 6 rows"
"$bin" roots --k1 0 --k2 0.2 --th 1.5 --tau 0.2 --format json | python3 -c "import json,sys; assert json.load(sys.stdin)['result']['ring_verdict'] == 'marginal'" &&
    ok || bad "roots --k1 0 json ring_verdict"
"$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.2 --ring inf --count 4 >"$tmp/v8.txt" && n=$(rows "$tmp/v8.txt") && [ "$n" -ge 4 ] && [ "$n" -le 5 ] &&
    ok || bad "roots --ring inf --count 4 lists 4 rows"
"$bin" string --k1 0 --k2 0.2 --th 1.5 --tau 0.2 >"$tmp/v9.txt" && grep -q '^plant  *MARGINAL' "$tmp/v9.txt" && grep -q 'string MARGINAL' "$tmp/v9.txt" &&
    ok || bad "string --k1 0: MARGINAL, not UNSTABLE"
printf '{"dimension": 1, "delays": [1.0], "A0": [[0.0]], "A": [[[-1.5707963267948966]]]}\n' >"$tmp/marg.json"
"$bin" roots --system "$tmp/marg.json" --count 3 --format json | python3 -c "import json,sys; r=json.load(sys.stdin)['result']; assert r['verdict']=='marginal' and 3 <= len(r['roots']) <= 4, r" &&
    ok || bad "roots --system on the axis: marginal, 3 roots (+ a conjugate partner)"
"$bin" roots --fleet-pattern A_min --ring 3 --solver sparse --degree 2 >"$tmp/v10.txt" 2>"$tmp/v10.err"; rc=$?
[ $rc -eq 4 ] && grep -q 'verdict    UNDECIDED' "$tmp/v10.txt" && grep -q 'undecided' "$tmp/v10.err" && [ "$(wc -l <"$tmp/v10.err")" -eq 1 ] &&
    ok || bad "unconverged fleet roots: UNDECIDED, reason on stderr, exit 4 (got $rc)"
"$bin" roots --fleet-pattern A_min --ring 5 --count 2 --format json | python3 -c "import json,sys; r=json.load(sys.stdin)['result']; assert 2 <= len(r['roots']) <= 3 and r['ring_verdict'] in ('stable','unstable','marginal'), r" &&
    ok || bad "roots --fleet-pattern --count 2"

# classify with the covariance calibrate writes: verdicts with probabilities, margins' intervals
fixture_cal
if [ -s "$tmp/cal.csv" ] || { bad "calibrate wrote no cal.csv"; false; }; then
    head -1 "$tmp/cal.csv" | grep -q ',cov_k1_k1,cov_k1_k2,' && ok || bad "calibrate csv covariance columns"
    "$bin" classify "$tmp/cal.csv" --samples 400 --ring-samples 20 >"$tmp/cu.txt" && grep -Eq 'string (UNSTABLE|stable) \(p [<>=] ' "$tmp/cu.txt" && ok || bad "classify with covariance: table verdict with p"
    "$bin" classify "$tmp/cal.csv" --samples 400 --ring-samples 20 --format json >"$tmp/cu.json" && python3 - "$tmp/cu.json" <<'PY' && ok || bad "classify with covariance: json keys"
import json, sys
d = json.load(open(sys.argv[1]))
v = d['result']['vehicles'][0]
assert 0.0 <= v['p_string_unstable'] <= 1.0
m = v['margin_intervals']
for k in ('c2', 'sup_gamma_minus_1', 'spectral_abscissa'):
    assert m[k][0] <= m[k][1], k
u = v['uncertainty']
assert u['samples'] == 400 and u['ring_samples'] == 20
lo, hi = u['string_unstable']['wilson']
assert lo <= v['p_string_unstable'] <= hi
assert d['inputs']['samples'] == 400 and d['inputs']['seed'] == 1
PY
    "$bin" classify "$tmp/cal.csv" --samples 400 --ring-samples 20 --format csv | head -1 | grep -q ',p_string_unstable,' && ok || bad "classify with covariance: csv column"
fi
expect_error "--samples = '0'" classify --samples 0

# help on every command, with units
for c in roots string sweep boundary; do
    if "$bin" $c --help >"$tmp/h.txt" && grep -q '1/s^2' "$tmp/h.txt" && grep -q -- '--tau' "$tmp/h.txt"; then ok; else bad "$c --help"; fi
done
"$bin" --help >/dev/null && ok || bad "--help"

fi  # part exits

if part files; then
# ---- files in and out (issue 15) ---------------------------------------------------------------
rootsargs="--k1 0.2 --k2 0.4 --th 1.5 --tau 0.3"
# a full stdout is a write error with the system's reason (exit 5), in every format
for fmt in table json csv; do
    "$bin" roots $rootsargs --format $fmt >/dev/full 2>"$fio/e.txt"
    rc=$?
    [ $rc -eq 5 ] && grep -q "cannot write standard output: No space left on device" "$fio/e.txt" && ok || bad "roots --format $fmt > /dev/full: exit $rc"
done
# devices are written into, never replaced; a write error carries the reason (one vehicle: a small figure)
printf 'name,k1,k2,th,tau\none,0.2,0.4,1.5,0.3\n' >"$fio/one.csv"
"$bin" classify "$fio/one.csv" --svg /dev/full >/dev/null 2>"$fio/e.txt"
rc=$?
[ $rc -eq 5 ] && [ -c /dev/full ] && grep -q "/dev/full: No space left on device" "$fio/e.txt" && ok || bad "classify --svg /dev/full: exit $rc, $(cat "$fio/e.txt")"
"$bin" classify "$fio/one.csv" --svg /dev/null >/dev/null && [ -c /dev/null ] && ok || bad "classify --svg /dev/null"
# outputs are written through links: the target is replaced, the link stays
mkdir -p "$fio/real"
echo old >"$fio/real/r.csv"
ln -s real/r.csv "$fio/r.csv"
"$bin" roots $rootsargs --out "$fio/r" >/dev/null && [ -L "$fio/r.csv" ] && head -1 "$fio/real/r.csv" | grep -q '^mode,' &&
    [ -z "$(ls -A "$fio/real" | grep -v '^r.csv$')" ] && ok || bad "write through a link"
# a regular file where a folder is needed, a folder where a file is needed: refused before any work
: >"$fio/plain"
expect_error "'$fio/plain' is a file, not a folder" sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$fio/plain/sub/x"
[ -f "$fio/plain" ] && ok || bad "the file in the way is left alone"
mkdir -p "$fio/d.svg"
expect_error "d.svg' is a folder, expected a file" chart maps/none.toml --out "$fio/d"
expect_error "is a folder, expected a file" classify --svg "$fio/d.svg"
# every command that writes files checks its folder before the work (paper takes many seconds)
mkdir -p "$fio/ro"
chmod 555 "$fio/ro"
if [ -w "$fio/ro" ]; then ro_dir="$fio/plain"; ro_msg="is a file, not a folder"; else ro_dir="$fio/ro"; ro_msg="is not writable"; fi  # root writes anywhere
for c in "roots $rootsargs" "string $rootsargs" "classify" "mix --x E_min --y A_min --ring 6 --p 0:1:2" "growth --followers 2" \
             "simulate --fleet A_min" "boundary --th 1.5 --tau 0.5 --k1 0.01:1 --k2 0.01:1" "paper" "sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:4"; do
    start=$(date +%s%N)
    expect_error "$ro_msg" $c --out "$ro_dir/x"
    { [ -n "${DDEMAP_SANITIZED:-}" ] || [ $(( ($(date +%s%N) - start) / 1000000 )) -lt 2000 ]; } && ok || bad "$c: the unusable folder was found only after the work"
done
chmod 755 "$fio/ro"
# an output set is all new or all old: a failed move puts every old file back, leaves no temporary file
mkdir -p "$fio/set"
echo old-csv >"$fio/set/r.csv"
echo old-json >"$fio/set/r.json"
DDEMAP_TEST_FAULT=move:2 expect_code 5 roots $rootsargs --out "$fio/set/r"
[ "$(cat "$fio/set/r.csv")" = old-csv ] && [ "$(cat "$fio/set/r.json")" = old-json ] && [ "$(ls -A "$fio/set" | wc -l)" -eq 2 ] && ok ||
    bad "a failed move left a half-replaced set: $(ls -A "$fio/set")"
# interrupted while the files are written (test hook: a pause there): the old set stays, nothing else
for fault in pause named,pause; do
    for sig in INT TERM KILL; do
        [ "$fault" = named,pause ] && [ $sig = KILL ] && continue  # named files cannot survive SIGKILL: see below
        DDEMAP_TEST_FAULT=$fault timeout -s $sig 1 "$bin" roots $rootsargs --out "$fio/set/r" >/dev/null 2>&1
        [ "$(cat "$fio/set/r.csv")" = old-csv ] && [ "$(ls -A "$fio/set" | wc -l)" -eq 2 ] && ok || bad "$fault $sig left: $(ls -A "$fio/set")"
    done
done
# named temporary files of a killed writer are removed by the next write into that folder
DDEMAP_TEST_FAULT=named,pause timeout -s KILL 1 "$bin" roots $rootsargs --out "$fio/set/r" >/dev/null 2>&1
ls -A "$fio/set" | grep -q '^\.r\.csv\.ddemap-.*\.tmp$' && ok || bad "the test hook named,pause did not leave the killed writer's file"
"$bin" roots $rootsargs --out "$fio/set/r" >/dev/null && [ "$(ls -A "$fio/set" | wc -l)" -eq 2 ] && head -1 "$fio/set/r.csv" | grep -q '^mode,' &&
    ok || bad "stale temporary files not removed: $(ls -A "$fio/set")"
# a folder never holds old and new files of one command: a sweep without boundaries removes the
# PREFIX-boundaries.csv of an earlier run with the set (and puts it back when the set fails)
"$bin" sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$fio/sw/x" >/dev/null && [ -f "$fio/sw/x-boundaries.csv" ] && ok || bad "sweep boundaries"
DDEMAP_TEST_FAULT=move:4 expect_code 5 sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:5 --out "$fio/sw/x" --no-boundaries
[ -f "$fio/sw/x-boundaries.csv" ] && [ "$(ls -A "$fio/sw" | wc -l)" -eq 4 ] && ! grep -q '^0,0.75,' "$fio/sw/x.csv" && ok || bad "a failed removal was not rolled back"
"$bin" sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:5 --out "$fio/sw/x" --no-boundaries >/dev/null && [ ! -e "$fio/sw/x-boundaries.csv" ] &&
    [ "$(ls -A "$fio/sw" | wc -l)" -eq 3 ] && ok || bad "an old PREFIX-boundaries.csv stayed beside a new chart: $(ls -A "$fio/sw")"
# inputs: a folder given as a file says so; a byte-order mark and CRLF line ends are accepted everywhere
expect_error "VEHICLES: '$fio' is a folder, expected a file" classify "$fio"
expect_error "is a folder, expected a file" roots --system "$fio"
expect_error "is a folder, expected a file" chart "$fio" --out "$fio/c"
expect_error "is a folder, expected a file" calibrate "$fio"
printf 'name,k1,k2,th,tau,eta\nmine,0.2,0.4,1.5,0.3,10\n' | crlf "$fio/v.csv"
"$bin" classify "$fio/v.csv" --format csv | grep -q '^mine,0.2' && ok || bad "classify: BOM + CRLF"
"$bin" simulate --fleet "$fio/v.csv" --out "$fio/sim" >/dev/null && ok || bad "simulate: BOM + CRLF"
printf 'vehicle,model,k1,k2,th,tau,count\nA_min,,,,,,2\n,ovrv,0.2,0.4,1.5,0.3,1\n' | crlf "$fio/f.csv"
"$bin" roots --fleet "$fio/f.csv" --count 2 >/dev/null && ok || bad "roots --fleet: BOM + CRLF"
printf '{"dimension": 1, "delays": [1.0], "A": [[[-1]]]}\n' | crlf "$fio/s.json"
"$bin" roots --system "$fio/s.json" --count 2 >/dev/null && ok || bad "roots --system: BOM + CRLF"
printf 'time_s,lead_speed_mps\n0,20\n10,20\n20,18\n40,20\n' | crlf "$fio/lead.csv"
"$bin" simulate --fleet A_min --lead "$fio/lead.csv" --out "$fio/sim2" >/dev/null && ok || bad "simulate --lead: BOM + CRLF"
# (the classification spec with a 5 x 5 grid: the parse is what is checked, not the figure)
sed 's/^count = 61/count = 5/' "$(dirname "$0")/../../maps/classification.toml" | crlf "$fio/spec.toml"
"$bin" chart "$fio/spec.toml" --out "$fio/spec" >/dev/null && ok || bad "chart: BOM + CRLF"
python3 - "$fio/t.csv" <<'PY'
import math, sys
rows = ["time_s,lead_speed_mps,follower_speed_mps,gap_m"]
for k in range(0, 601):
    t = k / 10
    v = 20 + math.sin(t / 5)
    rows.append(f"{t},{v},{v},{30 + 0.5 * math.cos(t / 5)}")
open(sys.argv[1], "wb").write(b"\xef\xbb\xbf" + "\r\n".join(rows).encode() + b"\r\n")
PY
"$bin" calibrate "$fio/t.csv" --out "$fio/fits" >/dev/null 2>&1; rc=$?
[ $rc -eq 0 ] || [ $rc -eq 4 ] && ok || bad "calibrate: BOM + CRLF (exit $rc)"
# one vehicle/fleet format family: what calibrate writes goes into classify, simulate, roots and mix
if [ -s "$fio/fits.csv" ]; then
    "$bin" classify "$fio/fits.csv" --format csv | grep -q '^t,' && ok || bad "classify takes calibrate's output"
    "$bin" simulate --fleet "$fio/fits.csv" --out "$fio/sim3" >/dev/null && ok || bad "simulate takes calibrate's output"
    "$bin" roots --fleet "$fio/fits.csv" --ring 8 --count 2 >/dev/null && ok || bad "roots --fleet takes calibrate's output"
    "$bin" mix --x "$fio/fits.csv" --y A_min --ring 6 --p 0:1:2 --out "$fio/mix" >/dev/null && ok || bad "mix --x takes calibrate's output"
    "$bin" mix --x "$fio/fits.csv:t" --y A_min --ring 6 --p 0:1:2 --out "$fio/mix" >/dev/null && ok || bad "mix --x FILE.csv:NAME"
    expect_error "no car named 'nope'" mix --x "$fio/fits.csv:nope" --y A_min --ring 6 --p 0:1:2 --out "$fio/mix"
else
    bad "calibrate wrote no fits.csv"
fi
# patterns and files the same way: a pattern in classify and roots --fleet, a fleet table in classify and simulate
"$bin" classify "A_min,E_max" --format csv | grep -c '^[AE]_' | grep -q '^2$' && ok || bad "classify PATTERN"
"$bin" roots --fleet "A_min,E_min" --ring 6 --format json | python3 -c "import json,sys; sys.exit(0 if json.load(sys.stdin)['result']['ring'] == 6 else 1)" && ok || bad "roots --fleet PATTERN --ring"
"$bin" classify "$fio/f.csv" --format csv | grep -c '^' | grep -q '^3$' && ok || bad "classify a fleet table (3 cars, 2 distinct: one row each)"
"$bin" simulate --fleet "$fio/f.csv" --out "$fio/sim4" >/dev/null && ok || bad "simulate a fleet table"
printf 'vehicle,model,k1,k2,th,tau,k3,tau2\n,ccc,0.1,0.3,1.2,0.4,0.2,0.1\n' >"$fio/ccc.csv"
expect_error "has model ccc" classify "$fio/ccc.csv"

fi  # part files

if part nonlinear; then
# ---- one consistent command line: help and errors -----------------------------------------------
for c in roots string classify sweep boundary chart paper simulate growth calibrate mix equilibria; do
    "$bin" $c --help >"$fio/h.txt" 2>&1
    grep -q ' TEXT' "$fio/h.txt" && bad "$c --help has an option without its kind: $(grep ' TEXT' "$fio/h.txt" | head -1)" || ok
done
"$bin" roots --help | grep -q -- '--count INTEGER=6' && ok || bad "help shows kinds and defaults"
"$bin" roots --help | grep -- '--th ' | grep -q 'required for ovrv, idm, ccc' && ok || bad "help: which model needs --th"
"$bin" roots --help | grep -- '--v0 ' | grep -q 'default: idm 33.3' && ok || bad "help: the IDM defaults"
"$bin" sweep --help | grep -q -- '--k1 NUMBER|LO:HI:COUNT' && ok || bad "sweep help: ranges"
"$bin" mix --help | grep -q -- '--x CAR' && "$bin" sweep --help | grep -q -- '--x NAME' && ok || bad "help: the kind of --x per command"
expect_error "unknown command 'rots': expected one of roots, string" rots --k1 0.2
expect_error "expected a command" 
python3 - "$bin" <<'PY' && ok || bad "the model list in errors is the model table"
import subprocess, sys
e = subprocess.run([sys.argv[1], "roots", "--model", "nope"], capture_output=True, text=True).stderr
h = subprocess.run([sys.argv[1], "roots", "--help"], capture_output=True, text=True).stdout
models = [l.split()[1].split("=")[0] for l in h.splitlines() if l.strip().startswith("--model ")][0].split("|")
assert set(models) >= {"ovrv", "idm", "ccc"}, models
assert all(m in e for m in models), (e, models)
PY

# ---- nonlinear systems with expressions: roots --system (linearised at the equilibrium) and equilibria
cat >"$tmp/nl.json" <<'EOF2'
{ "variables": ["x1", "x2"],
  "parameters": {"a": 0.5, "b": 0.6, "d": 0.05, "tau": 2.0},
  "equations": ["x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"],
  "equilibrium": [0.1, 0.0] }
EOF2
if "$bin" roots --system "$tmp/nl.json" --format json >"$tmp/nl_r.json"; then
    json_has "$tmp/nl_r.json" equilibrium linearisation && ok || bad "roots --system nonlinear json keys"
    # every root against the characteristic equation of the linearisation at 0, written by hand:
    # lambda^2 + d lambda + a + b - b exp(-lambda tau) = 0
    python3 - "$tmp/nl_r.json" <<'PY' && ok || bad "roots --system nonlinear: roots solve the hand-derived characteristic equation"
import json, sys, cmath
d = json.load(open(sys.argv[1]))["result"]
assert d["equilibrium"]["status"] == "converged" and max(abs(x) for x in d["equilibrium"]["x"]) < 1e-12
a, b, dd, tau = 0.5, 0.6, 0.05, 2.0
for r in d["linearisation"]["roots"]:
    l = complex(r["re"], r["im"])
    assert abs(l * l + dd * l + a + b - b * cmath.exp(-l * tau)) < 1e-10 * max(1, abs(l) ** 2), l
assert d["linearisation"]["stable"] is True
PY
else
    bad "roots --system nonlinear exit status"
fi
# no equilibrium from the guess (x' = x^2 + 1 has none): undecided, exit 4, the Newton result printed
echo '{"variables": ["x"], "equations": ["x^2 + 1"], "equilibrium": [0.5]}' >"$tmp/noeq.json"
"$bin" roots --system "$tmp/noeq.json" --format json >"$tmp/noeq.out" 2>"$tmp/noeq.err"
rc=$?
[ $rc -eq 4 ] && grep -q '"status"' "$tmp/noeq.out" && grep -q "undecided" "$tmp/noeq.err" && ok || bad "roots --system without equilibrium: exit $rc"
# expression errors: the file, the equation and the character
echo '{"variables": ["x"], "parameters": {"a": 1}, "equations": ["-a*x(t - x)"]}' >"$tmp/bad1.json"
expect_error "bad1.json: equation 1 (dx/dt), character 10: the delay depends on the state (x)" roots --system "$tmp/bad1.json"
echo '{"variables": ["x"], "parameters": {"a": 1}, "equations": ["-a*y"]}' >"$tmp/bad2.json"
expect_error "character 4: unknown name 'y'" equilibria --system "$tmp/bad2.json" --par a --from 0 --to 1
echo '{"variables": ["x"], "parameters": {"a": 1}, "equations": ["-a*(x + 1"]}' >"$tmp/bad3.json"
expect_error "character 10: the expression ends early: expected ')'" equilibria --system "$tmp/bad3.json" --par a --from 0 --to 1 --out "$tmp/eqbad"
[ ! -e "$tmp/eqbad.csv" ] && [ ! -e "$tmp/eqbad.json" ] && ok || bad "equilibria bad input wrote files"
expect_error "parameter 'q' is not a parameter of this system: expected one of p" equilibria --system "$tmp/fold.json" --par q --from 0 --to 1
expect_error "expected one of --system FILE or --model ov" equilibria --system "$tmp/fold.json" --model ov --par p --from 0 --to 1
expect_error "--model = 'ccc'" equilibria --model ccc --ring 5 --par v0 --from 0 --to 1
expect_error "--ring" equilibria --model ov --par headway --from 1.2 --to 3
# equilibria: a fold at p = 0 and a Hopf point at p = (pi/4)^2, omega = pi/2 (closed forms of x' = p - x(t-1)^2)
if "$bin" equilibria --system "$tmp/fold.json" --par p --from 0.9 --to -1 --format json --out "$tmp/eqf" >"$tmp/eqf.out"; then
    json_has "$tmp/eqf.out" parameter points folds hopf && ok || bad "equilibria json keys"
    python3 - "$tmp/eqf.out" "$tmp/eqf.csv" <<'PY' && ok || bad "equilibria fold and Hopf against the closed forms"
import json, sys, math, csv
d = json.load(open(sys.argv[1]))["result"]
assert d["parameter"] == "p"
assert len(d["folds"]) == 1 and abs(d["folds"][0]["par"]) < 1e-8 and d["folds"][0]["status"] == "converged"
assert len(d["hopf"]) == 1 and abs(d["hopf"][0]["par"] - math.pi ** 2 / 16) < 1e-8 and abs(d["hopf"][0]["omega"] - math.pi / 2) < 1e-8
for p in d["points"]:
    assert abs(p["par"] - p["x"][0] ** 2) < 1e-10  # on the curve p = x^2
rows = list(csv.DictReader(open(sys.argv[2])))
assert [r["kind"] for r in rows].count("hopf") == 1 and [r["kind"] for r in rows].count("fold") == 1
assert float([r for r in rows if r["kind"] == "hopf"][0]["p"]) == d["hopf"][0]["par"]  # round trip exact
PY
else
    bad "equilibria --system exit status"
fi
# the ov ring (5 cars, one headway eliminated): six Hopf points (modes 1, 2, 3 on both sides of the inflection of V)
if "$bin" equilibria --model ov --ring 5 --par headway --from 1.2 --to 3 --format csv >"$tmp/ov.csv"; then
    [ "$(grep -c '^hopf,' "$tmp/ov.csv")" -eq 6 ] && ! grep -qi 'nan\|inf' "$tmp/ov.csv" && ok || bad "equilibria ov ring: 6 Hopf points"
    # the ring's units in the header: headway and headways in m, speeds in m/s, rates in 1/s and rad/s
    head -1 "$tmp/ov.csv" | grep -q '^kind,headway_m,h0_m,h1_m,h2_m,h3_m,v0_mps,v1_mps,v2_mps,v3_mps,v4_mps,abscissa_per_s,unstable,stable,omega_rad_per_s,status$' &&
        ok || bad "equilibria CSV header with units: $(head -1 "$tmp/ov.csv")"
else
    bad "equilibria --model ov exit status"
fi
"$bin" equilibria --system "$tmp/fold.json" --par p --from 0.9 --to -1 | grep -q "^hopf       p = 0.6168502" && ok || bad "equilibria table"
# fold curves in two parameters (equilibria --par2): x' = p1 + x^2 + p2 x(t - 2) has the fold curve
# p1 = p2^2 / 4 and a Bogdanov-Takens point at p2 = -1/tau = -0.5, p1 = 1/16 (Delta'(0) = 1 + tau p2 = 0);
# x' = p1 + p2 x(t - 1) - x^3 the curve (-2 x^3, 3 x^2) with its cusp at the origin
echo '{"variables": ["x"], "parameters": {"p1": -0.5, "p2": 0.5, "tau": 2}, "equations": ["p1 + x^2 + p2*x(t - tau)"], "equilibrium": [-1]}' >"$tmp/bt.json"
echo '{"variables": ["x"], "parameters": {"p1": -1, "p2": 1}, "equations": ["p1 + p2*x(t - 1) - x^3"], "equilibrium": [-1.3]}' >"$tmp/cusp.json"
"$bin" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --par2 p2 --from2 -1.5 --to2 1.5 --format json --out "$tmp/btc" >"$tmp/bt.out" &&
    "$bin" equilibria --system "$tmp/cusp.json" --par p1 --from -1.5 --to 1.5 --par2 p2 --from2 -0.5 --to2 2 --format json >"$tmp/cusp.out" &&
    python3 - "$tmp/bt.out" "$tmp/cusp.out" "$tmp/btc.csv" <<'PY' && ok || bad "equilibria --par2: fold curves, the Bogdanov-Takens point and the cusp against closed forms"
import csv, json, sys
bt = json.load(open(sys.argv[1])); cu = json.load(open(sys.argv[2]))
assert bt["status"] == "converged" and cu["status"] == "converged", (bt["message"], cu["message"])
assert bt["inputs"]["par2"] == "p2" and bt["result"]["parameter2"] == "p2"
c = bt["result"]["curves"]
assert len(c) == 1 and c[0]["stop"] == ["bound", "bound"], c[0]["stop"]
assert all(abs(p["par"] - p["par2"] ** 2 / 4) < 1e-8 for p in c[0]["points"])
s = c[0]["special"]
assert [x["kind"] for x in s] == ["bogdanov_takens"] and s[0]["status"] == "converged"
assert abs(s[0]["par"] - 1 / 16) < 1e-8 and abs(s[0]["par2"] + 0.5) < 1e-8 and abs(s[0]["x"][0] - 0.25) < 1e-8
k = cu["result"]["curves"]
assert len(k) == 1 and [x["kind"] for x in k[0]["special"]] == ["cusp"]
assert abs(k[0]["special"][0]["par"]) < 1e-8 and abs(k[0]["special"][0]["par2"]) < 1e-8
rows = list(csv.DictReader(open(sys.argv[3])))
assert [r["kind"] for r in rows].count("point") == len(c[0]["points"]) and [r for r in rows if r["kind"] == "bogdanov_takens"]
assert float([r for r in rows if r["kind"] == "bogdanov_takens"][0]["p2"]) == s[0]["par2"]  # round trip exact
# the normal forms against their closed forms: BT a = 2/tau = 1, b = 4/3; cusp c = -1
assert abs(s[0]["normal_form"]["a"] - 1) < 1e-7 and abs(s[0]["normal_form"]["b"] - 4 / 3) < 1e-7, s[0]["normal_form"]
assert abs(k[0]["special"][0]["normal_form"]["c"] + 1) < 1e-7, k[0]["special"][0]["normal_form"]
r = [r for r in rows if r["kind"] == "bogdanov_takens"][0]
assert float(r["nf_a"]) == s[0]["normal_form"]["a"] and float(r["nf_b"]) == s[0]["normal_form"]["b"] and r["nf_c"] == ""
PY
"$bin" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --par2 p2 --from2 -1.5 --to2 1.5 | grep -q "Bogdanov-Takens (a double root at 0; a Hopf curve ends here): p1 = 0.0625, p2 = -0.5 (converged, residual 0); normal form a = 1, b = 1.3333333$" &&
    ok || bad "equilibria --par2 table"
# the two-parameter diagrams: the fold curve with its BT point; the Hopf curves of the 3-car ov ring with its GH points
"$bin" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --par2 p2 --from2 -1.5 --to2 1.5 --svg "$tmp/two/bt.svg" >/dev/null &&
    xmllint --noout "$tmp/two/bt.svg" && grep -q ">BT<" "$tmp/two/bt.svg" && grep -q "fold of equilibria" "$tmp/two/bt.svg" &&
    ok || bad "equilibria --par2 --svg"
"$bin" hopf --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --from2 0.3 --to2 2 --svg "$tmp/two/hopf.svg" --quiet >/dev/null &&
    xmllint --noout "$tmp/two/hopf.svg" && [ "$(grep -c '>GH<' "$tmp/two/hopf.svg")" -eq 2 ] && grep -q "Hopf, subcritical" "$tmp/two/hopf.svg" &&
    grep -q "τ \[s\]" "$tmp/two/hopf.svg" && ok || bad "hopf --par2 --svg"
expect_error "draws the curves of --par2" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --svg "$tmp/two/x.svg"
expect_error "draws the curves of --par2" hopf --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --svg "$tmp/two/x.svg"
[ ! -e "$tmp/two/x.svg" ] && ok || bad "a refused --svg wrote its file"
expect_error "--par2 needs --from2 and --to2" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --par2 p2
expect_error "expected it in [--from2, --to2]" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --par2 p2 --from2 1 --to2 2
expect_error "--from2/--to2 without --par2" equilibria --system "$tmp/bt.json" --par p1 --from -0.5 --to 2 --from2 1

# a published model as a system file: DDE-BIFTOOL's neuron demo (demo1_hopf: Hopf at a21 = 0.80712, omega = 0.78197)
cat >"$tmp/neuron.json" <<'EOF2'
{ "variables": ["x1", "x2"],
  "parameters": {"kappa": 0.5, "beta": -1, "a12": 1, "a21": 0.5, "tau1": 0.2, "tau2": 0.2, "taus": 1.5},
  "equations": ["-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"] }
EOF2
"$bin" equilibria --system "$tmp/neuron.json" --par a21 --from 0.3 --to 2 --format json |
    python3 -c "import json,sys; h=json.load(sys.stdin)['result']['hopf']; assert len(h) == 1 and abs(h[0]['par']/0.80712-1) < 5e-5 and abs(h[0]['omega']/0.78197-1) < 5e-5, h" &&
    ok || bad "equilibria: DDE-BIFTOOL neuron Hopf point"

# a flat line (speeds constant to rounding) is drawn, not a hang with ever finer ticks
timeout 30 "$bin" simulate --fleet A_min --t-end 20 --out "$tmp/flat" >/dev/null && [ "$(grep -c '<text' "$tmp/flat.svg")" -lt 200 ] &&
    ok || bad "simulate --t-end 20: a flat speed plot finishes with a bounded number of ticks"

# Bounded and visible (README "Limits and progress"): sizes refused before any work, no NaN or inf
expect_error "estimated" sweep --th 1.5 --tau 0.5 --k1 0:1:5000 --k2 0:1:5000 --out "$tmp/big"
expect_error "memory" sweep --th 1.5 --tau 0.5 --k1 0:1:100000 --k2 0:1:100000 --out "$tmp/big"   # was std::bad_alloc, exit 3
[ ! -e "$tmp/big.csv" ] && ok || bad "a refused sweep wrote a file"
expect_error "1e+09 s" simulate --fleet A_min --t-end 1e9 --out "$tmp/simbig"                      # was exit 3 (vector max_size)
expect_error "more than this machine has" simulate --fleet A_min --t-end 1e9 --allow-large --out "$tmp/simbig"
python3 -c "print('time_s,lead_speed_mps'); print('0,20'); print('100000,20')" >"$tmp/longlead.csv"
expect_error "estimated output files" simulate --fleet A_min --lead "$tmp/longlead.csv" --out "$tmp/simlong"   # was 340 MB written
# (a complex value: held dense, so refused; real triplets are held sparse and run)
printf '{"dimension": 20000, "delays": [1], "A0": {"triplets": []}, "A": [{"triplets": [[0, 0, [-1, 0.5]]]}]}\n' >"$tmp/dim20000.json"
expect_error "20000-state system" roots --system "$tmp/dim20000.json"
printf '{"dimension": 2, "delays": [1], "A0": [[1e300, 1e-300], [1e-300, -1e300]], "A": [[[1e-300, 1e300], [0, 1]]]}\n' >"$tmp/range.json"
expect_error "1e-100 to 1e100" roots --system "$tmp/range.json"                # was a Schur decomposition failure
printf 'title = "t"\nring = 22\nfixed = { th = 1.5, tau = 0.5 }\npanel_width = 1e308\nx = { name = "k1", lo = 0.01, hi = 1, count = 5 }\ny = { name = "k2", lo = 0.01, hi = 1, count = 5 }\n' >"$tmp/wide.toml"
expect_error "panel_width" chart "$tmp/wide.toml" --out "$tmp/wide"
sed 's/panel_width = 1e308/panel_width = -300/' "$tmp/wide.toml" >"$tmp/neg.toml"
expect_error "panel_width" chart "$tmp/neg.toml" --out "$tmp/neg"
# a constant lead (a flat speed plot): the figure's tick loop once never ended
python3 -c "print('time_s,lead_speed_mps'); print('0,20'); print('50,20')" >"$tmp/flatlead.csv"
timeout 60 "$bin" simulate --fleet A_min --lead "$tmp/flatlead.csv" --out "$tmp/flat" >/dev/null 2>&1 && xmllint --noout "$tmp/flat.svg" && ok || bad "simulate behind a constant lead"
# calibrate --train past the end of the file: bad input (once an abort inside a parallel loop)
python3 -c "
import math
print('time_s,lead_speed_mps,follower_speed_mps,gap_m')
for i in range(2251):
    t = i * 0.1
    print(f'{t:.1f},{20 + math.sin(t / 10):.4f},{20 + 0.9 * math.sin(t / 10 - 0.5):.4f},{30 + math.cos(t / 10):.4f}')
" >"$tmp/t225.csv"
expect_error "training window 200:300" calibrate "$tmp/t225.csv" "$tmp/t225.csv" --train 200:300
# a diverging simulation: UNDECIDED with the time, exit 4, no NaN or inf anywhere
printf 'name,k1,k2,th,tau\nX,1000,1000,1.5,0.5\n' >"$tmp/wildcar.csv"
"$bin" simulate --fleet "$tmp/wildcar.csv" --out "$tmp/wild" --format json >"$tmp/o.txt" 2>"$tmp/e.txt"
rc=$?
[ $rc -eq 4 ] && ok || bad "diverging simulate: exit $rc (expected 4)"
grep -q "UNDECIDED: the solution diverged at t = " "$tmp/e.txt" && ok || bad "diverging simulate: stderr: $(cat "$tmp/e.txt")"
if grep -qi -E 'nan|inf' "$tmp/o.txt" "$tmp/wild.csv" "$tmp/wild.svg"; then bad "NaN/inf in a diverged simulation's output"; else ok; fi
python3 -c "
import json, sys
d = json.load(open('$tmp/o.txt'))
assert d['status'] == 'numerical_issue', d['status']
assert d['result']['diverged_at'] > d['result']['t_end'] > 0
" && ok || bad "diverging simulate: json status"
# progress: one line per finished unit on a non-terminal stderr, nothing with --quiet, stdout untouched
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:6 --k2 0.01:1:7 --no-boundaries --out "$tmp/pr" >"$tmp/o.txt" 2>"$tmp/e.txt"
[ "$(grep -c -E '^ddemap: sweep: rows [0-9]+/7 \(' "$tmp/e.txt")" -eq 7 ] && ok || bad "progress lines: $(cat "$tmp/e.txt")"
grep -q "ddemap:" "$tmp/o.txt" && bad "progress on stdout" || ok
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:6 --k2 0.01:1:7 --no-boundaries --quiet --out "$tmp/pr" >/dev/null 2>"$tmp/e.txt"
[ ! -s "$tmp/e.txt" ] && ok || bad "--quiet still printed: $(cat "$tmp/e.txt")"

# calibrate's CSV carries the bounds the fit used; classify samples within them (not calibrate's defaults)
fixture_cal
if "$bin" calibrate "$excerpt" --bounds k1=0:2,tau=0.1:0.9 --out "$tmp/calb" >/dev/null 2>&1 || [ $? -eq 4 ]; then
    head -1 "$tmp/calb.csv" | grep -q ',cov_eta_eta,lo_k1_per_s2,hi_k1_per_s2,lo_k2_per_s,hi_k2_per_s,lo_th_s,hi_th_s,lo_tau_s,hi_tau_s,lo_eta_m,hi_eta_m$' && ok || bad "calibrate csv bounds columns"
    sed -n 2p "$tmp/calb.csv" | grep -q ',0,2,0,1,0,3,0.1,0.9,5,15$' && ok || bad "calibrate csv bounds values"
    if grep -q ',cov_k1_k1' "$tmp/calb.csv" && [ -n "$(sed -n 2p "$tmp/calb.csv" | cut -d, -f15)" ]; then
        "$bin" classify "$tmp/calb.csv" --samples 50 --ring-samples 0 --format json 2>/dev/null | python3 -c "
import json, sys
u = json.load(sys.stdin)['result']['vehicles'][0]['uncertainty']
assert u['bounds_source'] == 'file', u
assert u['bounds']['k1'] == [0, 2] and u['bounds']['tau'] == [0.1, 0.9] and u['bounds']['th'] == [0, 3], u['bounds']
" && ok || bad "classify samples within the file's bounds"
    fi
    "$bin" classify "$tmp/cal.csv" --samples 50 --ring-samples 0 --format json 2>/dev/null |
        python3 -c "import json,sys; u=json.load(sys.stdin)['result']['vehicles'][0]['uncertainty']; assert u['bounds_source'] == 'file' and u['bounds']['k1'] == [0, 1], u" &&
        ok || bad "classify: default-bounds fit carries its bounds"
else
    bad "calibrate --bounds exit status"
fi

# the computable range (c <= 1e8, c tau <= 10) on every path, refused before any work and no file written
crd="$tmp/range"; mkdir -p "$crd"
printf 'name,k1,k2,th,tau\nok,0.2,0.2,1.5,0.2\nbig,1e6,0.2,1.5,0.2\n' >"$crd/big.csv"
printf 'vehicle,model,k1,k2,th,tau\n,ovrv,0.2,0.2,1.5,0.2\n,ovrv,0.2,0.2,1.5,1e6\n' >"$crd/fleet.csv"
printf 'title = "t"\nmodel = "ovrv"\nring = 22\n[x]\nname = "k1"\nlo = 0.1\nhi = 1e6\ncount = 5\n[y]\nname = "k2"\nlo = 0.1\nhi = 0.3\ncount = 5\n[fixed]\nth = 1.5\ntau = 0.2\n' >"$crd/big.toml"
expect_error "vehicle 'big': gains and delay outside the computable range" classify "$crd/big.csv"
expect_error "car 2 (big): gains and delay outside the computable range" roots --fleet "$crd/big.csv" --ring 4
expect_error "computable range" roots --fleet "$crd/fleet.csv" --ring 4
expect_error "car 1 (big): gains and delay outside the computable range" mix --x "$crd/big.csv:big" --y A_min --ring 6 --p 0:1:2 --out "$crd/mix"
expect_error "the corner k1 = 1000000, k2 = 0.1 of the window: gains and delay outside the computable range" sweep --k1 0.1:1e6:3 --k2 0.1:0.3:2 --th 1.5 --tau 0.2 --out "$crd/sweep"
expect_error "computable range" sweep --k1 0.1:0.3:3 --k2 0.1:0.3:2 --th 1.5 --tau 1e6 --out "$crd/sweep"
# IDM's coefficient sum peaks inside the delta range (corners 9.7 and 9.98, delta = 5.125 gives 10.12):
# every point is checked, not only the corners
expect_error "the point a = 100000, delta = 5.125 of the window: gains and delay outside the computable range" sweep --model idm --a 1e5:1.00001e5:2 --delta 3:20:9 --th 1.5 --tau 5.3e-4 --speed 16.65 --out "$crd/sweep" --no-boundaries
expect_error "the corner k1 = 1000000, k2 = 0.1 of the window: gains and delay outside the computable range" boundary --k1 0.1:1e6 --k2 0.1:0.3 --th 1.5 --tau 0.2 --out "$crd/boundary"
expect_error "panel 1: the corner k1 = 1000000, k2 = 0.1 of the window: gains and delay outside the computable range" chart "$crd/big.toml" --out "$crd/chart"
# a vehicle just inside the range: its figure's window is pulled back inside, not refused
printf 'name,k1,k2,th,tau\nedge,19.5,0.2,1.5,0.2\n' >"$crd/edge.csv"
"$bin" classify "$crd/edge.csv" --out "$crd/edge/c" >/dev/null 2>&1 && xmllint --noout "$crd/edge/c.svg" && ok || bad "classify --out of a vehicle near the edge of the computable range"
rm -rf "$crd/edge" "$crd/edge.csv"
[ -z "$(ls "$crd" | grep -v '^big\.\(csv\|toml\)$\|^fleet\.csv$')" ] && ok || bad "computable range: files written: $(ls "$crd")"

# the 3-car optimal-velocity ring with default settings: the branch from the first Hopf point ends
# at the second, with exactly the two folds of orbits, exit 0 (it looped 2.5 times, listed 17
# "folds", 3 of them at Hopf points, and exited 4), and two separate bistable windows
"$bin" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --svg "$tmp/ov3.svg" --quiet >"$tmp/ov3.out" 2>"$tmp/ov3.err"
rc=$?
[ $rc -eq 0 ] && [ "$(grep -c '^fold ' "$tmp/ov3.out")" -eq 2 ] && grep -q "(ended: hopf)" "$tmp/ov3.out" && ok || bad "ov ring 3 orbits: exit $rc, $(grep -c '^fold ' "$tmp/ov3.out") folds"
grep -Eq "bistable \(stable orbit and stable equilibrium\) for headway in \[[0-9.]+, [0-9.]+\] and \[[0-9.]+, [0-9.]+\];" "$tmp/ov3.svg" && ok || bad "ov ring 3: two bistable windows"
# switching at a branch point of equilibria (examples/hutchinson.json, x' = x (p - x(t - 1))):
# from x = 0 onto x = p at p = 0, and on it the Hopf point p = pi/2 with omega = pi/2
if "$bin" equilibria --system "$(dirname "$0")/../../examples/hutchinson.json" --par p --from -1 --to 2 --branch-point 0 --format json \
       --out "$tmp/hut" --quiet >"$tmp/hut.json"; then
    python3 - "$tmp/hut.json" "$tmp/hut-switched.csv" <<'PY' && ok || bad "equilibria --branch-point: the other branch of Hutchinson's equation"
import json, sys, math, csv
d = json.load(open(sys.argv[1]))
assert d["status"] == "converged" and d["inputs"]["branch_point"] == 0
r = d["result"]
sw = r["switched"]
assert sw["from"]["index"] == 0 and abs(sw["from"]["par"]) < 1e-10
pts = sw["points"]
assert all(abs(p["x"][0] - p["par"]) < 1e-12 for p in pts) and pts[-1]["par"] == 2
assert pts[0]["par"] == -1  # both halves: the one towards --from first, from its far end
h = sw["hopf"]
assert len(h) == 1 and abs(h[0]["par"] - math.pi / 2) < 1e-9 and abs(h[0]["omega"] - math.pi / 2) < 1e-9
rows = list(csv.DictReader(open(sys.argv[2])))
assert len([x for x in rows if x["kind"] == "point"]) == len(pts), rows[0]
PY
else
    bad "equilibria --branch-point exit status"
fi
# a pitchfork: both halves x = +-sqrt(p) of x' = x (p - x(t - 1)^2), each with its Hopf point p = pi/4
echo '{"variables":["x"],"parameters":{"p":-1},"equations":["x*(p - x(t - 1)^2)"]}' >"$tmp/pitchfork.json"
"$bin" equilibria --system "$tmp/pitchfork.json" --par p --from -1 --to 1 --branch-point 0 --format json --quiet >"$tmp/pf.json" &&
    python3 - "$tmp/pf.json" <<'PY' && ok || bad "equilibria --branch-point at a pitchfork: both halves"
import json, sys, math
sw = json.load(open(sys.argv[1]))["result"]["switched"]
pts = sw["points"]
assert pts[0]["par"] == 1 and pts[-1]["par"] == 1
assert all(abs(p["x"][0] ** 2 - p["par"]) < 1e-10 for p in pts)
assert any(p["x"][0] > 0.5 for p in pts) and any(p["x"][0] < -0.5 for p in pts)
h = sw["hopf"]
assert len(h) == 2 and all(abs(x["par"] - math.pi / 4) < 1e-9 and abs(x["omega"] - math.pi / 2) < 1e-9 for x in h)
assert h[0]["x"][0] * h[1]["x"][0] < 0
PY
# (checked once the branch is computed: --quiet keeps a slow build's progress lines out)
expect_error "--branch-point = '1': expected an index from 0 to 0 (the branch has 1 branch point)" \
    equilibria --system "$(dirname "$0")/../../examples/hutchinson.json" --par p --from -1 --to 2 --branch-point 1 --out "$tmp/hutbad" --quiet
expect_error "--branch-point = '0': the branch has no branch point in p from 0.5 to 2" \
    equilibria --system "$(dirname "$0")/../../examples/hutchinson.json" --par p --from 0.5 --to 2 --branch-point 0 --quiet
expect_error "--branch-point: not with --par2" \
    equilibria --system "$(dirname "$0")/../../examples/hutchinson.json" --par p --from -1 --to 2 --branch-point 0 --par2 p --from2 0 --to2 1
[ ! -e "$tmp/hutbad.json" ] && ok || bad "equilibria --branch-point bad input wrote files"

fi  # part nonlinear

if part hopf; then
# ---- hopf: Hopf points with their criticality, and Hopf curves in two parameters ----------------
"$bin" hopf --help >"$tmp/hh.txt" 2>&1
grep -q ' TEXT' "$tmp/hh.txt" && bad "hopf --help has an option without its kind: $(grep ' TEXT' "$tmp/hh.txt" | head -1)" || ok
# Wright's equation y' = -alpha y(t - 1) (1 + y): Hopf at alpha = omega = pi/2, supercritical,
# L1 = -2 (3 pi - 2) / (5 (4 + pi^2)), max - min ~ 4 sqrt(10 (alpha - pi/2) / (3 pi - 2)) (Chow and Mallet-Paret)
if "$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --format json --out "$tmp/hw" >"$tmp/hw.out"; then
    json_has "$tmp/hw.out" parameter hopf && ok || bad "hopf json keys"
    python3 - "$tmp/hw.out" "$tmp/hw.csv" <<'PY' && ok || bad "hopf: Wright's equation against the closed forms"
import json, sys, math, csv
e = json.load(open(sys.argv[1]))
assert e["command"] == "hopf" and e["status"] == "converged"
d = e["result"]
assert d["parameter"] == "alpha" and len(d["hopf"]) == 1
h = d["hopf"][0]
pi = math.pi
assert abs(h["par"] - pi / 2) < 1e-8 and abs(h["omega"] - pi / 2) < 1e-8
assert abs(h["l1"] + 2 * (3 * pi - 2) / (5 * (4 + pi * pi))) < 1e-9 and h["criticality"] == "supercritical"
assert abs(h["dre_dpar"] - 2 * pi / (4 + pi * pi)) < 1e-9 and h["side"] == "above"
assert abs(h["amplitude_coefficient"][0] - 4 * math.sqrt(10 / (3 * pi - 2))) < 1e-9
assert abs(h["equilibrium"][0]) < 1e-12 and h["residual"] < 1e-9
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == 1 and float(rows[0]["l1"]) == h["l1"] and rows[0]["criticality"] == "supercritical"  # round trip exact
PY
else
    bad "hopf --system exit status"
fi
"$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 | grep -q "supercritical" && ok || bad "hopf table"
# the Hopf curve in (alpha, b): the line alpha = pi/2 (the linearisation does not see b); L1 ~ b^2 < 0, b = 0 degenerate
if "$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b --from2 0.5 --to2 2 --format json >"$tmp/hc.out"; then
    python3 - "$tmp/hc.out" <<'PY' && ok || bad "hopf --par2: the curve alpha = pi/2"
import json, sys, math
d = json.load(open(sys.argv[1]))["result"]
assert d["parameter2"] == "b" and len(d["curves"]) == 1
pts = d["curves"][0]["points"]
assert len(pts) > 5 and all(abs(p["par"] - math.pi / 2) < 1e-8 and p["criticality"] == "supercritical" for p in pts)
assert abs(min(p["par2"] for p in pts) - 0.5) < 1e-12 and abs(max(p["par2"] for p in pts) - 2) < 1e-12
PY
else
    bad "hopf --par2 exit status"
fi
"$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b --from2 0.5 --to2 2 --format csv | head -1 |
    grep -q '^curve,kind,alpha,b,omega_rad_per_s,l1,criticality,status$' && ok || bad "hopf --par2 csv header"
expect_error "parameter 'q' is not a parameter of this system" hopf --system "$tmp/wright.json" --par q --from 1 --to 2
expect_error "expected --from < --to" hopf --system "$tmp/wright.json" --par alpha --from 2 --to 1
expect_error "expected a value other than --from" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 1
expect_error "parameter 'c' is not a parameter of this system" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 c --from2 0 --to2 1
expect_error "expected a parameter other than --par" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 alpha --from2 0 --to2 1
expect_error "--par2 needs --from2 and --to2" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b
expect_error "expected --from2 < --to2" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b --from2 2 --to2 0.5
expect_error "expected it in \[--from2, --to2\]" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b --from2 2 --to2 3 --out "$tmp/hbad"
[ ! -e "$tmp/hbad.csv" ] && [ ! -e "$tmp/hbad.json" ] && ok || bad "hopf bad input wrote files"
expect_error "--from2/--to2 without --par2" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --from2 0
# the ov ring (3 cars): two Hopf points of the ring mode, both subcritical (Orosz and Stepan 2006)
"$bin" hopf --model ov --ring 3 --par headway --from 1.2 --to 3 --format csv >"$tmp/hov.csv" &&
    [ "$(grep -c ',subcritical,' "$tmp/hov.csv")" -eq 2 ] && ! grep -qi 'nan\|inf' "$tmp/hov.csv" && ok || bad "hopf ov ring: two subcritical Hopf points"
# a branch cut short by --max-points: undecided, exit 4, the output still printed as JSON
"$bin" hopf --model ov --ring 3 --par headway --from 1.2 --to 3 --max-points 3 --format json >"$tmp/hund.out" 2>"$tmp/hund.err"
rc=$?
[ $rc -eq 4 ] && grep -q "undecided" "$tmp/hund.err" && python3 -c "import json,sys; json.load(open(sys.argv[1]))" "$tmp/hund.out" && ok || bad "hopf undecided: exit $rc"

# DDE-BIFTOOL's minimal demo (published L1 = 0.12631, 0.13109, -0.48039 at its three Hopf points in tau)
"$bin" hopf --system "$(dirname "$0")/../../examples/duffing.json" --par tau --from 0 --to 10 --format json |
    python3 -c "
import json, sys
h = json.load(sys.stdin)['result']['hopf']
assert [abs(x['l1'] / p - 1) < 5e-5 for x, p in zip(h, (0.12631, 0.13109, -0.48039))] == [True] * 3 and len(h) == 3, h
assert [x['criticality'] for x in h] == ['subcritical', 'subcritical', 'supercritical'], h
" && ok || bad "hopf: DDE-BIFTOOL minimal demo L1 values"

# its generalised Hopf point in (tau, b) carries L2 (c1 real part 0 there) in JSON and the table
"$bin" hopf --system "$(dirname "$0")/../../examples/duffing.json" --par tau --from 0 --to 20 --par2 b --from2 0 --to2 0.6 --quiet --out "$tmp/dgh" >"$tmp/dgh.txt" &&
    grep -q "generalised Hopf (L1 = 0): tau = 14.8348.*L2 = " "$tmp/dgh.txt" && python3 - "$tmp/dgh.json" <<'PY' && ok || bad "hopf --par2: L2 at the generalised Hopf point"
import json, sys
g = [g for c in json.load(open(sys.argv[1]))['result']['curves'] for g in c['generalised_hopf'] if abs(g['par'] - 14.83483) < 1e-4]
assert len(g) == 1, g
nf = g[0]['normal_form']
assert g[0]['l2'] == nf['l2'] and abs(nf['c1']['re']) < 1e-9 * abs(nf['c1']['im']) + 1e-12, nf
assert nf['l2'] * g[0]['omega'] == nf['c2']['re'] or abs(nf['l2'] * g[0]['omega'] / nf['c2']['re'] - 1) < 1e-15, nf
PY

# the IDM ring (--model idm): the branch in the mean gap; its Hopf point is where the linear ring analysis
# (roots --model idm --ring 5 at the uniform-flow speed of that gap) puts a root on the axis
# (idm_ring_axis.py: that check for a Hopf point (gap, tau, omega), shared with the curve below)
cat >"$tmp/idm_ring_axis.py" <<'PY'
import json, math, subprocess

def check(bin_, gap, tau, omega):
    # the uniform-flow speed of this gap: s*(v) = (eta + th v) / sqrt(1 - (v/v0)^4) = gap, by bisection
    lo, hi = 0.0, 32.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if (2 + 1.2 * mid) / math.sqrt(1 - (mid / 32) ** 4) < gap else (lo, mid)
    r = json.loads(subprocess.run([bin_, 'roots', '--model', 'idm', '--ring', '5', '--th', '1.2', '--tau', repr(tau), '--a', '1.1', '--b', '1.6',
                                   '--v0', '32', '--speed', repr(lo), '--format', 'json'], capture_output=True, text=True, check=True).stdout)['result']
    assert abs(r['spectral_abscissa']) < 1e-8, r['spectral_abscissa']
    assert any(abs(abs(x['im']) - omega) < 1e-8 for x in r['roots'] if abs(x['re']) < 1e-8), r['roots']
PY
"$bin" hopf --model idm --ring 5 --th 1.2 --tau 0.6 --a 1.1 --b 1.6 --v0 32 --par gap --from 6 --to 40 --format json >"$tmp/hidm.json" &&
    PYTHONPATH="$tmp" python3 - "$tmp/hidm.json" "$bin" <<'PY' && ok || bad "hopf --model idm: the Hopf point against the linear ring analysis"
import json, sys, idm_ring_axis
h = json.load(open(sys.argv[1]))['result']['hopf']
assert len(h) == 1 and h[0]['status'] == 'converged', h
idm_ring_axis.check(sys.argv[2], h[0]['par'], 0.6, h[0]['omega'])
PY
# its Hopf curve in (gap, tau) across the box, in a few dozen points (the equilibrium's speeds
# and gaps of 20-30 are scaled in the step: unscaled, 543 points reached a fifth of the box), and
# its end on the face tau = 1 against the linear ring analysis there
"$bin" hopf --model idm --ring 5 --th 1.2 --tau 0.6 --a 1.1 --b 1.6 --v0 32 --par gap --from 6 --to 40 --par2 tau --from2 0.3 --to2 1 --format json \
    --quiet >"$tmp/hidm2.json" && PYTHONPATH="$tmp" python3 - "$tmp/hidm2.json" "$bin" <<'PY' && ok || bad "hopf --model idm --par2: the Hopf curve across the box, its end against the linear ring analysis"
import json, sys, idm_ring_axis
d = json.load(open(sys.argv[1]))
c = d['result']['curves']
assert d['status'] == 'converged' and len(c) == 1 and c[0]['stop'] == ['bound', 'bound'] and len(c[0]['points']) < 150, (d['status'], c[0]['stop'], len(c[0]['points']))
end = max(c[0]['points'], key=lambda p: p['par2'])
assert end['par2'] == 1, end
idm_ring_axis.check(sys.argv[2], end['par'], 1.0, end['omega'])
PY
expect_error "--model idm needs --tau" equilibria --model idm --ring 5 --th 1.2 --par gap --from 6 --to 40
expect_error "--alpha is not a parameter of --model idm" equilibria --model idm --ring 5 --th 1.2 --tau 0.6 --alpha 2 --par gap --from 6 --to 40
expect_error "gap = 1: expected a finite mean gap > eta" equilibria --model idm --ring 5 --th 1.2 --tau 0.6 --par gap --from 1 --to 40
expect_error "--h-st is not a parameter of --model idm" hopf --model idm --ring 5 --th 1.2 --tau 0.6 --h-st 2 --par gap --from 6 --to 40
expect_error "--th is not a parameter of --model ov" equilibria --model ov --ring 5 --th 2 --par headway --from 1.2 --to 3

# the ring method of a sweep: winding tables without boundaries (any N), per mode with them
wnd="$tmp/winding"; mkdir -p "$wnd"
"$bin" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring 1000000 --no-boundaries --out "$wnd/a" --format json >"$wnd/a.out" 2>/dev/null &&
    python3 -c "import json; d = json.load(open('$wnd/a.out')); assert d['solver'] == {'given': 'auto', 'used': 'winding'}, d['solver']" &&
    ok || bad "sweep --ring 1000000 --no-boundaries: winding tables"
"$bin" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring 6 --out "$wnd/b" --format json >"$wnd/b.out" 2>/dev/null &&
    python3 -c "import json; d = json.load(open('$wnd/b.out')); assert d['solver']['used'] == 'modes', d['solver']" &&
    ok || bad "sweep with boundaries: per-mode roots"
rm -rf "$wnd"

# fold curves of periodic orbits in two parameters (orbits --par2): the 3-car ov ring in (headway,
# tau); each curve's point on the face tau = 0.8 must be a fold of the one-parameter branch computed
# at tau = 0.8 (a second path), every point has g = 0, and the CSV holds the JSON's numbers exactly
fc="$tmp/foldcurves"; mkdir -p "$fc"
if "$bin" orbits --model ov --ring 3 --headway 1.2 --par headway --from 1.2 --to 3 --par2 tau --from2 0.8 --to2 1.2 --format json --quiet --out "$fc/a" >"$fc/a.json" &&
   "$bin" orbits --model ov --ring 3 --headway 1.2 --tau 0.8 --par headway --from 1.2 --to 3 --format json --quiet >"$fc/b.json"; then
    python3 - "$fc/a.json" "$fc/b.json" "$fc/a-folds.csv" <<'PY' && ok || bad "orbits --par2: the fold curves against the folds at tau = 0.8"
import json, sys, csv
a = json.load(open(sys.argv[1])); b = json.load(open(sys.argv[2]))
assert a["status"] == "converged" and a["inputs"]["par2"] == "tau"
curves = a["result"]["fold_curves"]
assert len(curves) == 2, len(curves)
folds08 = [f["par"] for f in b["result"]["folds"]]
assert len(folds08) == 2
for c in curves:
    assert c["status"] == "converged" and c["stop_backward"] == "bound", (c["stop_backward"], c["message"])
    end = c["points"][0]
    assert end["par2"] == 0.8
    assert min(abs(end["par"] - f) for f in folds08) < 1e-8, (end["par"], folds08)
    assert all(p["fold_test"] < 1e-12 and p["residual"] < 1e-8 and p["second_distance"] < 1e-2 for p in c["points"])
rows = list(csv.DictReader(open(sys.argv[3])))
assert len(rows) == sum(len(c["points"]) for c in curves)
assert float(rows[0]["headway_m"]) == curves[0]["points"][0]["par"] and float(rows[0]["tau_s"]) == 0.8
PY
else
    bad "orbits --par2 exit status"
fi
# knut's traffic demo: the folds of orbits of the 3-car ring (alpha = 0.6, v0 = 0.8) in (headway,
# alpha); on the face alpha = 1.2 the curves end where the branch in the headway at alpha = 1.2 folds
if "$bin" orbits --model ov --ring 3 --alpha 0.6 --v0 0.8 --tau 1 --par headway --from 1.2 --to 3 --par2 alpha --from2 0.3 --to2 1.2 --format json --quiet >"$fc/knut.json" &&
   "$bin" orbits --model ov --ring 3 --alpha 1.2 --v0 0.8 --tau 1 --par headway --from 1.2 --to 3 --format json --quiet >"$fc/knut12.json"; then
    python3 - "$fc/knut.json" "$fc/knut12.json" <<'PY' && ok || bad "orbits --par2 alpha: knut's demo against the folds at alpha = 1.2"
import json, sys
curves = json.load(open(sys.argv[1]))["result"]["fold_curves"]
folds = sorted(f["par"] for f in json.load(open(sys.argv[2]))["result"]["folds"])
ends = sorted(p["par"] for c in curves for p in c["points"] if p["par2"] == 1.2)
assert len(curves) == 2 and len(folds) == 2 and len(ends) == 2, (len(curves), folds, ends)
assert all(abs(a - b) < 1e-8 for a, b in zip(ends, folds)), (ends, folds)
PY
else
    bad "orbits --par2 alpha exit status"
fi
expect_error "--par2 needs --from2 and --to2" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --out "$fc/bad1"
expect_error "--par2 = 'headway': expected a parameter other than --par" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 headway --from2 1 --to2 2
expect_error "expected it in \[--from2, --to2\]" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --from2 1.5 --to2 2 --out "$fc/bad2"
expect_error "--par2: not with --wave" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --from2 0.5 --to2 2 --wave 1
expect_error "--from2/--to2 without --par2" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --from2 0.5
expect_error "'nope'" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 nope --from2 0.5 --to2 2
[ -z "$(ls "$fc" | grep bad)" ] && ok || bad "orbits --par2 bad input wrote files: $(ls "$fc")"
# the bistability chart of the 3-car ov ring in (headway, tau): curves and cells as JSON and CSV,
# the figure; the two bistable windows at tau = 1 lie between the Hopf points and the folds of the
# one-parameter branch there (checked above and in test_periodic_orbit.cpp)
if "$bin" bistability --model ov --ring 3 --headway 1.2 --par headway --from 1.2 --to 3 --par2 tau --from2 0.3 --to2 2 --format json --quiet --out "$fc/bi" >"$fc/bi.json"; then
    python3 - "$fc/bi.json" "$fc/bi-curves.csv" <<'PY' && ok || bad "bistability: cells and curves of the 3-car ov ring"
import json, sys, csv
d = json.load(open(sys.argv[1]))
assert d["status"] == "converged" and d["command"] == "bistability"
r = d["result"]
assert len(r["fold_curves"]) == 3 and sum(len(c["generalised_hopf"]) for c in r["hopf"]["curves"]) == 3
def cell(p1, p2):
    best = None
    for c in r["cells"]:
        for y, lo, hi in c["intervals"]:
            if lo <= p1 <= hi and (best is None or abs(y - p2) < best[0]):
                best = (abs(y - p2), c)
    return best[1]
assert cell(2.6, 1.0)["bistable"] and cell(1.32, 1.0)["bistable"]
assert not cell(2.9, 1.0)["bistable"] and not cell(2.0, 1.0)["equilibrium_stable"]
rows = list(csv.DictReader(open(sys.argv[2])))
kinds = {x["kind"] for x in rows}
assert {"hopf_supercritical", "hopf_subcritical", "generalised_hopf", "fold_of_orbits"} <= kinds, kinds
assert sum(x["kind"] == "fold_of_orbits" for x in rows) == sum(len(c["points"]) for c in r["fold_curves"])
PY
    xmllint --noout "$fc/bi.svg" && grep -q "bistable: stable wave and stable uniform flow" "$fc/bi.svg" && grep -q "fold of periodic orbits" "$fc/bi.svg" \
        && ok || bad "bistability --out: the figure"
else
    bad "bistability exit status"
fi
expect_error "--par2 = 'headway': expected a parameter other than --par" bistability --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 headway --from2 1 --to2 2 --out "$fc/bad3"
expect_error "expected it in \[--from2, --to2\]" bistability --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --from2 1.5 --to2 2 --out "$fc/bad4"
expect_error "--rows" bistability --model ov --ring 3 --par headway --from 1.2 --to 3 --par2 tau --from2 0.5 --to2 2 --rows 2
expect_error "--par2 is required" bistability --model ov --ring 3 --par headway --from 1.2 --to 3
[ -z "$(ls "$fc" | grep bad)" ] && ok || bad "bistability bad input wrote files: $(ls "$fc")"
# the paper's ACC law with acceleration limits on a ring (--model acc): A_min's gains from --car;
# its Hopf points in k2 are where the linear OVRV ring (roots, independent code) has a root on the
# axis, and the upper one is supercritical
if "$bin" hopf --model acc --ring 8 --car A_min --gap 30 --par k2 --from 0.2 --to 1.2 --format json --quiet >"$tmp/acc.json"; then
    python3 - "$tmp/acc.json" "$bin" <<'PY' && ok || bad "hopf --model acc: the Hopf points against the linear ring's roots"
import json, sys, subprocess
d = json.load(open(sys.argv[1]))
assert d["inputs"]["car"] == "A_min" and d["inputs"]["model"] == "acc"
hs = d["result"]["hopf"]
assert len(hs) == 2 and hs[1]["l1"] < 0, hs
for h in hs:
    out = subprocess.run([sys.argv[2], "roots", "--model", "ovrv", "--k1", "0.052", "--k2", repr(h["par"]), "--th", "0.819", "--tau", "0.948",
                          "--eta", "8.03", "--ring", "8", "--count", "12", "--format", "json"], capture_output=True, text=True, check=True).stdout
    roots = json.loads(out)["result"]["roots"]
    assert any(abs(r["re"]) < 1e-8 and abs(abs(r["im"]) - h["omega"]) < 1e-8 for r in roots), (h, roots[:4])
PY
else
    bad "hopf --model acc exit status"
fi
expect_error "--car: only with --model acc" hopf --model ov --ring 3 --car A_min --par headway --from 1 --to 2
expect_error "--model acc needs --gap" hopf --model acc --ring 3 --car A_min --par k2 --from 0.2 --to 1
expect_error "a_min = 1: expected a finite braking limit < 0" hopf --model acc --ring 3 --car A_min --gap 30 --a-min 1 --par k2 --from 0.2 --to 1
expect_error "--alpha is not a parameter of --model acc" hopf --model acc --ring 3 --car A_min --gap 30 --alpha 1 --par k2 --from 0.2 --to 1

fi  # part hopf

if part orbits; then
# ---- orbits: periodic orbits from a Hopf point (Wright's equation y' = -alpha y(t-1)(1 + y): Hopf at
# alpha = pi/2 with period 4; the orbits exist for alpha > pi/2 and are stable)
if "$bin" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --points 8 --format json --out "$orb/w" --svg "$orb/w.svg" >"$orb/w.out"; then
    json_has "$orb/w.out" points folds period_doublings tori && ok || bad "orbits json keys"
    python3 - "$orb/w.out" "$orb/w.csv" <<'PY' && ok || bad "orbits: Wright's branch (period -> 4, stable, alpha > pi/2)"
import json, sys, math, csv
d = json.load(open(sys.argv[1]))["result"]
assert abs(d["hopf"]["par"] - math.pi / 2) < 1e-8 and abs(d["hopf"]["omega"] - math.pi / 2) < 1e-8
p = d["points"]
assert len(p) == 8 and all(set(q) >= {"par", "period", "min", "max", "stable", "multipliers"} for q in p)
assert abs(p[0]["period"] - 4) < 1e-3 and all(q["par"] > math.pi / 2 and q["stable"] for q in p)
assert all(abs(complex(*q["multipliers"][0]) - 1) < 1e-8 for q in p)  # the trivial multiplier, the largest here
rows = list(csv.DictReader(open(sys.argv[2])))
assert [r["kind"] for r in rows].count("orbit") == 8 and float(rows[0]["period_s"]) == p[0]["period"]  # round trip exact
PY
    xmllint --noout "$orb/w.svg" && grep -q 'stable periodic orbits' "$orb/w.svg" && ok || bad "orbits --svg"
else
    bad "orbits --system exit status"
fi
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --points 3 | grep -q "^hopf       alpha = 1.570796327" && ok || bad "orbits table"
# bad input: nothing on stdout, one line on stderr, exit 2, no file written
expect_error "parameter 'beta' is not a parameter of this system" orbits --system "$orb/wright.json" --par beta --from 1 --to 2 --out "$orb/bad1"
expect_error "--hopf = '1': expected an index from 0 to 0 (the branch has 1 Hopf point)" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --hopf 1 --out "$orb/bad2" --svg "$orb/bad2.svg" --quiet
expect_error "no Hopf point on the equilibrium branch in alpha from 0.5 to 1.5" orbits --system "$orb/wright.json" --par alpha --from 0.5 --to 1.5 --out "$orb/bad3" --quiet
expect_error "--variable = 'x': expected one of y" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --variable x
expect_error "--degree" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --degree 0
expect_error "--intervals" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --intervals 1
[ -z "$(ls "$orb" | grep bad)" ] && ok || bad "orbits bad input wrote files: $(ls "$orb")"
"$bin" orbits --help >"$orb/h.txt" 2>&1 && ! grep -q ' TEXT' "$orb/h.txt" && ok || bad "orbits --help has an option without its kind"
# a mesh is sized before any work (once: 300 s and 3.4 GB with no guard and no progress)
expect_error "a mesh of 10000 intervals of degree 20 (2e+05 collocation unknowns): estimated memory 8 GB is above the limit 2 GB (--allow-large runs it anyway)" \
    orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --degree 20 --intervals 10000
# orbits whose multipliers are not computed (a mesh above the dense monodromy limit): no stability
# verdict in the table, the JSON (stable null) or the figure (grey), exit 4; once "stable no", exit 0
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1.4 --to 2 --points 3 --degree 10 --intervals 1700 --format json \
    --svg "$orb/nomu.svg" --quiet >"$orb/nomu.json" 2>"$orb/nomu.err"
rc=$?
[ $rc -eq 4 ] && grep -q "no Floquet multipliers" "$orb/nomu.err" && ok || bad "orbits without multipliers: exit $rc, $(cat "$orb/nomu.err")"
python3 -c "
import json, sys
d = json.load(open(sys.argv[1]))
assert d['status'] == 'numerical_issue', d['status']
assert all(p['stable'] is None and p['multipliers'] == [] and 'no Floquet multipliers' in p['undecided'] for p in d['result']['points'])
" "$orb/nomu.json" && grep -q "undecided periodic orbits" "$orb/nomu.svg" && ! grep -q ">stable periodic orbits\|>unstable periodic orbits" "$orb/nomu.svg" \
    && ok || bad "orbits without multipliers in the JSON and the figure"
# switching at a period doubling (Mackey-Glass, examples/mackey_glass.json): the branch of twice the
# period starts at the located doubling, its orbits have twice the period of the old ones there and
# are stable past it; the next doubling of the cascade is on it (checked by simulation in
# tests/analysis/bifurcation/test_periodic_orbit.cpp)
if "$bin" orbits --system "$(dirname "$0")/../../examples/mackey_glass.json" --par tau --from 0.3 --to 2 --points 200 --period-doubling 0 --format json \
       --out "$orb/pd" --svg "$orb/pd.svg" --quiet >"$orb/pd.json"; then
    python3 - "$orb/pd.json" "$orb/pd-doubled.csv" <<'PY' && ok || bad "orbits --period-doubling: the branch of twice the period"
import json, sys, csv
d = json.load(open(sys.argv[1]))
assert d["status"] == "converged" and d["inputs"]["period_doubling"] == 0
r = d["result"]
pd = r["period_doublings"][0]
dbl = r["period_doubled"]
assert dbl["from"]["par"] == pd["par"] and dbl["from"]["period"] == pd["period"]
p = dbl["points"]
assert len(p) > 5 and dbl["intervals"] == 2 * r["intervals"]
# T(tau) extrapolated from the first two orbits to the doubling: twice the period there
T = p[0]["period"] + (pd["par"] - p[0]["par"]) * (p[1]["period"] - p[0]["period"]) / (p[1]["par"] - p[0]["par"])
assert abs(T - 2 * pd["period"]) < 1e-3 * pd["period"], T
assert p[0]["par"] > pd["par"] and p[1]["stable"]
assert len(dbl["period_doublings"]) >= 1 and dbl["period_doublings"][0]["par"] > pd["par"]
rows = list(csv.DictReader(open(sys.argv[2])))
assert [x["kind"] for x in rows].count("orbit") == len(p) and float(rows[0]["period_s"]) == p[0]["period"]
PY
    xmllint --noout "$orb/pd.svg" && grep -q "stable orbits of twice the period" "$orb/pd.svg" && ok || bad "orbits --period-doubling --svg"
else
    bad "orbits --period-doubling exit status"
fi
# (these indices can only be checked once the branch is computed: --quiet, so that a slow build's
# progress lines, which may come first, do not count as a second line of the error)
expect_error "--period-doubling = '1': expected an index from 0 to 0 (the branch has 1 period doubling)" \
    orbits --system "$(dirname "$0")/../../examples/mackey_glass.json" --par tau --from 0.3 --to 1.5 --period-doubling 1 --out "$orb/bad4" --quiet
expect_error "--period-doubling = '0': the branch has no period doubling in alpha from 1 to 2" \
    orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --period-doubling 0 --out "$orb/bad5" --quiet
expect_error "--period-doubling = '-1': expected an integer >= 0" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --period-doubling -1
expect_error "--period-doubling: not with --wave" orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --period-doubling 0 --wave 1
[ -z "$(ls "$orb" | grep bad)" ] && ok || bad "orbits --period-doubling bad input wrote files: $(ls "$orb")"
# curves of period doublings in two parameters (orbits --par2): Mackey-Glass in (tau, n); the curve
# passes through the branch's doubling, ends on both faces of n, and every point has a multiplier -1
mg="$(dirname "$0")/../../examples/mackey_glass.json"
if "$bin" orbits --system "$mg" --par tau --from 0.3 --to 2 --points 200 --par2 n --from2 9 --to2 10.5 --format json --out "$orb/pdc" --quiet >"$orb/pdc.json"; then
    python3 - "$orb/pdc.json" "$orb/pdc-doublings.csv" <<'PY' && ok || bad "orbits --par2: the curve of period doublings"
import json, sys, csv
d = json.load(open(sys.argv[1]))
r = d["result"]
assert d["status"] == "converged" and len(r["period_doubling_curves"]) == 1
c = r["period_doubling_curves"][0]
pd = r["period_doublings"][0]
assert abs(c["points"][c["start"]]["par"] - pd["par"]) < 1e-9 and c["points"][c["start"]]["par2"] == 9.65  # corrected again on the curve: 1.8e-13 apart
assert c["stop_backward"] == c["stop_forward"] == "bound"
assert {c["points"][0]["par2"], c["points"][-1]["par2"]} == {9, 10.5}
assert all(q["second_distance"] < 1e-8 and q["fold_test"] < 1e-10 for q in c["points"])
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == len(c["points"]) and float(rows[0]["tau"]) == c["points"][0]["par"], rows[0]
PY
else
    bad "orbits --par2 (period doublings) exit status"
fi
# the curve of torus bifurcations (orbits --par2): DDE-BIFTOOL's minimal demo in (tau, b), from the
# torus of the branch born at tau = 7.3195; it ends on the face b = 0.9 and where the orbits
# shrink onto the double Hopf point that hopf --par2 locates (tau = 8.728742694, b = 0.3544448049)
duff="$(dirname "$0")/../../examples/duffing.json"
if "$bin" orbits --system "$duff" --par tau --from 0 --to 20 --hopf 1 --points 12 --intervals 30 --par2 b --from2 0.3 --to2 0.9 --format json \
    --out "$orb/tor" --svg "$orb/tor.svg" --quiet >"$orb/tor.json"; then
    # the figure with --par2: the plane (tau, b), the torus curve and its end at the double Hopf point marked
    grep -q ">torus bifurcation<" "$orb/tor.svg" && grep -q ">DH<" "$orb/tor.svg" && ok || bad "orbits --par2 --svg: the torus curve in the plane"
    python3 - "$orb/tor.json" "$orb/tor-tori.csv" <<'PY' && ok || bad "orbits --par2: the curve of torus bifurcations"
import json, sys, csv, math
d = json.load(open(sys.argv[1]))
r = d["result"]
assert d["status"] == "converged" and len(r["torus_curves"]) == 1 and len(r["tori"]) == 1
c = r["torus_curves"][0]
s = c["points"][c["start"]]
assert abs(s["par"] - r["tori"][0]["par"]) < 1e-8 and s["par2"] == 0.6
assert c["stop_backward"] == "hopf" and c["stop_forward"] == "bound"
end = c["points"][0]
assert abs(end["par"] - 8.728742694) < 1e-4 and abs(end["par2"] - 0.3544448049) < 1e-4, end
assert all(q["second_distance"] < 1e-9 and q["fold_test"] < 1e-10 and 0 < q["rotation"] < math.pi for q in c["points"])
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == len(c["points"]) and float(rows[0]["rotation_rad"]) == c["points"][0]["rotation"], rows[0]
PY
else
    bad "orbits --par2 (tori) exit status"
fi
# starts other than a Hopf point: the orbit a simulation settles on (--from-simulation), or one
# given in a file (--guess), at --par = --from. Wright's equation: each is corrected to the orbit
# that the branch from the Hopf point reaches on its face (alpha = 2 from a simulation, alpha = 1.7
# from a sine of period 4.1 and amplitude 0.8: near the Hopf point the orbit is nearly one)
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --points 200 --format json --quiet >"$orb/hopf2.json" || bad "orbits to alpha = 2"
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1 --to 1.7 --points 200 --format json --quiet >"$orb/hopf17.json" || bad "orbits to alpha = 1.7"
"$bin" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --points 4 --from-simulation 300 --format json --quiet >"$orb/sim.json" \
    || bad "orbits --from-simulation exit status"
python3 -c "
import math
with open('$orb/guess.csv', 'w') as f:
    f.write('t,y\n')
    for i in range(101):
        t = 4.1 * i / 100
        f.write('%r,%r\n' % (t, 0.8 * math.sin(2 * math.pi * t / 4.1)))
"
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1.7 --to 2.5 --points 4 --guess "$orb/guess.csv" --format json --quiet >"$orb/file.json" \
    || bad "orbits --guess exit status"
python3 - "$orb/hopf2.json" "$orb/sim.json" "$orb/hopf17.json" "$orb/file.json" <<'PY' && ok || bad "orbits --from-simulation and --guess: the orbits of the branch from the Hopf point"
import json, sys
h2, s, h17, f = (json.load(open(a)) for a in sys.argv[1:])
for h, d, kind, at in ((h2, s, "simulation", 2), (h17, f, "file", 1.7)):
    end = h["result"]["points"][-1]
    assert end["par"] == at
    assert d["status"] == "converged" and d["result"]["start"]["kind"] == kind and "hopf" not in d["result"], d["result"].get("start")
    first = d["result"]["points"][0]
    assert first["par"] == at and abs(first["period"] - end["period"]) < 1e-9 * end["period"], (first["period"], end["period"])
    # the same orbit in another phase: max is sampled at 8 d points per interval, so it agrees to
    # the sampling error (h T / (8 d))^2 |x''| / 8, about 3e-6 here (1.2e-6 and 5.6e-7 measured)
    assert abs(first["max"][0] - end["max"][0]) < 1e-5 and first["stable"]
    assert all(p["par"] >= at for p in d["result"]["points"])  # followed towards --to
assert s["result"]["start"]["crossings_per_period"] == 1 and s["result"]["start"]["period_spread"] < 1e-3
assert s["inputs"]["t_end"] == 300 and "hopf" not in s["inputs"]
PY
# a simulation that settles on the (stable) equilibrium gives no orbit: undecided, exit 4, said why
"$bin" orbits --system "$orb/wright.json" --par alpha --from 1 --to 1.5 --from-simulation 200 --quiet >"$orb/eqsim.out" 2>"$orb/eqsim.err"
rc=$?
[ $rc -eq 4 ] && grep -q "settled on an equilibrium" "$orb/eqsim.err" && ok || bad "orbits --from-simulation on a stable equilibrium: exit $rc, $(cat "$orb/eqsim.err")"
printf 't,y\n0,1\n1,2\n' >"$orb/short.csv"
printf 't,y,z\n0,1,1\n' >"$orb/cols.csv"
printf 't,y\n0,1\n1,2\n0.5,0\n2,1\n' >"$orb/order.csv"
expect_error "--guess = $orb/short.csv: 2 rows of numbers: expected at least 4 covering one period" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --guess "$orb/short.csv" --out "$orb/bad6"
expect_error "row 1: expected 2 columns (t and one per variable), found 3" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --guess "$orb/cols.csv"
expect_error "row 4: t = 0.5: expected times increasing" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --guess "$orb/order.csv"
expect_error "--history = '1,2': expected 1 values (one per variable), found 2" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --from-simulation 100 --history 1,2
expect_error "--from-simulation = '-1': expected a run time above 0, at most 1e7" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --from-simulation -1
expect_error "--hopf: not with --from-simulation" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --from-simulation 100 --hopf 0
expect_error "--from-simulation and --guess: expected one start of the orbits" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --from-simulation 100 --guess "$orb/guess.csv"
expect_error "--history: only with --from-simulation" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --history 1
expect_error "a simulation of 1e+09 steps of 1 variables: estimated run time 50 min is above the limit 10 min" orbits --system "$orb/wright.json" --par alpha --from 2 --to 2.5 --from-simulation 1e7
[ -z "$(ls "$orb" | grep bad)" ] && ok || bad "orbits --guess bad input wrote files: $(ls "$orb")"

fi  # part orbits

if part rings; then
# roots/string --ring: verdict, counts and abscissa from the winding pass (cost independent of N)
rwd="$tmp/ringwind"; mkdir -p "$rwd"
for n in 1000000 1000000000; do
    t0=$(ms_now)
    "$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring "$n" --format json >"$rwd/r$n.json" 2>/dev/null &&
        { [ -n "${DDEMAP_SANITIZED:-}" ] || [ $(( $(ms_now) - t0 )) -lt 3000 ]; } && ok || bad "roots --ring $n: not done in 3 s or failed"
done
"$bin" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring inf --format json >"$rwd/rinf.json" 2>/dev/null
python3 - "$rwd" <<'PY' && ok || bad "roots --ring 1e6 / 1e9: winding verdict equals the N = inf verdict, listed roots are roots"
import json, sys
d = sys.argv[1]
inf = json.load(open(d + "/rinf.json"))
for n in (1000000, 1000000000):
    e = json.load(open(d + "/r%d.json" % n))
    assert e["solver"] == {"given": "auto", "used": "winding"}, e["solver"]
    r = e["result"]
    assert r["listed_by"] == "newton" and r["winding"]["certified"], r["winding"]
    assert r["ring_verdict"] == inf["result"]["ring_verdict"] == "unstable", (n, r["ring_verdict"])
    assert r["winding"]["unstable_roots"] > 0
    # far from the boundary the long ring's abscissa is near the sup over theta
    assert abs(r["spectral_abscissa"] - inf["result"]["spectral_abscissa"]) < 1e-6, r["spectral_abscissa"]
    assert len(r["roots"]) == 6 and r["roots"][0]["re"] == r["spectral_abscissa"], r["roots"][0]
    for x in r["roots"]:
        assert x["residual"] < 1e-12 and 0 <= x["mode"] < n, x
PY
# a string-stable point: the long ring is stable as N = inf is
for n in inf 1000000; do "$bin" string --k1 0.6 --k2 0.9 --th 1.5 --tau 0.1 --ring "$n" --format json >"$rwd/s$n.json" 2>/dev/null; done
python3 - "$rwd" <<'PY' && ok || bad "string --ring 1e6: winding verdict equals the N = inf verdict"
import json, sys
a, b = (json.load(open(sys.argv[1] + "/s%s.json" % n)) for n in ("inf", "1000000"))
assert b["solver"]["used"] == "winding", b["solver"]
assert a["result"]["ring_verdict"] == b["result"]["ring_verdict"] == "stable", (a["result"]["ring_verdict"], b["result"]["ring_verdict"])
PY
# N = 22: the winding pass and the per-mode path agree (verdict, counts, abscissa to 1e-8)
for p in "0.2 0.2" "0.6 0.9" "0.4 0.3"; do
    set -- $p
    "$bin" roots --k1 "$1" --k2 "$2" --th 1.5 --tau 0.1 --ring 22 --ring-method winding --format json >"$rwd/w.json" 2>/dev/null
    "$bin" roots --k1 "$1" --k2 "$2" --th 1.5 --tau 0.1 --ring 22 --ring-method modes --format json >"$rwd/m.json" 2>/dev/null
    python3 - "$rwd" <<'PY' && ok || bad "roots --ring 22 k1=$1 k2=$2: winding and per-mode path differ"
import json, sys
w, m = (json.load(open(sys.argv[1] + f)) for f in ("/w.json", "/m.json"))
assert w["solver"] == {"given": "winding", "used": "winding"} and m["solver"] == {"given": "modes", "used": "modes"}, (w["solver"], m["solver"])
rw, rm = w["result"], m["result"]
assert rm["winding"] is None and rw["winding"]["certified"]
assert rw["winding"]["verdict"] == rm["ring_verdict"], (rw["winding"]["verdict"], rm["ring_verdict"])
assert rw["winding"]["unstable_roots"] == rm["unstable_roots"] and rw["winding"]["marginal_roots"] == rm["marginal_roots"]
assert abs(rw["winding"]["spectral_abscissa"] - rm["spectral_abscissa"]) < 1e-8, (rw["winding"]["spectral_abscissa"], rm["spectral_abscissa"])
PY
done
# N = 2001 (past the per-mode listing): the roots listed by Newton from the abscissa mode are the per-mode path's
for p in "0.6 0.9" "0.2 0.2"; do
    set -- $p
    "$bin" roots --k1 "$1" --k2 "$2" --th 1.5 --tau 0.1 --ring 2001 --count 4 --format json >"$rwd/w.json" 2>/dev/null
    "$bin" roots --k1 "$1" --k2 "$2" --th 1.5 --tau 0.1 --ring 2001 --count 4 --ring-method modes --format json >"$rwd/m.json" 2>/dev/null
    python3 - "$rwd" <<'PY' && ok || bad "roots --ring 2001 k1=$1 k2=$2: Newton-listed roots differ from the per-mode ones"
import json, sys
w, m = (json.load(open(sys.argv[1] + f))["result"] for f in ("/w.json", "/m.json"))
assert w["listed_by"] == "newton" and m["listed_by"] == "modes", (w["listed_by"], m["listed_by"])
assert len(w["roots"]) == len(m["roots"]) == 4
for a, b in zip(w["roots"], m["roots"]):
    assert abs(complex(a["re"], a["im"]) - complex(b["re"], b["im"])) < 1e-10 and a["residual"] < 1e-12, (a, b)
assert w["ring_verdict"] == m["ring_verdict"] and w["unstable_roots"] == m["unstable_roots"]
PY
done
# k1 = 0 (every gap free): the low-frequency series cannot decide the trivial branch; past 2,000 cars: UNDECIDED, exit 4
"$bin" roots --k1 0 --k2 0.5 --th 1.5 --tau 0.1 --ring 100000 >"$rwd/u.txt" 2>"$rwd/u.err"
[ $? -eq 4 ] && grep -q "verdict    ring UNDECIDED" "$rwd/u.txt" && grep -q "ring-method modes" "$rwd/u.err" && ok || bad "roots --ring 100000 at k1 = 0: not UNDECIDED with exit 4"
"$bin" roots --k1 0 --k2 0.5 --th 1.5 --tau 0.1 --ring 22 --format json >"$rwd/u.json" 2>/dev/null &&
    python3 -c "import json; r = json.load(open('$rwd/u.json'))['result']; assert r['ring_verdict'] == 'marginal' and r['winding']['fell_back_to_modes'], r['winding']" &&
    ok || bad "roots --ring 22 at k1 = 0: the per-mode path does not decide where the winding pass cannot"
expect_error "at most 1000000)" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 2000000 --ring-method modes
expect_error "at most 1000000000)" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring 2000000000
expect_error "--ring-method = 'fast': expected auto, winding or modes" roots --k1 0.2 --k2 0.2 --th 1.5 --tau 0.1 --ring-method fast
rm -rf "$rwd"

# connected cruise control rings (cars of two leaders, in a random order): the product path
# (transfer matrices, taken by auto) against the sparse path, and the order of the cars matters
ccwd=$(mktemp -d)
printf 'vehicle,model,k1,k2,k3,th,tau,tau2
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
A_min,,,,,,,
A_min,,,,,,,
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
A_min,,,,,,,
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
A_min,,,,,,,
A_min,,,,,,,
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
,ccc,0.1,0.3,0.2,1.2,0.4,0.1
A_min,,,,,,,
' >"$ccwd/ccc.csv"
{ head -1 "$ccwd/ccc.csv"; tail -n +2 "$ccwd/ccc.csv" | sort; } >"$ccwd/sorted.csv"
"$bin" roots --fleet "$ccwd/ccc.csv" --count 8 --format json >"$ccwd/p.json" &&
    "$bin" roots --fleet "$ccwd/ccc.csv" --count 8 --solver sparse --format json >"$ccwd/s.json" &&
    "$bin" roots --fleet "$ccwd/sorted.csv" --count 8 --format json >"$ccwd/o.json" &&
    python3 - "$ccwd" <<'PY' && ok || bad "roots --fleet with ccc cars: product path against sparse, order"
import json, sys
p, s, o = (json.load(open(sys.argv[1] + f)) for f in ("/p.json", "/s.json", "/o.json"))
assert p["status"] == s["status"] == o["status"] == "converged"
assert p["solver"]["used"] == "product" and s["solver"]["used"] == "sparse", (p["solver"], s["solver"])
p, s, o = p["result"], s["result"], o["result"]
zp = [complex(r["re"], r["im"]) for r in p["roots"]]
zs = [complex(r["re"], r["im"]) for r in s["roots"]]
assert len(zp) == len(zs) >= 8 and all(abs(a - b) < 1e-10 * max(1, abs(a)) for a, b in zip(zp, zs)), (zp, zs)
assert all(r["residual"] < 1e-12 for r in p["roots"]), p["roots"]
assert abs(p["spectral_abscissa"] - o["spectral_abscissa"]) > 1e-4, (p["spectral_abscissa"], o["spectral_abscissa"])
PY
OMP_NUM_THREADS=1 "$bin" roots --fleet "$ccwd/ccc.csv" --count 8 --format json >"$ccwd/p1.json" &&
    OMP_NUM_THREADS=2 "$bin" roots --fleet "$ccwd/ccc.csv" --count 8 --format json >"$ccwd/p2.json" &&
    cmp -s "$ccwd/p1.json" "$ccwd/p2.json" && ok || bad "roots --fleet with ccc cars: output depends on the number of threads"
rm -rf "$ccwd"

fi  # part rings

if part progress; then
# ---- progress of equilibria, hopf and orbits on stderr (one line per finished point when stderr
# is a file, none with --quiet), and SIGINT during orbits --out leaves the old set, nothing else
pgd="$tmp/progress"; mkdir -p "$pgd"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" equilibria --system "$tmp/fold.json" --par p --from 0.9 --to -1 --format json >"$pgd/eq.json" 2>"$pgd/eq.err"
n=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['result']['points']))" "$pgd/eq.json" 2>/dev/null || echo none)
[ "$(pgcount "$pgd/eq.err" "^ddemap: equilibria: points [0-9]+/$n, p = [-0-9.e]+ \(")" = "$n" ] && ! grep -q "ddemap:" "$pgd/eq.json" && ok ||
    bad "equilibria: not one progress line per point ($n): $(head -3 "$pgd/eq.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" equilibria --system "$tmp/fold.json" --par p --from 0.9 --to -1 --quiet >/dev/null 2>"$pgd/eq.err"
[ ! -s "$pgd/eq.err" ] && ok || bad "equilibria --quiet still printed: $(head -3 "$pgd/eq.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --par2 b --from2 0.5 --to2 2 >/dev/null 2>"$pgd/hc.err"
pgcount "$pgd/hc.err" '^ddemap: hopf: equilibria [0-9]+/[0-9]+, alpha = ' >/dev/null &&
    pgcount "$pgd/hc.err" '^ddemap: hopf: [0-9]+ curve points \(at most 799\), alpha = [-0-9.e]+ \(' >/dev/null && ok ||
    bad "hopf --par2: progress lines of the branch and the curve: $(head -3 "$pgd/hc.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" hopf --system "$tmp/wright.json" --par alpha --from 1 --to 2 --quiet >/dev/null 2>"$pgd/hc.err"
[ ! -s "$pgd/hc.err" ] && ok || bad "hopf --quiet still printed: $(head -3 "$pgd/hc.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 3 --par headway --from 2 --to 3.5 --points 12 --format json >"$pgd/or.json" 2>"$pgd/or.err"
n=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['result']['points']))" "$pgd/or.json" 2>/dev/null || echo none)
[ "$(pgcount "$pgd/or.err" '^ddemap: orbits: [0-9]+ orbits? \(at most 12\), headway = [-0-9.e]+ \(')" = "$n" ] && ok ||
    bad "orbits: not one progress line per orbit ($n): $(grep -v equilibria "$pgd/or.err" | head -3)"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 3 --par headway --from 2 --to 3.5 --points 12 --quiet >/dev/null 2>"$pgd/or.err"
[ ! -s "$pgd/or.err" ] && ok || bad "orbits --quiet still printed: $(head -3 "$pgd/or.err")"
# SIGINT while the orbits are computed (after the second one): the old output set stays as it was
mkdir -p "$pgd/int"
for f in o.csv o.json o.svg; do echo old >"$pgd/int/$f"; done
python3 - "$bin" "$pgd/int" <<'PY' && ok || bad "orbits interrupted by SIGINT"
import os, signal, subprocess, sys, time
bin, d = sys.argv[1], sys.argv[2]
env = dict(os.environ, DDEMAP_TEST_PROGRESS_AT_ONCE="1")
p = subprocess.Popen([bin, "orbits", "--model", "ov", "--ring", "10", "--par", "headway", "--from", "1.2", "--to", "3",
                      "--out", d + "/o", "--svg", d + "/o.svg"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
for line in p.stderr:  # wait for the second orbit: the work is under way
    if ": 2 orbits (at most" in line:
        break
else:
    sys.exit("the orbits ended before the second orbit was reported")
p.send_signal(signal.SIGINT)
p.stderr.close()
rc = p.wait(timeout=60)
assert rc == -signal.SIGINT, rc
left = sorted(os.listdir(d))
assert left == ["o.csv", "o.json", "o.svg"], left
assert all(open(os.path.join(d, f)).read() == "old\n" for f in left)
PY

fi  # part progress

if part waves; then
# ---- orbits --wave: travelling waves of a ring in the reduced form (one car; the leader is the car
# shifted by K T / N). The 3-car ov ring: the wave agrees with the full ring's branch from the same
# Hopf point (fold headway, period), and the stability is the full ring's (N <= 10)
wav="$tmp/waves"; mkdir -p "$wav"
"$bin" orbits --model ov --ring 3 --wave 1 --par headway --from 3.5 --to 2 --points 40 --format json --out "$wav/w" >"$wav/w.out" &&
    "$bin" orbits --model ov --ring 3 --par headway --from 3.5 --to 2 --points 40 --format json >"$wav/f.out" &&
    json_has "$wav/w.out" points folds period_doublings tori wave && [ -s "$wav/w.csv" ] && [ -s "$wav/w.json" ] &&
    python3 - "$wav/w.out" "$wav/f.out" <<'PY' && ok || bad "orbits --wave 1 --ring 3: the reduced branch differs from the full ring's"
import json, sys
w, f = (json.load(open(a))["result"] for a in sys.argv[1:3])
assert w["wave"]["cars"] == 3 and w["wave"]["wave"] == 1 and w["wave"]["stability"] == "full_ring", w["wave"]
assert abs(w["wave"]["hopf"]["par"] - f["hopf"]["par"]) < 1e-8
assert len(w["folds"]) == len(f["folds"]) == 1
assert abs(w["folds"][0]["par"] - f["folds"][0]["par"]) < 1e-6 and abs(w["folds"][0]["period"] - f["folds"][0]["period"]) < 1e-6
assert w["points"][-1]["par"] == f["points"][-1]["par"] == 2 and abs(w["points"][-1]["period"] - f["points"][-1]["period"]) < 1e-6
assert w["points"][-1]["stable"] is True and w["points"][0]["stable"] is False
assert w["variables"] == ["h0", "v0"]
PY
# 1000 cars, 10 per wave: one car's cost; no stability claimed (stable null, the table says not computed)
"$bin" orbits --model ov --ring 1000 --wave 100 --par headway --from 3.5 --to 2 --points 5 --no-stability --format json >"$wav/l.out" &&
    python3 -c "
import json; r = json.load(open('$wav/l.out'))['result']
assert r['wave']['stability'] == 'not_computed' and all(p['stable'] is None and p['multipliers'] == [] for p in r['points']), r['points'][0]
assert len(r['points']) == 5 and r['certificate']['max_residual'] < 1e-8" && ok || bad "orbits --wave at 1000 cars"
"$bin" orbits --model ov --ring 1000 --wave 100 --par headway --from 3.5 --to 2 --points 3 --no-stability | grep -q "not computed" && ok || bad "orbits --wave table: stability not computed"
# the other wave number of the same Hopf pair has no wave with omega > 0: UNDECIDED, exit 4, naming the other one
"$bin" orbits --model ov --ring 5 --wave 4 --par headway --from 3.5 --to 2 >"$wav/u.txt" 2>"$wav/u.err"
[ $? -eq 4 ] && grep -q "try 1" "$wav/u.err" && ok || bad "orbits --wave 4 --ring 5: not UNDECIDED naming wave number 1"
expect_error "--wave = '5': expected a wave number from 1 to N - 1 = 4" orbits --model ov --ring 5 --wave 5 --par headway --from 3.5 --to 2 --out "$wav/bad1"
expect_error "--wave = '0': expected a wave number from 1 to N - 1 = 4" orbits --model ov --ring 5 --wave 0 --par headway --from 3.5 --to 2
expect_error "--wave = '1' needs a built-in ring" orbits --system "$orb/wright.json" --wave 1 --par alpha --from 1 --to 2 --out "$wav/bad2"
expect_error "--svg: not available with --wave" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --svg "$wav/bad3.svg"
expect_error "--initial-step: only with --wave" orbits --system "$orb/wright.json" --par alpha --from 1 --to 2 --initial-step 0.01
[ -z "$(ls "$wav" | grep bad)" ] && ok || bad "orbits --wave bad input wrote files: $(ls "$wav")"

fi  # part waves

if part large; then
# sweep and chart rings up to 10^9 cars on the winding tables; the per-mode path (--ring-curves all) stays at 10^6
big="$tmp/bigring"; mkdir -p "$big"
"$bin" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring 1000000000 --no-boundaries --out "$big/n" --format json >"$big/n.out" 2>/dev/null &&
    "$bin" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring inf --no-boundaries --out "$big/i" --format json >/dev/null 2>&1 &&
    python3 - "$big" <<'PY' && ok || bad "sweep --ring 1000000000 --no-boundaries: winding tables, the abscissa and counts of N = inf"
import csv, json, sys
d = json.load(open(sys.argv[1] + "/n.out"))
assert d["solver"]["used"] == "winding" and d["inputs"]["ring"] == 1000000000, (d["solver"], d["inputs"]["ring"])
n = list(csv.DictReader(open(sys.argv[1] + "/n.csv")))
i = list(csv.DictReader(open(sys.argv[1] + "/i.csv")))
assert len(n) == len(i) == 16
for a, b in zip(n, i):
    # N = inf unstable: the same sup of the abscissa; N = inf stable: 10^9 cars have no unstable root, only
    # the smallest wave numbers within the marginal band of the axis (so not "stable" either)
    if b["ring_stable"] == "false":
        assert a["ring_stable"] == "false" and int(a["unstable_roots"]) > 0, (a, b)
        assert abs(float(a["spectral_abscissa_per_s"]) - float(b["spectral_abscissa_per_s"])) < 1e-10, (a, b)
    else:
        assert int(a["unstable_roots"]) == 0 and abs(float(a["spectral_abscissa_per_s"])) < 1e-12, (a, b)
PY
expect_error "expected at most 1000000 cars for sweep with every mode's ring curve" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring 1000001 --ring-curves all --out "$big/b"
expect_error "expected at most 1000000 cars for boundary --ring-curves all" boundary --th 1.5 --tau 0.5 --k1 0.1:1 --k2 0.1:1 --ring 2000000 --ring-curves all --out "$big/c"
expect_error "at most 1000000000)" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring 1000000001 --no-boundaries --out "$big/d"
[ ! -e "$big/b.csv" ] && [ ! -e "$big/c.csv" ] && ok || bad "a refused ring size wrote files"
rm -rf "$big"

# roots --system on a large sparse file (real triplets are held sparse): a delayed reaction-diffusion
# equation from bench/sparse_systems.py; its rightmost root solves the scalar equation of the first
# Laplacian mode, lambda = mu + a - b e^{-lambda tau} (Newton in Python from the reported root: an
# independent check of value and mode), and the path is the sparse one with the compact basis
bsd=$(mktemp -d)
python3 "$(dirname "$0")/../../bench/sparse_systems.py" rd --nx 30 --ny 20 --out "$bsd/rd.json"
"$bin" roots --system "$bsd/rd.json" --format json >"$bsd/rd.out" 2>"$bsd/rd.err" &&
    python3 - "$bsd/rd.out" <<'PY' && ok || bad "roots --system 600-state reaction-diffusion: wrong root or path"
import cmath, json, math, sys
d = json.load(open(sys.argv[1]))
assert d["status"] == "converged" and d["solver"]["used"] == "sparse", (d["status"], d["solver"])
assert "compact Arnoldi" in d["message"], d["message"]
r = d["result"]["roots"]
assert len(r) >= 6 and r[0]["residual"] < 1e-12, r
z = complex(r[0]["re"], r[0]["im"])
mu = -4 * math.sin(math.pi / 62) ** 2 - 4 * 0.37 * math.sin(math.pi / 42) ** 2  # mode (1, 1), nx = 30, ny = 20
c, b, tau = mu + 0.5, 1.0, 2.0
w = z
for _ in range(50):  # Newton on f(w) = w - c + b e^{-w tau}
    w -= (w - c + b * cmath.exp(-w * tau)) / (1 - b * tau * cmath.exp(-w * tau))
assert abs(w - z) < 1e-10, (w, z)
PY
# a complex triplet makes the file dense: the dense path and its size estimate, as before
python3 - "$bsd/c.json" <<'PY'
import json, sys
json.dump({"dimension": 20, "delays": [1.0], "A0": {"triplets": [[i, i, -1.0] for i in range(20)]},
           "A": [{"triplets": [[i, (i + 1) % 20, [0.1, 0.2]] for i in range(20)]}]}, open(sys.argv[1], "w"))
PY
"$bin" roots --system "$bsd/c.json" --format json >"$bsd/c.out" 2>/dev/null &&
    python3 -c "import json; d = json.load(open('$bsd/c.out')); assert d['solver']['used'] == 'dense', d['solver']" && ok ||
    bad "roots --system with complex triplets: not the dense path"
rm -rf "$bsd"

fi  # part large

if part progress2; then
# ---- progress of roots --fleet/--system (at most one line per contour count, shift or degree when
# stderr is a file, at most one a second; none with --quiet), SIGINT during a long
# roots --fleet --out leaves no output file and ends the process by the signal, and a branch's
# first orbit is "1 orbit"
rpd="$tmp/root-progress"; mkdir -p "$rpd"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" roots --fleet-pattern "A_min,C_max" --ring 200 >"$rpd/f.out" 2>"$rpd/f.err"
n=$(sed -n 's/^solver     product, \([0-9]*\) contour counts.*/\1/p' "$rpd/f.out")
[ -n "$n" ] && grep -q -E '^ddemap: roots: step [0-9]+ of at most 200000, Re = [-0-9.e]+ \([^)]*; time left unknown\)$' "$rpd/f.err" &&
    [ "$(grep -c '^ddemap: roots:' "$rpd/f.err")" -le "$n" ] && ! grep -q "ddemap:" "$rpd/f.out" && ok ||
    bad "roots --fleet: no progress line, or more than one per contour count ($n): $(head -3 "$rpd/f.err")"
grep -q '^ddemap: roots: step 1 of at most' "$rpd/f.err" && ! grep -q ' left)' "$rpd/f.err" && ok || bad "roots --fleet progress: no 'step 1', or an estimate of the time left"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" roots --fleet-pattern "A_min,C_max" --ring 200 --quiet >/dev/null 2>"$rpd/q.err"
[ ! -s "$rpd/q.err" ] && ok || bad "roots --fleet --quiet still printed: $(head -3 "$rpd/q.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" roots --system "$(dirname "$0")/../../examples/system.json" --format json >/dev/null 2>"$rpd/s.err" &&
    grep -q -E '^ddemap: roots: step [0-9]+ of at most [0-9]+, Re = ' "$rpd/s.err" && ok ||
    bad "roots --system: no progress line: $(head -3 "$rpd/s.err")"
python3 - "$bin" "$rpd" <<'PY' && ok || bad "roots --fleet interrupted by SIGINT"
import os, signal, subprocess, sys, time
bin, d = sys.argv[1], sys.argv[2]
env = dict(os.environ, DDEMAP_TEST_PROGRESS_AT_ONCE="1")
p = subprocess.Popen([bin, "roots", "--fleet-pattern", "A_min,C_max", "--ring", "1000000", "--out", d + "/big"],
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
line = p.stderr.readline()  # the first contour count: the work is under way (about 20 s in all)
if ": step 1 of at most" not in line:
    sys.exit("no progress line for the first contour count: " + line)
time.sleep(1)
p.send_signal(signal.SIGINT)
p.stderr.close()
rc = p.wait(timeout=60)
assert rc == -signal.SIGINT, rc
left = sorted(f for f in os.listdir(d) if f.startswith("big") or f.startswith("."))
assert left == [], left
PY
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 3 --par headway --from 2 --to 3.5 --points 2 >"$rpd/o1.out" 2>"$rpd/o1.err"
grep -q '^ddemap: orbits: 1 orbit (at most 2)' "$rpd/o1.err" && grep -q '^branch     2 orbits, degree' "$rpd/o1.out" &&
    ! grep -q -E '(^|: )1 (orbits|points|waves|steps)' "$rpd/o1.out" "$rpd/o1.err" && ok ||
    bad "orbits --points 2: not '1 orbit' in the progress: $(grep -h -E '^branch|1 orbit' "$rpd/o1.out" "$rpd/o1.err" | head -3)"
rm -rf "$rpd"

# ---- progress of mix, growth and orbits --wave: one line per finished unit when stderr is a file
# (with the time left where the number of units is known), a line redrawn in place with the time
# left on a terminal, none with --quiet, stdout untouched; SIGINT during mix, growth and
# orbits --wave with --out leaves the old output set and nothing else; growth is sized before
# the work; a sweep with one uncertified point says "1 point has"
spd="$tmp/study-progress"; mkdir -p "$spd"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" mix --x A_min --y C_max --ring 20 --p 0:1:3 --draws 1 --out "$spd/m" >"$spd/m.out" 2>"$spd/m.err"
[ "$(grep -c -E '^ddemap: mix: arrangements [1-6]/6, p = [0-9.e]+ \(' "$spd/m.err")" = 6 ] && grep -q '^ddemap: mix: arrangements 6/6, p = 1 (' "$spd/m.err" &&
    grep -q -E '^ddemap: mix: arrangements 1/6, p = 0 \([^)]*, about [^)]* left\)$' "$spd/m.err" && ! grep -q "ddemap:" "$spd/m.out" && ok ||
    bad "mix: not one progress line per arrangement (6) with the time left: $(head -3 "$spd/m.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" mix --x A_min --y C_max --ring 20 --p 0:1:3 --quiet --out "$spd/m" >/dev/null 2>"$spd/m.err"
[ ! -s "$spd/m.err" ] && ok || bad "mix --quiet still printed: $(head -3 "$spd/m.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" growth --followers 3 >"$spd/g.out" 2>"$spd/g.err"
[ "$(grep -c -E '^ddemap: growth: platoons ([1-9]|1[0-4])/14 \(' "$spd/g.err")" = 14 ] && grep -q '^ddemap: growth: platoons 14/14 (' "$spd/g.err" &&
    ! grep -q "ddemap:" "$spd/g.out" && ok || bad "growth: not one progress line per platoon (14): $(head -3 "$spd/g.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" growth --followers 3 --quiet >/dev/null 2>"$spd/g.err"
[ ! -s "$spd/g.err" ] && ok || bad "growth --quiet still printed: $(head -3 "$spd/g.err")"
printf 'time_s,lead_speed_mps\n0,20\n10,19.9\n20,20\n10000000,20\n' >"$spd/lead-long.csv"
"$bin" growth --lead "$spd/lead-long.csv" --followers 200 --out "$spd/gl" >"$spd/o.txt" 2>"$spd/e.txt"
[ $? -eq 2 ] && [ ! -s "$spd/o.txt" ] && [ "$(wc -l <"$spd/e.txt")" -eq 1 ] && grep -q "^ddemap: error: 14 platoons of 200 followers over 1e+07 s" "$spd/e.txt" &&
    [ ! -e "$spd/gl.csv" ] && ok || bad "growth with a lead of 1e7 s: not refused before the work: $(cat "$spd/e.txt")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 3 --wave 1 --par headway --from 3.5 --to 2 --points 6 --format json >"$spd/w.json" 2>"$spd/w.err"
n=$(python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['result']['points']))" "$spd/w.json" 2>/dev/null || echo none)
[ "$(grep -c -E '^ddemap: orbits: [0-9]+ waves? \(at most 6\), headway = [-0-9.e]+ \(' "$spd/w.err")" = "$n" ] && grep -q '^ddemap: orbits: 1 wave (at most 6)' "$spd/w.err" && ok ||
    bad "orbits --wave: not one progress line per wave ($n): $(head -3 "$spd/w.err")"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 3 --wave 1 --par headway --from 3.5 --to 2 --points 6 --quiet >/dev/null 2>"$spd/w.err"
[ ! -s "$spd/w.err" ] && ok || bad "orbits --wave --quiet still printed: $(head -3 "$spd/w.err")"
# a terminal: the line is redrawn in place (carriage return) and carries the time left
python3 - "$bin" "$spd/mt" <<'PY' && ok || bad "mix on a terminal: no line redrawn in place with the time left"
import os, pty, subprocess, sys
master, slave = pty.openpty()
env = dict(os.environ, DDEMAP_TEST_PROGRESS_AT_ONCE="1")
p = subprocess.run([sys.argv[1], "mix", "--x", "A_min", "--y", "C_max", "--ring", "20", "--p", "0:1:3", "--draws", "1", "--format", "json", "--out", sys.argv[2]],
                   stdout=subprocess.DEVNULL, stderr=slave, env=env, timeout=120)
os.close(slave)
text = b""
while True:
    try:
        chunk = os.read(master, 65536)
    except OSError:
        break
    if not chunk:
        break
    text += chunk
os.close(master)
text = text.decode()
assert p.returncode == 0, p.returncode
assert "\rddemap: mix: arrangements 1/6, p = 0 (" in text and ", about " in text and " left)\x1b[K" in text, repr(text[:300])
text = text.replace("\r\n", "\n")  # the terminal's own line ends
assert text.count("\n") == 1 and text.endswith("\x1b[K\n") and "\rddemap: mix: arrangements 6/6, p = 1 (" in text, repr(text[-200:])
PY
# SIGINT after the first finished unit: the process ends by the signal, the old set stays as it was
python3 - "$bin" "$spd" "$spd/lead-1e5.csv" <<'PY' && ok || bad "mix, growth or orbits --wave interrupted by SIGINT"
import os, signal, subprocess, sys
bin, d, lead = sys.argv[1], sys.argv[2], sys.argv[3]
with open(lead, "w") as f:
    f.write("time_s,lead_speed_mps\n0,20\n10,19.999\n20,20\n100000,20\n")
env = dict(os.environ, DDEMAP_TEST_PROGRESS_AT_ONCE="1")
runs = {
    "mix": (["mix", "--x", "A_min", "--y", "C_max", "--ring", "100000", "--p", "0:1:11"], ": arrangements 1/11,", [".csv", ".json", ".svg"]),
    "growth": (["growth", "--lead", lead, "--followers", "1"], ": platoons 1/14 (", [".csv", ".json", ".svg"]),
    "orbits": (["orbits", "--model", "ov", "--ring", "10", "--wave", "1", "--par", "headway", "--from", "3.5", "--to", "2", "--points", "200"],
               ": 2 waves (at most 200)", [".csv", ".json"]),
}
for name, (argv, first, exts) in runs.items():
    out = os.path.join(d, "int-" + name)
    os.makedirs(out)
    for e in exts:
        with open(os.path.join(out, "o" + e), "w") as f:
            f.write("old\n")
    p = subprocess.Popen([bin] + argv + ["--out", out + "/o"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    for line in p.stderr:  # the work is under way
        if first in line:
            break
    else:
        sys.exit(name + ": ended before '" + first + "' was reported")
    p.send_signal(signal.SIGINT)
    p.stderr.close()
    rc = p.wait(timeout=60)
    assert rc == -signal.SIGINT, (name, rc)
    left = sorted(os.listdir(out))
    assert left == sorted("o" + e for e in exts), (name, left)
    assert all(open(os.path.join(out, f)).read() == "old\n" for f in left), name
PY
# one uncertified point (k2 = 0 and tau = 0 on a ring of 10^5 cars: roots on the imaginary axis)
"$bin" sweep --k2 0:0.2:2 --tau 0:0.2:2 --th 1.5 --k1 0.4 --ring 100000 --no-boundaries --out "$spd/s1" >"$spd/s1.out" 2>"$spd/s1.err"
[ $? -eq 4 ] && grep -q '^ddemap: sweep undecided (uncertified): 1 point has no certificate' "$spd/s1.err" &&
    grep -q '(1 of them UNDECIDED: no certificate)' "$spd/s1.out" && ! grep -q -E '\b1 (points|curves|threads)\b' "$spd/s1.out" "$spd/s1.err" && ok ||
    bad "sweep with one uncertified point: $(cat "$spd/s1.err")"
rm -rf "$spd"

fi  # part progress2

if part waves2; then
# ---- orbits --wave: the resolution of the waves (defect between collocation points) ----
wrs="$(mktemp -d)"
# 100 cars per wave on 20 uniform intervals: the branch stops as unresolved, exit 4, every
# reported wave below the limit 0.1
"$bin" orbits --model ov --ring 1000 --wave 10 --par headway --from 3.5 --to 2 --initial-step 0.001 --points 40 --intervals 20 --no-stability --format json >"$wrs/u.json" 2>"$wrs/u.err"
[ $? -eq 4 ] && grep -q "not resolved" "$wrs/u.err" && python3 -c "
import json; d = json.load(open('$wrs/u.json')); r = d['result']
assert r['stop'] == 'unresolved' and len(r['points']) > 0
assert all(0 <= p['defect'] <= 0.1 for p in r['points'])
assert r['wave']['max_defect'] == max(p['defect'] for p in r['points']) and r['wave']['intervals_used'] == 20" && ok ||
    bad "orbits --wave 10 --ring 1000 --intervals 20: not stopped as unresolved with the defects in JSON"
rm -rf "$wrs"

# ---- orbits --max-step: the largest continuation step (weighted norm); longer steps, fewer orbits, the same branch
msd="$tmp/maxstep"; mkdir -p "$msd"
echo '{"variables": ["y"], "parameters": {"alpha": 1}, "equations": ["-alpha*y(t - 1)*(1 + y)"], "equilibrium": [0]}' >"$msd/wright.json"
"$bin" orbits --system "$msd/wright.json" --par alpha --from 1 --to 2.5 --points 1000 --max-step 0.02 --format json >"$msd/s.json" &&
    "$bin" orbits --system "$msd/wright.json" --par alpha --from 1 --to 2.5 --points 1000 --max-step 1 --format json >"$msd/l.json" &&
    python3 - "$msd/s.json" "$msd/l.json" <<'PY' && ok || bad "orbits --max-step 1: not fewer orbits on the same branch"
import json, sys
s, l = (json.load(open(f)) for f in sys.argv[1:3])
assert l["inputs"]["max_step"] == 1 and s["inputs"]["max_step"] == 0.02, (l["inputs"], s["inputs"])
ps, pl = s["result"]["points"], l["result"]["points"]
assert s["result"]["stop"] == l["result"]["stop"] == "bound"
assert 3 * len(pl) < len(ps), (len(pl), len(ps))
# the last orbits are both on the face alpha = 2.5: the same period
assert abs(ps[-1]["period"] - pl[-1]["period"]) < 1e-6 * ps[-1]["period"], (ps[-1]["period"], pl[-1]["period"])
PY
expect_error "--max-step = '0.01': expected a value from 0.02 (the first step) to 1e6" orbits --system "$msd/wright.json" --par alpha --from 1 --to 2 --max-step 0.01 --out "$msd/bad1"
expect_error "--max-step = 'inf': expected a finite number" orbits --system "$msd/wright.json" --par alpha --from 1 --to 2 --max-step inf
expect_error "--max-step = '0.01': expected a value from 0.02 (the first step) to 1e6" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --max-step 0.01 --out "$msd/bad2"
[ -z "$(ls "$msd" | grep bad)" ] && ok || bad "orbits --max-step bad input wrote files: $(ls "$msd")"
rm -rf "$msd"

# ---- orbits --wave --max-step: the waves share the step control and special points of orbits
wms="$tmp/wavemaxstep"; mkdir -p "$wms"
"$bin" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --points 100 --quiet --format json >"$wms/s.json" &&
    "$bin" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --points 100 --max-step 2 --quiet --format json >"$wms/l.json" &&
    python3 - "$wms/s.json" "$wms/l.json" <<'PY' && ok || bad "orbits --wave --max-step 2: not fewer waves with the same fold"
import json, sys
s, l = (json.load(open(f)) for f in sys.argv[1:3])
assert l["inputs"]["max_step"] == 2 and "max_step" not in s["inputs"], (l["inputs"], s["inputs"])
rs, rl = s["result"], l["result"]
assert rs["stop"] == rl["stop"] == "bound" and len(rl["points"]) < len(rs["points"]), (len(rl["points"]), len(rs["points"]))
assert len(rs["folds"]) == len(rl["folds"]) == 1 and rs["folds"][0]["located"] and rl["folds"][0]["located"]
assert abs(rs["folds"][0]["par"] - rl["folds"][0]["par"]) < 1e-8, (rs["folds"], rl["folds"])
assert rs["period_doublings"] == rl["period_doublings"] == [] and rs["tori"] == rl["tori"] == []
PY
# the IDM wave with the full ring's multipliers: a period doubling and a torus, in JSON and in the table
"$bin" orbits --model idm --ring 5 --th 1.2 --tau 0.6 --wave 1 --par gap --from 6 --to 22 --points 300 --max-step 1 --quiet --format json >"$wms/i.json" &&
    "$bin" orbits --model idm --ring 5 --th 1.2 --tau 0.6 --wave 1 --par gap --from 6 --to 22 --points 300 --max-step 1 --quiet >"$wms/i.txt" &&
    grep -q "^doubling   gap = 21.0402" "$wms/i.txt" && grep -q "^torus      gap = 20.4574" "$wms/i.txt" && python3 - "$wms/i.json" <<'PY' && ok || bad "orbits --wave 1 on the 5-car IDM ring: no period doubling and torus: $(grep -E 'doubling|torus' "$wms/i.txt")"
import json, sys
r = json.load(open(sys.argv[1]))["result"]
pd, to = r["period_doublings"], r["tori"]
assert len(pd) == 1 and len(to) == 1 and pd[0]["located"] and to[0]["located"], (pd, to)
assert abs(pd[0]["par"] - 21.0402) < 1e-4 and abs(to[0]["par"] - 20.4575) < 1e-4, (pd, to)
assert pd[0]["par_bracket"] < 1e-6 and to[0]["par_bracket"] < 1e-6 and abs(pd[0]["multiplier"][0] + 1) < 1e-8
PY
expect_error "--initial-step = '0.5': expected a value from 1e-6 to 0.1 (the largest step, --max-step)" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --initial-step 0.5
"$bin" orbits --model ov --ring 5 --wave 1 --par headway --from 3.5 --to 2 --points 3 --initial-step 0.5 --max-step 1 --quiet --format json >"$wms/big.json" 2>/dev/null
[ $? -ne 2 ] && ok || bad "orbits --wave --initial-step 0.5 --max-step 1: refused"
rm -rf "$wms"

fi  # part waves2

if part mix; then
# ---- mix: sized before any work (time, memory, output); refused in one line naming the rings and the limit
mxd="$tmp/mixsize"; mkdir -p "$mxd"
expect_error "101 arrangements of a 1000000-car ring (product path): estimated run time .* is above the limit 10 min (--allow-large runs it anyway)" \
    mix --x A_min --y C_max --ring 1000000 --p 0:1:101 --out "$mxd/a"
expect_error "1000100000 arrangements of a 40-car ring (product path): estimated run time" mix --x A_min --y C_max --ring 40 --p 0:1:100000 --draws 10000 --out "$mxd/b"
expect_error "11 arrangements of a 100-car ring (dense path): estimated run time" mix --x A_min --y C_max --ring 100 --solver dense --out "$mxd/c"
expect_error "11 arrangements of a 5000-car ring (sparse path): estimated run time" mix --x A_min --y C_max --ring 5000 --solver sparse --out "$mxd/d"
expect_error "of memory, more than this machine has" mix --x A_min --y C_max --ring 3000 --solver dense --p 0:1:2 --allow-large --out "$mxd/e"
[ -z "$(ls "$mxd")" ] && ok || bad "mix refused by its size guard wrote files: $(ls "$mxd")"
# within the limits it runs
"$bin" mix --x A_min --y C_max --ring 40 --p 0:1:3 --out "$mxd/ok" >/dev/null && [ -s "$mxd/ok.csv" ] && ok || bad "mix: a small study refused"
rm -rf "$mxd"

# ---- roots --ring inf: the search's progress is also called within a long dense degree (M = 216, 434 complex
# states, in stages); off a terminal that adds no line: one line per finished step, step numbers increasing, no NaN
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" roots --k1 5 --k2 0.2 --th 1.5 --tau 0.2 --ring inf --count 5 >/dev/null 2>"$tmp/steps.txt" &&
    python3 - "$tmp/steps.txt" <<'PY' && ok || bad "roots --ring inf: the search's progress lines repeat a step or show NaN: $(cat "$tmp/steps.txt")"
import re, sys
steps = [int(m.group(1)) for m in re.finditer(r"roots: step (\d+) of at most", open(sys.argv[1]).read())]
assert len(steps) >= 2 and steps == sorted(set(steps)), steps
assert "nan" not in open(sys.argv[1]).read().lower()
PY

fi  # part mix

if part waves3; then
# ---- orbits --wave on more than 10 cars: the full ring's multipliers by the matrix-free path (Arnoldi
# on the monodromy applied by sparse sweeps); near the Hopf point of mode 10 the waves of 10 cars
# are unstable on 100 cars; a verdict per wave, stable null when undecided; a progress line per wave
wms="$tmp/wavems"; mkdir -p "$wms"
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" orbits --model ov --ring 100 --wave 10 --par headway --from 3.5 --to 2 --points 4 --format json >"$wms/m.json" 2>"$wms/m.err"
rc=$?
python3 - "$wms/m.json" "$rc" <<'PY' && ok || bad "orbits --wave 10 --ring 100: not the matrix-free multipliers with a verdict per wave"
import json, sys
d = json.load(open(sys.argv[1])); r = d["result"]; rc = int(sys.argv[2])
assert r["wave"]["stability"] == "full_ring" and r["wave"]["stability_method"] == "matrix_free", r["wave"]
assert len(r["points"]) == 4
for p in r["points"]:
    if p["stability_status"] == "converged":
        assert p["stable"] is False and len(p["multipliers"]) > 0 and abs(p["multipliers"][0][0]) + abs(p["multipliers"][0][1]) > 1, p
    else:
        assert p["stable"] is None and p["stability_message"], p
assert (rc == 0) == (r["wave"]["stability_status"] == "converged"), rc
PY
[ "$(grep -c "waves with multipliers" "$wms/m.err")" -eq 4 ] && ok || bad "orbits --wave --ring 100: not one progress line per wave's multipliers: $(head -3 "$wms/m.err")"
"$bin" orbits --model ov --ring 100 --wave 10 --par headway --from 3.5 --to 2 --points 2 | grep -q "matrix-free" && ok || bad "orbits --wave --ring 100 table: the method not named"
echo '{"variables": ["y"], "parameters": {"alpha": 1}, "equations": ["-alpha*y(t - 1)*(1 + y)"], "equilibrium": [0]}' >"$wms/wright.json"
expect_error "--no-stability: only with --wave" orbits --system "$wms/wright.json" --par alpha --from 1 --to 2 --no-stability --out "$wms/bad1"
[ -z "$(ls "$wms" | grep bad)" ] && ok || bad "orbits --no-stability bad input wrote files"
rm -rf "$wms"

fi  # part waves3

if part shortdelay; then
# ---- large gains with a short delay: the certified short-delay path settles every mode (exit 0, M = 0, a verdict,
# under 5 s); where a mode's listing still does not settle, the certified winding verdict is kept and the table is
# marked UNSETTLED with exit 4 (never a bare verdict next to a non-converged status)
s0=$(date +%s)
"$bin" roots --k1 1e6 --k2 0.2 --th 1.5 --tau 1e-9 >"$tmp/stiff.txt" 2>"$tmp/stiff.err" &&
    grep -q '^verdict    ring STABLE' "$tmp/stiff.txt" && grep -q 'M = 0 (converged)' "$tmp/stiff.txt" &&
    ! grep -q 'UNSETTLED' "$tmp/stiff.txt" && { [ -n "${DDEMAP_SANITIZED:-}" ] || [ $(( $(date +%s) - s0 )) -le 5 ]; } &&
    ok || bad "roots --k1 1e6 --tau 1e-9: converged with a verdict, exit 0, within 5 s: $(cat "$tmp/stiff.txt" "$tmp/stiff.err" | tail -3)"
"$bin" roots --k1 1e3 --k2 0.2 --th 1e-3 --tau 1e-3 >"$tmp/stiff2.txt" 2>"$tmp/stiff2.err"; rc=$?
if [ $rc -eq 0 ]; then
    ! grep -q 'UNSETTLED' "$tmp/stiff2.txt" && ok || bad "roots --k1 1e3 --th 1e-3 --tau 1e-3: exit 0 with an UNSETTLED table"
else
    [ $rc -eq 4 ] && grep -q '^roots      UNSETTLED (max_degree_reached)' "$tmp/stiff2.txt" && grep -q 'undecided' "$tmp/stiff2.err" &&
        ok || bad "roots --k1 1e3 --th 1e-3 --tau 1e-3: exit $rc without the UNSETTLED mark and the reason on stderr"
fi

# ---- review 12: the neuron's branch point a21 = 2.25 (det Delta(0) = (kappa - beta)^2 - a12 a21
# changes sign) is a "branch_point" in "folds", not a Hopf point; JSON solver {given, used};
# branch messages name the parameter; --ring of the nonlinear commands takes N only
r12="$tmp/r12"; mkdir -p "$r12"
cat >"$r12/neuron.json" <<'EOF'
{ "variables": ["x1", "x2"],
  "parameters": {"kappa": 0.5, "beta": -1, "a12": 1, "a21": 0.3, "tau1": 0.2, "tau2": 0.2, "taus": 1.5},
  "equations": ["-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"],
  "equilibrium": [0, 0] }
EOF
"$bin" equilibria --system "$r12/neuron.json" --par a21 --from 2.2 --to 2.35 --format json >"$r12/e.json" 2>/dev/null &&
    python3 - "$r12/e.json" <<'PY' && ok || bad "equilibria: the neuron's branch point is not a located branch_point, or the message does not name the parameter"
import json, sys
d = json.load(open(sys.argv[1])); r = d["result"]
assert d["solver"]["given"] and d["solver"]["used"], d["solver"]
assert r["hopf"] == [], r["hopf"]
assert [f["kind"] for f in r["folds"]] == ["branch_point"] and abs(r["folds"][0]["par"] - 2.25) < 1e-9, r["folds"]
assert "parameter a21" in d["message"] and "unknown 2" not in d["message"], d["message"]
PY
"$bin" hopf --system "$r12/neuron.json" --par a21 --from 0.3 --to 3 --format json >"$r12/h.json" 2>/dev/null &&
    python3 - "$r12/h.json" <<'PY' && ok || bad "hopf: solver null or the branch point listed as a Hopf point"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["solver"] is not None and "given" in d["solver"] and "used" in d["solver"], d["solver"]
assert len(d["result"]["hopf"]) == 1 and d["result"]["hopf"][0]["omega"] > 0.7, d["result"]["hopf"]
PY
"$bin" orbits --help | grep -q -- "--ring N " && ! "$bin" orbits --help | grep -q "N|inf" && ok || bad "orbits --help: --ring offers inf, which it refuses"
rm -rf "$r12"

fi  # part shortdelay

if part curves; then
# ---- orbits --wave above 200 cars: the matrix-free multipliers only with --stability (minutes per wave)
"$bin" orbits --model ov --ring 1000 --wave 100 --par headway --from 3.5 --to 2 --points 3 --quiet >"$tmp/w1000.txt" &&
    grep -q "^stability  not computed (more than 200 cars" "$tmp/w1000.txt" && ok || bad "orbits --wave --ring 1000: multipliers computed by default: $(grep stability "$tmp/w1000.txt")"
expect_error "--stability and --no-stability: expected at most one of them" orbits --model ov --ring 1000 --wave 100 --par headway --from 3.5 --to 2 --stability --no-stability
expect_error "--stability: only with --wave (expected --wave K)" orbits --model ov --ring 5 --par headway --from 3.5 --to 2 --stability

# ---- ring curves: every mode's Hopf curve (all) or only the boundary of the ring-stable region
# (envelope, seeded from the winding sweep, any N); auto = all up to 64 cars
env="$tmp/envelope"; mkdir -p "$env"
"$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:41 --k2 0.01:1:41 --ring 22 --out "$env/a" --format json >"$env/a.out" 2>/dev/null &&
    "$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:41 --k2 0.01:1:41 --ring 22 --ring-curves envelope --out "$env/e" --format json >"$env/e.out" 2>/dev/null &&
    python3 - "$env" <<'PY' && ok || bad "sweep --ring 22: auto draws every mode's curve, envelope only the ring-stable region's boundary"
import csv, json, sys
a = json.load(open(sys.argv[1] + "/a.out")); e = json.load(open(sys.argv[1] + "/e.out"))
assert a["solver"]["used"] == "modes" and e["solver"]["used"] == "winding", (a["solver"], e["solver"])
assert a["inputs"]["ring_curves"] == "all" and e["inputs"]["ring_curves"] == "envelope"
ring = lambda p: {r["branch"] for r in csv.DictReader(open(sys.argv[1] + p)) if r["subkind"] == "ring"}
na, ne = len(ring("/a-boundaries.csv")), len(ring("/e-boundaries.csv"))
assert na >= 5 and 1 <= ne < na, (na, ne)
assert e["result"]["boundaries"]["ring_curves"] == "envelope"
PY
# a ring of 10^6 cars with boundaries: accepted (the envelope by default), on the winding tables, in seconds
start=$(date +%s.%N)
"$bin" sweep --th 1.5 --tau 0.5 --k1 0.01:1:60 --k2 0.01:1:60 --ring 1000000 --out "$env/m" --format json >"$env/m.out" 2>/dev/null &&
    python3 - "$env" "$start" "$(date +%s.%N)" <<'PY' && ok || bad "sweep --ring 1000000 with boundaries: refused, slow, or without a ring arc"
import csv, json, sys
d = json.load(open(sys.argv[1] + "/m.out"))
assert d["solver"]["used"] == "winding" and d["inputs"]["ring_curves"] == "envelope", (d["solver"], d["inputs"])
rows = list(csv.DictReader(open(sys.argv[1] + "/m-boundaries.csv")))
assert any(r["subkind"] == "ring" and int(r["mode"]) > 0 for r in rows)
# in seconds, not minutes (the per-mode path would take minutes); a sanitized build (scripts/sanitize.sh
# sets DDEMAP_SANITIZED) is several times slower by design and only checks the rest
import os
assert os.environ.get("DDEMAP_SANITIZED") or float(sys.argv[3]) - float(sys.argv[2]) < 20, "took %.1f s" % (float(sys.argv[3]) - float(sys.argv[2]))
PY
"$bin" boundary --th 1.5 --tau 0.5 --k1 0.01:1 --k2 0.01:1 --ring 1000000000 --out "$env/b" >/dev/null 2>&1 && grep -q ',hopf,ring,' "$env/b.csv" &&
    ok || bad "boundary --ring 1000000000: the envelope"
cat >"$env/c.toml" <<'TOML'
model = "ovrv"
ring = 1000
ring_curves = "envelope"
fixed = { th = 1.5, tau = 0.5 }
x = { name = "k1", lo = 0.01, hi = 1, count = 30 }
y = { name = "k2", lo = 0.01, hi = 1, count = 30 }
[[panel]]
TOML
"$bin" chart "$env/c.toml" --out "$env/c" >/dev/null 2>&1 && grep -q 'id="panel1-boundaries"' "$env/c.svg" && grep -q 'ring Hopf' "$env/c.svg" &&
    ok || bad "chart with ring_curves = envelope"
expect_error "--ring-curves = 'some': expected all, envelope or auto" sweep --th 1.5 --tau 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring-curves some --out "$env/x"
expect_error "string verdict (the low-frequency string condition) needs a law that uses only the car ahead" sweep --model ccc --th 1.5 --tau 0.5 --k3 0.2 --tau2 0.5 --k1 0.1:1:4 --k2 0.1:1:4 --ring-curves envelope --out "$env/x"
expect_error "uses only the car ahead; this one uses 2 cars ahead" boundary --model ccc --th 1.5 --tau 0.5 --k3 0.2 --tau2 0.5 --k1 0.1:1 --k2 0.1:1 --ring-curves all --out "$env/x"
[ ! -e "$env/x.csv" ] && ok || bad "a refused --ring-curves wrote files"
rm -rf "$env"

fi  # part curves

if part chain; then
# outputs chain into inputs: simulate's CSV is a trace for calibrate (every follower, FILE.csv:K,
# --follower K) and a lead for simulate (P.csv:K); the round trip simulate (known cars, noise) ->
# calibrate recovers every parameter within the fit's own 95 % intervals
ch=$(mktemp -d)
"$bin" simulate --fleet "ovrv:k1=0.1,k2=0.5,th=1.4,tau=0.4,eta=8,A_min" --lead-profile oscillatory --noise 0.05:0.1 --seed 3 --out "$ch/sim" --quiet >/dev/null &&
    ok || bad "simulate with --noise"
head -1 "$ch/sim.csv" | grep -q '^time_s,car,position_m,speed_mps,gap_m$' && ok || bad "simulate's CSV header has units"
grep -q '0\.10000000000000001\|0\.45000000000000001' "$ch/sim.csv" && bad "CSV numbers not in the shortest form" || ok
"$bin" calibrate "$ch/sim.csv" --out "$ch/fits" --format json --quiet >"$ch/fits.out" 2>/dev/null && ok || bad "calibrate simulate's CSV"
python3 - "$ch/fits.out" <<'PY' && ok || bad "round trip: the true parameters lie in the 95 % intervals"
import json, sys
d = json.load(open(sys.argv[1]))
truth = {"sim-1": dict(k1=0.1, k2=0.5, th=1.4, tau=0.4, eta=8.0),
         "sim-2": dict(k1=0.052, k2=0.338, th=0.819, tau=0.948, eta=8.03)}  # A_min: the paper's Table 1
fits = {f["name"]: f for f in d["result"]["fits"]}
assert sorted(fits) == sorted(truth), sorted(fits)
for name, t in truth.items():
    assert fits[name]["status"] == "converged", fits[name]["status"]
    for p, (lo, hi) in fits[name]["ci95"].items():
        assert lo <= t[p] <= hi, (name, p, lo, hi, t[p])
        assert hi - lo < 0.25 * max(t[p], 0.2), (name, p, lo, hi)  # informative, not just wide
PY
"$bin" classify "$ch/fits.json" --format csv | grep -c '^sim-' | grep -q '^2$' && ok || bad "classify the fits of a simulated platoon"
# the fits' CSV (its header with units: k1_per_s2, lo_k1_per_s2, rmse_speed_mps) is the same car table as their JSON
head -1 "$ch/fits.csv" | grep -q '^name,k1_per_s2,k2_per_s,th_s,tau_s,eta_m,rmse_speed_mps,rmse_gap_m,' && ok || bad "calibrate CSV header with units"
"$bin" classify "$ch/fits.csv" --format csv >"$ch/c1.csv" && "$bin" classify "$ch/fits.json" --format csv >"$ch/c2.csv" &&
    cmp -s "$ch/c1.csv" "$ch/c2.csv" && ok || bad "classify reads the fits' CSV and JSON alike"
"$bin" calibrate "$ch/sim.csv:2" --format csv --quiet | grep -c '^sim-2,' | grep -q '^1$' && ok || bad "calibrate FILE.csv:K"
"$bin" calibrate "$ch/sim.csv" --follower 1 --format csv --quiet | grep -c '^sim-' | grep -q '^1$' && ok || bad "calibrate --follower"
expect_error "follower 3: expected 1 to 2" calibrate "$ch/sim.csv:3"
cp "$ch/sim.csv" "$ch/plain.csv" && python3 -c "
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
lead = {r['time_s']: r['speed_mps'] for r in rows if r['car'] == '0'}
with open(sys.argv[2], 'w') as out:
    out.write('time_s,lead_speed_mps,follower_speed_mps,gap_m\n')
    for r in rows:
        if r['car'] == '1': out.write('%s,%s,%s,%s\n' % (r['time_s'], lead[r['time_s']], r['speed_mps'], r['gap_m']))
" "$ch/sim.csv" "$ch/plain.csv"
expect_error "none of the DATA files is a platoon CSV" calibrate "$ch/plain.csv" --follower 1
"$bin" simulate --fleet A_min --lead "$ch/sim.csv:2" --out "$ch/behind" --format json --quiet >"$ch/b.json" 2>/dev/null && ok || bad "simulate --lead P.csv:K"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); assert d['inputs']['lead'].endswith('sim.csv:2')" "$ch/b.json" && ok || bad "the lead is named P.csv:K"
expect_error "name the car that leads" simulate --fleet A_min --lead "$ch/sim.csv" --out "$ch/x"
expect_error "car 7: expected 0 to 2" simulate --fleet A_min --lead "$ch/sim.csv:7" --out "$ch/x"
# impossible data: named with the line, never "converged"
python3 - "$ch" <<'PY'
import math, sys
d = sys.argv[1]
def trace(name, f):
    with open(d + "/" + name, "w") as out:
        out.write("time_s,lead_speed_mps,follower_speed_mps,gap_m\n")
        for i in range(600):
            t, row = f(i)
            out.write("%s,%s,%s,%s\n" % (t, *row))
ok = lambda i: (20 + math.sin(i / 50), 20 + 0.9 * math.sin(i / 50 - 0.5), 30 + math.cos(i / 50))
trace("neg.csv", lambda i: (i / 10, ok(i)[:2] + (-5,)))
trace("ms.csv", lambda i: (i * 100, ok(i)))
trace("fast.csv", lambda i: (i * 1e-4, ok(i)))
trace("kmh.csv", lambda i: (i / 10, (ok(i)[0] * 3.6 * 2, ok(i)[1], ok(i)[2])))
PY
expect_error "neg.csv:2: gap_m = -5 and 599 more gaps <= 0 of 600 samples: expected gaps > 0 m" calibrate "$ch/neg.csv"
expect_error "looks like milliseconds" calibrate "$ch/ms.csv"
expect_error "fast.csv: time_s: a median sampling step of 9.99.*e-05 s: expected a sampling step of 1 ms to 10 s" calibrate "$ch/fast.csv"
expect_error "divide by 3.6" calibrate "$ch/kmh.csv"
# a platoon that collides: said on stderr, the cars' lines end at their collisions, the speed and
# gap axes start at 0 (once the lines went on to -43 m and the speed axis to -5 m/s)
"$bin" simulate --fleet "B_min*8" --out "$ch/col" --format json >"$ch/col.json" 2>"$ch/col.err"
grep -q "3 cars collided (the first: car 6 at t = 73.96 s)" "$ch/col.err" && ok || bad "collisions on stderr: $(cat "$ch/col.err")"
python3 - "$ch/col.svg" "$ch/col.json" <<'PY' && ok || bad "the platoon figure after collisions"
import json, re, sys
svg = open(sys.argv[1]).read()
doc = json.load(open(sys.argv[2]))
events = {c["car"]: e["time"] for c in doc["result"]["cars"] for e in c["events"] if e["type"] == "collision"}
assert sorted(events) == [6, 7, 8], events
# the summary is of the physical part (up to each collision), and the message says so
for c in doc["result"]["cars"]:
    assert c["min_gap"] >= 0 and c["lowest_speed"] >= -1e-9, c
assert "3 cars collided (the first, car 6" in doc["message"] and "not physical" in doc["message"], doc["message"]
assert 'text-anchor="end">-' not in svg, "a negative tick on a y axis"
assert "red x: collision (car 6 at 74.0 s, car 7 at 76.4 s, car 8 at 79.4 s)" in svg
# every polyline of a collided car ends at its collision: its last x is the largest of the speed panel's lines at most
ends = {}
for m in re.finditer(r'<polyline stroke="[^"]*"[^>]*points="([^"]*)"><title>car (\d+) ', svg):
    xs = [float(p.split(",")[0]) for p in m.group(1).split()]
    ends.setdefault(int(m.group(2)), []).append(max(xs))
full = max(ends[1])
for car in events:
    assert all(e < full - 20 for e in ends[car]), (car, ends[car], full)
PY
# classify is sized before the work: 20,000 cars as rings of every length would take about 15 min
python3 -c "
import random
random.seed(1)
print('name,k1,k2,th,tau')
for i in range(20000): print('c%d,%.3f,%.3f,%.2f,%.2f' % (i, random.uniform(0.05, 0.5), random.uniform(0.1, 0.8), random.uniform(0.8, 2), random.uniform(0.1, 0.8)))
" >"$ch/many.csv"
expect_error "20000 cars: estimated run time .* is above the limit .* (--allow-large runs it anyway)" classify "$ch/many.csv" --ring inf
# a mistyped flag: the nearest flag of the command and its help
expect_error "(did you mean --tau?) (see ddemap string --help)" string --k1 0.1 --k2 0.4 --th 1.5 --tua 0.5
expect_error "(did you mean --samples?) (see ddemap classify --help)" classify A_min --sample 3
# CSV headers a spreadsheet writes, and a JSON file where a CSV is expected
printf 'Time_s,lead_speed_mps,follower_speed_mps,gap_m\n0,1,1,1\n' >"$ch/upper.csv"
expect_error "the header has 'Time_s': column names are lower case" calibrate "$ch/upper.csv"
printf 'time_s;lead_speed_mps;follower_speed_mps;gap_m\n0;1;1;1\n' >"$ch/semi.csv"
expect_error "the header is separated by ';': expected commas" calibrate "$ch/semi.csv"
printf '{"time_s": [0, 1]}\n' >"$ch/trace.json"
expect_error "trace.json is JSON: expected a CSV file with a header time_s" calibrate "$ch/trace.json"
# text that is not UTF-8 (a Latin-1 name) is refused naming its line and byte, for every reader
# (once: "internal error: [json.exception.type_error.316] invalid UTF-8 byte" from classify --format json)
printf 'name,k1,k2,th,tau\nZo\xeb,0.1,0.2,1.5,0.3\n' >"$ch/latin1.csv"
expect_error "latin1.csv:2: byte 3 (0xEB) is not UTF-8: expected UTF-8 text" classify "$ch/latin1.csv" --format json
expect_error "latin1.csv:2: byte 3 (0xEB) is not UTF-8" simulate --fleet "$ch/latin1.csv" --out "$ch/lat"
# the same byte in an inline name is shown escaped: the message itself stays valid UTF-8
"$bin" classify "$(printf 'ovrv:k1=0.1,k2=0.2,th=1.5,tau=0.3,name=Zo\xeb')" 2>"$ch/lat.err"; rc=$?
[ $rc -eq 2 ] && grep -q 'name=Zo\\xeb' "$ch/lat.err" && iconv -f UTF-8 -t UTF-8 "$ch/lat.err" >/dev/null 2>&1 && ok || bad "inline non-UTF-8 name: exit $rc, $(cat -v "$ch/lat.err")"
# numbers that underflow (1e-310) are finite: judged by their range (0 or a normal magnitude of
# at least 2.2e-308: a subnormal overflows 1 / x), not called non-finite; overflow is named
expect_error "expected a finite number (beyond the range of doubles" string --k1 1e999 --k2 0.2 --th 1.5 --tau 0.2
expect_error "k2 = 9.99999999999997e-311: expected 0 or a magnitude of at least 2.2e-308 (a subnormal number overflows 1 / x) \[1/s\]" string --k1 0.2 --k2 1e-310 --th 1.5 --tau 0.2
"$bin" string --k1 0.2 --k2 1e-300 --th 1.5 --tau 0.2 >/dev/null 2>&1 && ok || bad "string --k2 1e-300 refused"
[ ! -e "$ch/lat.csv" ] && ok || bad "an output after a refused input"
expect_error "expected a name without control characters" classify "ovrv:name=a$(printf '\001')b,k1=0.1,k2=0.2,th=1.5,tau=0.3"
printf 'name,k1,k2,th,tau\nZo\xc3\xab,0.1,0.2,1.5,0.3\n' >"$ch/utf8.csv"
"$bin" classify "$ch/utf8.csv" --format json >"$ch/utf8.json" && grep -q "\"name\": \"Zo$(printf '\303\253')\"" "$ch/utf8.json" && ok || bad "a UTF-8 name through classify's JSON"
# numbers far outside what the model means: a lead at 1e18 m/s is refused before the work (once
# an internal error from a NaN in the figure); a marker at k2 = -1e308 is drawn on the window's
# edge as any marker outside it, with finite coordinates
printf 'time_s,lead_speed_mps\n0,1e18\n1,20\n' >"$ch/fastlead.csv"
expect_error "fastlead.csv:2: lead_speed_mps = 1e+18: expected 0 to 100 m/s" simulate --fleet A_min --lead "$ch/fastlead.csv" --out "$ch/fl"
# sweep --mark: the cars of a table as labelled markers, a car of another (tau, th) named on stderr
"$bin" sweep --th 2 --tau 0.2 --k1 0.01:0.4:20 --k2 0.01:1:20 --mark "$(dirname "$0")/../../examples/mycars.csv" --out "$ch/mk" --quiet 2>"$ch/mk.err" &&
    grep -q ">Sedan<" "$ch/mk.svg" && grep -q "SUV has tau = 0.5 (the chart's 0.2), th = 1.8 (the chart's 2)" "$ch/mk.err" && xmllint --noout "$ch/mk.svg" &&
    ok || bad "sweep --mark: $(cat "$ch/mk.err")"
printf 'time_s,lead_speed_mps\n-1e308,20\n0,22\n' >"$ch/oldlead.csv"  # once a nan in the CSV (exit 3)
expect_error "time -1e+308 at sample 1: expected -1e9 to 1e9 s" simulate --fleet A_min --lead "$ch/oldlead.csv" --out "$ch/fl"
sed -e 's/^k2 = 0.2$/k2 = -1e308/' -e 's/count = 101/count = 5/' "$(dirname "$0")/../../maps/paper.toml" >"$ch/far.toml"
grep -q "k2 = -1e308" "$ch/far.toml" || bad "the far marker's spec"
"$bin" chart "$ch/far.toml" --out "$ch/far" >/dev/null 2>&1 && ! grep -qi "nan\|inf" "$ch/far.svg" && grep -q "paper example (outside)" "$ch/far.svg" \
    && ok || bad "a marker at k2 = -1e308"
# a system file is sized before it is read: an 839 MB file (sparse on disk: nothing to read) is
# refused at once, not after parsing (a 1.15 GB dense file once took 22 s and 1.15 GB to refuse)
truncate -s 800M "$ch/huge.json"
start_ns=$(date +%s%N)
expect_error "huge.json (839 MB of JSON): estimated memory 2.52 GB is above the limit 2 GB (--allow-large runs it anyway)" roots --system "$ch/huge.json"
[ $(( ($(date +%s%N) - start_ns) / 1000000 )) -lt 5000 ] && ok || bad "the huge system file took more than 5 s to refuse"
rm -f "$ch/huge.json"
# a dense file below that limit but of too many states (100 MB, 5000 states) is refused from its
# "dimension" by a text search, before any tokenisation (once 4.4 s and 935 MB; the text alone is 100 MB)
python3 -c "
import sys
row = '[' + ','.join(['0'] * 5000) + ']'
mat = '[' + ','.join([row] * 5000) + ']'
sys.stdout.write('{\"dimension\": 5000, \"delays\": [1.0], \"A0\": %s, \"A\": [%s]}' % (mat, mat))" >"$ch/dense5000.json"
/usr/bin/time -f "%M" -o "$ch/dense5000.mem" "$bin" roots --system "$ch/dense5000.json" >/dev/null 2>"$ch/dense5000.err"; rc=$?
[ $rc -eq 2 ] && grep -q "a 5000-state system with 1 delay: estimated memory 2.4 GB is above the limit" "$ch/dense5000.err" && [ "$(tail -1 "$ch/dense5000.mem")" -lt 400000 ] &&
    ok || bad "the 5000-state dense file: exit $rc, $(head -1 "$ch/dense5000.err"), $(tail -1 "$ch/dense5000.mem") KB"
rm -f "$ch/dense5000.json"
# a search bounded only by its step count stops at the run-time limit (10 min; 1 s here through
# the test hook), undecided with exit 4, and says which bound stopped it
DDEMAP_TEST_TIME_LIMIT=1 "$bin" roots --fleet-pattern A_min,B_min --ring 20000 --solver sparse --format json >"$ch/tl.json" 2>"$ch/tl.err"
rc=$?
[ $rc -eq 4 ] && grep -q "stopped at the run-time limit of 1 s after step [0-9]* of at most [0-9]* (--allow-large lets it run on)" "$ch/tl.err" \
    && grep -q '"status": "cancelled"' "$ch/tl.json" && ok || bad "the run-time limit of a root search: exit $rc, $(cat "$ch/tl.err")"
# ... and was sized before it started: its estimate (minutes) is announced first
head -1 "$ch/tl.err" | grep -q "^ddemap: roots: note: the sparse root search of a ring of 20000 cars (about [0-9]* Arnoldi shifts of .* s each: sparse LU of .*): estimated run time .* min$" \
    && ok || bad "the root search's estimate before it starts: $(head -1 "$ch/tl.err")"
# a search predicted above the limit is refused at once (exit 2): 10^5 cars on the sparse path,
# about 40 min (BENCHMARKS.md compares the prediction with measured runs)
start_ns=$(date +%s%N)
"$bin" roots --fleet-pattern A_min,B_min --ring 100000 --solver sparse >/dev/null 2>"$ch/big.err"; rc=$?
[ $rc -eq 2 ] && [ "$(wc -l <"$ch/big.err")" -eq 1 ] &&
    grep -q "^ddemap: error: the sparse root search of a ring of 100000 cars (about [0-9]* Arnoldi shifts of .*): estimated run time .* is above the limit 10 min (--allow-large runs it anyway)$" "$ch/big.err" &&
    [ $(( ($(date +%s%N) - start_ns) / 1000000 )) -lt 10000 ] && ok || bad "the 10^5-car sparse ring: exit $rc, $(cat "$ch/big.err")"
# 10^6 cars: the estimate takes UMFPACK's bound instead of factorising (one LU of it ran over a
# minute inside the estimate) and refuses on memory
start_ns=$(date +%s%N)
"$bin" roots --fleet-pattern A_min,B_min --ring 1000000 --solver sparse >/dev/null 2>"$ch/big6.err"; rc=$?
[ $rc -eq 2 ] && grep -q "^ddemap: error: the sparse root search of a ring of 1000000 cars (.*UMFPACK's symbolic upper bound.*): estimated memory .* GB is above the limit 2 GB" "$ch/big6.err" &&
    [ $(( ($(date +%s%N) - start_ns) / 1000000 )) -lt 30000 ] && ok || bad "the 10^6-car sparse ring: exit $rc, $(cat "$ch/big6.err")"
# the second fuzzing run's findings (issue: hostile input): a subnormal delay (1/tau overflows)
# is refused wherever a parameter is read, never an internal error
expect_error "tau = 9.99988867182683e-321: expected 0 or a magnitude of at least 2.2e-308 (a subnormal number overflows 1 / x) \[s\]" string --k1 0.2 --k2 0.3 --th 1.5 --tau 1e-320
expect_error "tau = 4.94065645841247e-324: expected 0 or a magnitude of at least 2.2e-308" classify ovrv:k1=0.2,k2=0.6,th=2,tau=4.9e-324,eta=8
expect_error "tau = 9.99988867182683e-321: expected 0 or a magnitude of at least 2.2e-308" hopf --model ov --ring 3 --tau 1e-320 --par headway --from 1.2 --to 3
printf '{"variables": ["x"], "parameters": {"beta": 2, "gamma": 1, "n": 9.65, "tau": 1e-320}, "equations": ["beta*x(t - tau)/(1 + x(t - tau)^n) - gamma*x"], "equilibrium": [1]}' >"$ch/subnormal.json"
expect_error "subnormal.json: parameters.tau: 9.99988867182683e-321: expected 0 or a finite magnitude from 1e-100 to 1e100" equilibria --system "$ch/subnormal.json" --par beta --from 1 --to 3
# an endless stream is refused after 1 GB, not read for ever
expect_error "'/dev/zero': more than 1 GB of text: expected an input file of at most 1 GB" roots --system /dev/zero
# a gap weight that overflows the objective; a misspelt key of a chart axis
expect_error "gap weight = 1e+308: expected a number from 0 to 1e6" calibrate "$(dirname "$0")/../../examples/openacc_runs.csv" --gap-weight 1e308
printf 'title = "t"\n[x]\nname = "k1"\nlo = 0.1\nhi = 1\ncount = 5\ncout = 7\n[y]\nname = "k2"\nlo = 0.1\nhi = 1\ncount = 5\n[[panel]]\nth = 1.5\ntau = 0.1\n' >"$ch/axis.toml"
expect_error "axis.toml:7: x: unknown key 'cout': expected name, lo, hi, count" chart "$ch/axis.toml" --out "$ch/axis"
# a chart reports its grid rows (not only finished panels): a one-panel chart of 1.1 million
# points once ran 25 s without a line
DDEMAP_TEST_PROGRESS_AT_ONCE=1 "$bin" chart "$(dirname "$0")/../../maps/classification.toml" --out "$ch/rows" >/dev/null 2>"$ch/rows.err"
grep -q "^ddemap: chart: grid rows of all panels 1/" "$ch/rows.err" && ok || bad "chart progress by rows: $(head -2 "$ch/rows.err")"
# an output that is a link into /proc is found unwritable before the work (once: after it; access()
# says yes to root there, a file made and dropped in the folder says no)
ln -s /proc/self/status "$ch/proc.csv"
expect_error "proc.csv': the folder '/proc/self' is not writable" classify A_min --out "$ch/proc"
# a value given as '' (an empty shell variable) is bad input, never taken as absent
expect_error "--cars = '': expected a value (see ddemap roots --help)" roots --fleet-pattern A_min --cars ''
expect_error "--ring = '': expected a value" roots --fleet-pattern A_min --ring ''
expect_error "--tau = '': expected a value" string --k1 0.2 --k2 0.4 --th 1.5 --tau ''
for cmd in "classify A_min" "simulate --fleet A_min" "growth --fleet A_min --followers 2" "string --k1 0.2 --k2 0.4 --th 1.5 --tau 0.5"; do
    expect_error "--out = '': expected an output prefix" $cmd --out ''
done
rm -rf "$ch"
# the third fuzzing run (13,264 cases): a delay of 2^31 leaves the roots undecided: no -inf in
# any output, "undecided" in the table, exit 4 (it was an internal error); a covariance of 1e308
# and a repeated run are bad input; a note about the input is not printed before an error;
# rings too long for classify and for every mode's curves are sized and refused up front
echo '{"variables":["y"],"parameters":{"alpha":1},"equations":["-alpha*y(t - 2147483648)*(1 + y)"]}' >"$tmp/bigdelay.json"
"$bin" equilibria --system "$tmp/bigdelay.json" --par alpha --from 0.5 --to 0.6 --format csv >"$tmp/bd.csv" 2>/dev/null; rc=$?
[ $rc -eq 4 ] && grep -q '^point,0.5,0,,,,,max_degree_reached$' "$tmp/bd.csv" && ! grep -qi 'inf' "$tmp/bd.csv" && ok || bad "equilibria with a 2^31 delay: rc $rc $(head -3 "$tmp/bd.csv")"
"$bin" equilibria --system "$tmp/bigdelay.json" --par alpha --from 0.5 --to 0.6 2>/dev/null | grep -q '^  0.5  *0  *-  *-  *undecided$' && ok || bad "equilibria table: undecided points"
printf 'name,k1,k2,th,tau,eta,cov_k1_k1,cov_k1_k2,cov_k1_th,cov_k1_tau,cov_k1_eta,cov_k2_k2,cov_k2_th,cov_k2_tau,cov_k2_eta,cov_th_th,cov_th_tau,cov_th_eta,cov_tau_tau,cov_tau_eta,cov_eta_eta\ns,0.05,0.3,1.5,0.4,8,1e308,0,0,0,0,1e-4,0,0,0,1e-4,0,0,1e-4,0,1e-2\n' >"$tmp/cov1e308.csv"
expect_error "cov1e308.csv:2: column 'cov_k1_k1' = 1e308: expected a magnitude at most 1e6" classify "$tmp/cov1e308.csv" --out "$tmp/cov"
printf 'car,file,role\nCarA,t1.csv,train\nCarA,t1.csv,test\n' >"$tmp/dupruns.csv"
expect_error "dupruns.csv:3: car 'CarA' with file 't1.csv' is listed before (role train): expected each run once" calibrate --runs "$tmp/dupruns.csv" --report "$tmp/rep"
expect_error "length = 10000000 m: expected at least" roots --fleet A_min,C_max --ring 999999 --length 1e7
expect_error "14 cars in rings of 1000000 cars: estimated run time" classify --ring 1000000
expect_error "a 3 x 3 grid of a 1000000-car ring: estimated run time" sweep --ring 1000000 --k1 0.01:1:3 --k2 0.01:1:3 --th 1.5 --tau 0.1 --ring-curves all --out "$tmp/sw"
# the fourth run's timeouts: a delay written in an equation has a linear file's range (1e308 made
# the dense eigenvalues crawl on subnormal numbers, 9 s a point); the continuations' roots and
# the per-mode ring path are sized before they start: refused above the limit, else announced
echo '{"variables":["x"],"parameters":{"p":-1},"equations":["x*(p - x(t - 1e308))"]}' >"$tmp/hu308.json"
expect_error "hu308.json: equations: a delay of 1e+308: expected a delay of at most 1e100" equilibria --system "$tmp/hu308.json" --par p --from -1 --to 3
printf '{"variables": ["x1", "x2"], "parameters": {"kappa": 0.5, "beta": -1, "a12": 1, "a21": 1e5, "tau1": 0.2, "tau2": 0.2, "taus": 1.5}, "equations": ["-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))", "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"]}' >"$tmp/coupled.json"
expect_error "the roots at 24 points of the equilibrium branch and about 10 slices like it (dense root searches of about .* each, one or two per point: the eigenvalues of two collocation degrees, 802 and 1.2e+03 rows): estimated run time .* min is above the limit 10 min (--allow-large runs it anyway)" \
    bistability --system "$tmp/coupled.json" --par kappa --from 0.1 --to 2 --par2 beta --from2 -2 --to2 0 --points 50 --rows 8 --out "$tmp/bi"
printf '{"variables": ["x1", "x2"], "parameters": {"a": 0.5, "b": 0.6, "d": 0.05, "tau": 1e19}, "equations": ["x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"]}' >"$tmp/duffing19.json"
timeout 3 "$bin" hopf --system "$tmp/duffing19.json" --par a --from 0.1 --to 2 >/dev/null 2>"$tmp/duffing19.err"
head -1 "$tmp/duffing19.err" | grep -q "^ddemap: hopf: note: the roots at 24 points of the branch (dense root searches of about .* each, one or two per point: .*): estimated run time .* min$" &&
    ok || bad "hopf sized before its roots: $(head -1 "$tmp/duffing19.err")"
timeout 3 "$bin" string --ring 1000000 --k1 0.2 --k2 0.3 --th 1.5 --tau 0.2 --ring-method modes >/dev/null 2>"$tmp/modes.err"
head -1 "$tmp/modes.err" | grep -q "^ddemap: string: note: the 500001 modes of a ring of 1000000 cars (dense root searches of about .* each: .*): estimated run time .* min$" &&
    ok || bad "the per-mode ring path sized before it starts: $(head -1 "$tmp/modes.err")"
fi  # part chain

if part killset; then
# ---- output sets under SIGKILL at every system call of their final moves (issue 34) ----------
# strace kills the writer at the N-th call of one of the calls that place a set (N = 1, 2, ...
# until a run is no longer killed). Right after the kill the four files of a sweep are all old,
# or all new, or mixed with the writer's journal beside them; after the next ddemap run that
# reads from or writes into the folder they are all old or all new, and no hidden file is left.
command -v strace >/dev/null || { bad "strace is missing (scripts/install-deps.sh installs it)"; }
# a machine that forbids ptrace (some containers) cannot run this part: said, not hidden
if ! strace -f -o /dev/null true 2>/dev/null; then
    echo "SKIP: killset: strace cannot trace here (ptrace not permitted): $(strace -o /dev/null true 2>&1 | head -1)"
    killset_skip=1
fi
ks="$tmp/killset"
mkdir -p "$ks"
sweep_set() { "$bin" sweep --th "$1" --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$2/x" >/dev/null 2>&1; }
mkdir -p "$ks/old" "$ks/new"
sweep_set 1.5 "$ks/old"
sweep_set 1.2 "$ks/new"
printf 'name,k1,k2,th,tau\none,0.2,0.4,1.5,0.3\n' >"$ks/old/cars.csv"
# the state of the set in folder $1: old, new or mixed (the JSON's timings left out)
set_state() {
    local o=0 n=0 f
    for f in x.csv x.svg x-boundaries.csv x.json; do
        if cmp -s <(grep -v -E '"seconds"|per_second' "$1/$f" 2>/dev/null) <(grep -v -E '"seconds"|per_second' "$ks/old/$f"); then o=$((o + 1)); fi
        if cmp -s <(grep -v -E '"seconds"|per_second' "$1/$f" 2>/dev/null) <(grep -v -E '"seconds"|per_second' "$ks/new/$f"); then n=$((n + 1)); fi
    done
    if [ $o -eq 4 ]; then echo old; elif [ $n -eq 4 ]; then echo new; else echo "mixed($o old, $n new)"; fi
}
kills=0
calls="renameat2 renameat linkat unlinkat fsync"
[ -z "${killset_skip:-}" ] || calls=""
for call in $calls; do
    for n in $(seq 1 40); do
        rm -rf "$ks/k"
        cp -r "$ks/old" "$ks/k"
        # (LeakSanitizer cannot run under ptrace: off for these runs of a sanitized build)
        ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" strace -f -o /dev/null -e trace="$call" -e inject="$call":signal=KILL:when="$n" \
            "$bin" sweep --th 1.2 --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$ks/k/x" >/dev/null 2>&1
        rc=$?
        if [ $rc -ne 137 ]; then
            [ $rc -eq 0 ] && [ "$(set_state "$ks/k")" = new ] && ok || bad "$call #$n: not killed, exit $rc, set $(set_state "$ks/k")"
            break
        fi
        kills=$((kills + 1))
        state=$(set_state "$ks/k")
        journal=$(ls -A "$ks/k" | grep -c '^\.ddemap-set-.*\.journal$')
        [ "$state" = old ] || [ "$state" = new ] || [ "$journal" -ge 1 ] && ok || bad "$call #$n: killed, the set is $state and no journal"
        # the next run: a reader of a file in the folder (odd N) or a writer into it (even N)
        if [ $((n % 2)) -eq 1 ]; then
            "$bin" classify "$ks/k/cars.csv" --format csv >/dev/null 2>&1
        else
            "$bin" classify A_min --out "$ks/k/c" >/dev/null 2>&1
        fi
        state=$(set_state "$ks/k")
        [ "$state" = old ] || [ "$state" = new ] && ok || bad "$call #$n: after the next run the set is $state"
        left=$(ls -A "$ks/k" | grep -v -E '^(x\.csv|x\.svg|x-boundaries\.csv|x\.json|cars\.csv|c\.csv|c\.svg|c\.json)$' | tr '\n' ' ')
        [ -z "$left" ] && ok || bad "$call #$n: left behind after the next run: $left"
    done
done
# the set of 4 files has 4 moves, a journal renamed in, its removal and 4 old contents dropped:
# every one of those calls was a kill point
[ -n "${killset_skip:-}" ] || { [ $kills -ge 20 ] && ok || bad "only $kills kill points"; }
rm -rf "$ks"
fi  # part killset

if part design; then
# design: the nearest string-stable gains of C_max, written as CSV and JSON
"$bin" design C_max --objective nearest --out "$tmp/des/c" >"$tmp/des.txt" 2>"$tmp/des.err" && ok || bad "design C_max nearest: exit $?"
json_has "$tmp/des/c.json" gains objective change attenuation_margin margin_met infeasibility_proof verdicts initial starts && ok || bad "design json keys"
python3 - "$tmp/des/c.json" "$tmp/des/c.csv" <<'PY' && ok || bad "design: the JSON and the CSV say the same, the design is certified string stable"
import csv, json, sys
d = json.load(open(sys.argv[1]))
r = d["result"]
assert d["status"] == "converged", d["message"]
assert r["verdicts"]["string_stable"] is True and r["initial"]["verdicts"]["string_stable"] is False
assert r["attenuation_margin"] >= 0.1 and r["margin_met"] is True and r["infeasibility_proof"] is None
rows = list(csv.DictReader(open(sys.argv[2])))
assert [x["point"] for x in rows] == ["car", "design"]
assert float(rows[1]["k1_per_s2"]) == r["gains"]["k1"] and float(rows[1]["k2_per_s"]) == r["gains"]["k2"]  # round-trip exact
assert rows[1]["string_stable"] == "true" and rows[0]["string_stable"] == "false"
PY
grep -q "^string (L2) *UNSTABLE *STABLE$" "$tmp/des.txt" && ok || bad "design table: the L2 verdicts before and after"
# the figure: the car and the design on one (k1, k2) chart (th held), on two when th is designed too
xmllint --noout "$tmp/des/c.svg" && grep -q ">C_max<" "$tmp/des/c.svg" && grep -q ">C_max, designed<" "$tmp/des/c.svg" &&
    ! grep -q "the design&#39;s chart" "$tmp/des/c.svg" && ok || bad "design figure (k1, k2 free)"
"$bin" design C_max --free k1,k2,th --objective nearest --out "$tmp/des/t" --quiet >/dev/null &&
    xmllint --noout "$tmp/des/t.svg" && grep -q "the car&#39;s chart" "$tmp/des/t.svg" && grep -q "the design&#39;s chart" "$tmp/des/t.svg" &&
    ok || bad "design figure (k1, k2, th free): two panels"
# no gains of the box are string stable (th < tau): the proof, exit 0, the gains unchanged
"$bin" design A_min --objective nearest --format json >"$tmp/des2.json" && ok || bad "design A_min nearest: exit $?"
python3 - "$tmp/des2.json" <<'PY' && ok || bad "design A_min: the proof of infeasibility"
import json, sys
d = json.load(open(sys.argv[1]))
r = d["result"]
assert d["status"] == "converged" and "no gains within the bounds are string stable" in d["message"], d["message"]
assert r["infeasibility_proof"] and r["gains"] == {"k1": 0.052, "k2": 0.338}, r["gains"]
PY
# a car of a file, inline, and bad input: one line, exit 2, nothing on stdout
expect_code 0 design "$(dirname "$0")/../../examples/mycars.csv:SUV" --free k1,k2,th --starts 2 --format csv
expect_code 0 design ovrv:k1=0.5,k2=0.5,th=1,tau=0 --objective abscissa --bounds k1=0.1:1,k2=0.01:2 --starts 1
expect_error "expected sup-gamma, peak, abscissa or nearest" design C_max --objective fastest
expect_error "expected one car" design A_min,C_max
expect_error "expected NAME=LO:HI" design C_max --bounds k1=0.1
expect_error "which is not free" design C_max --bounds th=1:2
expect_error "expected lower <= upper" design C_max --bounds k1=0.5:0.1
expect_error "expected LO < HI" design C_max --bounds k1=0.1:0.1
expect_error "the law's domain" design C_max --bounds k1=-1:0.1
expect_error "free parameter 'gain'" design C_max --free k1,gain
expect_error "expected a number of seconds" design C_max --margin 0
expect_error "expected an integer 1..64" design C_max --starts 0
expect_error "one per free parameter" design C_max --objective nearest --weights 1
expect_error "computable range" design ovrv:k1=5,k2=5,th=1,tau=2
expect_error "CAR is required" design
# a box nine decades wide: the car's own values start the search (not a point a thousandth of
# the width inside), the differences stay inside the law's domain, the same nearest gains
"$bin" design C_max --objective nearest --bounds k2=1e-9:1e9 --format json >"$tmp/des3.json" && ok || bad "design with a wide box: exit $?"
python3 - "$tmp/des/c.json" "$tmp/des3.json" <<'PY' && ok || bad "design: a wide box gives the same nearest gains, not at a bound"
import json, sys
a, b = (json.load(open(f))["result"] for f in sys.argv[1:])
assert b["at_bound"] == [], b["at_bound"]
for k in ("k1", "k2"):
    assert abs(a["gains"][k] - b["gains"][k]) <= 1e-7 * abs(a["gains"][k]), (a["gains"], b["gains"])
PY
expect_error "expected a number of seconds in \[0.001, 1000\]" design C_max --margin 1e-12
# --robust: refused without a covariance; on a fit with one, the worst margin over its ellipsoid meets --margin
expect_error "--robust: the car C_max has no covariance" design C_max --robust
python3 - "$tmp/rfit.csv" <<'PY'
import sys
names = ["k1", "k2", "th", "tau", "eta"]
cols = ["cov_%s_%s" % (names[i], names[j]) for i in range(5) for j in range(i, 5)]
cov = dict.fromkeys(cols, 0.0)
cov.update(cov_tau_tau=0.05 ** 2, cov_th_th=0.1 ** 2, cov_th_tau=0.5 * 0.1 * 0.05)
open(sys.argv[1], "w").write("name,k1,k2,th,tau,eta," + ",".join(cols) + "\nfit,0.05,0.3,1.5,0.4,10," + ",".join(repr(cov[c]) for c in cols) + "\n")
PY
"$bin" design "$tmp/rfit.csv" --objective nearest --robust --starts 2 --format json >"$tmp/rob.json" 2>/dev/null && ok || bad "design --robust: exit $?"
python3 - "$tmp/rob.json" <<'PY' && ok || bad "design --robust: met, the worst margin at least --margin, its steps"
import json, sys
d = json.load(open(sys.argv[1]))
r = d["result"]
assert d["inputs"]["robust"] is True
assert r["robust"]["met"] is True and len(r["robust"]["steps"]) >= 2, r["robust"]
assert r["robust"]["steps"][0]["scenario"] == {} and r["robust"]["steps"][-1]["worst_margin"] >= 0.1 * (1 - 1e-6)
assert r["uncertainty"]["worst_case"]["design"]["attenuation_margin"] >= 0.1 * (1 - 1e-6)
PY
# classify prints the attenuation margin m*: its sign is the string verdict, the design's meets the margin
"$bin" classify "$(dirname "$0")/../../examples/mycars.csv",A_min,C_max --format json >"$tmp/desc.json" && ok || bad "classify with m*: exit $?"
python3 - "$tmp/desc.json" <<'PY' && ok || bad "classify: attenuation_margin > 0 exactly for the string-stable cars"
import json, sys
v = json.load(open(sys.argv[1]))["result"]["vehicles"]
assert len(v) == 5
for c in v:
    assert (c["attenuation_margin"] > 0) == c["string_stable"], c
PY
fi  # part design

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
