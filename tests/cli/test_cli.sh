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
    head -1 "$tmp/s1.csv" | grep -q '^k1,k2,spectral_abscissa,unstable_roots,sup_gamma,omega_peak,plant_stable,ring_stable,string_stable' && ok || bad "sweep CSV header"
    xmllint --noout "$tmp/s1.svg" && ok || bad "sweep SVG is not valid XML"
    grep -q '<text' "$tmp/s1.svg" && grep -q 'id="panel1-boundaries"' "$tmp/s1.svg" && ok || bad "sweep SVG layers"
    json_has "$tmp/s1.json" model fixed x y ring degree seconds version && ok || bad "sweep JSON keys"
    head -1 "$tmp/s1-boundaries.csv" | grep -q '^branch,kind,subkind,mode,k1,k2,omega' && ok || bad "boundaries CSV header"
else
    bad "sweep exit status"
fi
expect_error "exactly two swept" sweep --th 1.5 --tau 0.5 --k1 0.01:1:30 --out "$tmp/x"
expect_error "LO:HI:COUNT" sweep --th 1.5 --tau 0.5 --k1 0.01:1:1 --k2 0:1:4 --out "$tmp/x"
expect_error "k1 = -1" sweep --th 1.5 --tau 0.5 --k1 -1:1:4 --k2 0:1:4 --out "$tmp/x"
: >"$tmp/afile"
expect_error "does not exist" sweep --th 1.5 --tau 0.5 --k1 0:1:4 --k2 0:1:4 --out "$tmp/afile/x"
[ ! -e "$tmp/x.csv" ] && ok || bad "a failed sweep left output"

# boundary
if "$bin" boundary --th 1.5 --tau 0.5 --k1 0.01:1 --k2 0.01:1 --seed-grid 21 --out "$tmp/b" >/dev/null; then
    grep -q ',hopf,ring,' "$tmp/b.csv" && grep -q ',string,lowfreq,' "$tmp/b.csv" && ok || bad "boundary kinds"
else
    bad "boundary exit status"
fi
expect_error "LO:HI" boundary --th 1.5 --tau 0.5 --k1 0.01:1:5 --k2 0.01:1 --out "$tmp/b2.csv"

# classify: built in, from a file, errors naming line and column
"$bin" classify --format csv >"$tmp/c.csv" && [ "$(grep -c ',false,false,false,' "$tmp/c.csv")" -eq 0 ] && ok || bad "classify csv"
[ "$(tail -n +2 "$tmp/c.csv" | wc -l)" -eq 14 ] && ok || bad "classify rows"
[ "$(cut -d, -f9 "$tmp/c.csv" | grep -c false)" -eq 14 ] && ok || bad "all 14 string unstable"
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
expect_error "bad2.csv:1: missing column 'tau'" classify "$tmp/bad2.csv"
printf 'name,k1,k2,th,tau
A,0.1,0.2,1
' >"$tmp/bad3.csv"
expect_error "bad3.csv:2: 4 fields, expected 5" classify "$tmp/bad3.csv"
printf 'name,k1,k2,th,tau
A,-0.1,0.2,1,0.3
' >"$tmp/bad4.csv"
expect_error "bad4.csv:2: k1 = -0.1" classify "$tmp/bad4.csv"
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
    head -1 "$tmp/sim.csv" | grep -q '^time,car,position,speed,gap$' && ok || bad "simulate CSV header"
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
"$bin" growth --format csv >"$tmp/g.csv" && head -1 "$tmp/g.csv" | grep -q '^name,position,speed_drop,amplification,min_gap,failure$' && ok || bad "growth csv"

# calibrate: an excerpt of real data (tests/data), JSON keys, the table goes into classify
excerpt="$(dirname "$0")/../data/openacc_excerpt_rav4_to_etron.csv"
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
python3 - >"$tmp/cyc.json" <<'PY'
import json
n = 20
print(json.dumps({"dimension": n, "delays": [1.0, 0.4], "A0": {"triplets": [[i, i, -1.0] for i in range(n)]},
                  "A": [{"triplets": [[i, (i - 1) % n, 0.9] for i in range(n)]}, {"triplets": [[i, (i + 1) % n, 0.3] for i in range(n)]}]}))
PY
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
expect_error "fleet pattern entry 'Q'" roots --fleet-pattern "A_min,Q" --ring 4
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
expect_error "react only to the car ahead" roots --fleet "$tmp/fleet.csv" --solver product
expect_error "the product path has no collocation degree" roots --fleet-pattern "A_min,E_min" --ring 6 --solver product --degree 20
"$bin" roots --fleet-pattern "A_min,E_min" --ring 6 --degree 20 --format json | python3 -c "import json,sys; sys.exit(0 if json.load(sys.stdin)['result']['degree'] == 20 else 1)" && ok || bad "--degree selects a collocation path"
expect_error "expected at least" roots --fleet-pattern "A_min" --ring 4 --length 5
if "$bin" mix --x E_min --y A_min --ring 10 --p 0:1:3 --out "$tmp/mix" >/dev/null && [ -s "$tmp/mix.csv" ] && xmllint --noout "$tmp/mix.svg"; then
    python3 - "$tmp/mix.csv" <<'PY' && ok || bad "mix csv"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [r["x_cars"] for r in rows] == ["0", "5", "10"], rows
assert all(r["status"] == "converged" for r in rows), rows
PY
else bad "mix"; fi
expect_error "p = 1.5" mix --x E_min --y A_min --ring 10 --p 0:1.5:3 --out "$tmp/mix2"
[ ! -e "$tmp/mix2.csv" ] && ok || bad "mix wrote output after an error"

# exit codes (README "Exit codes"): 0 success, 2 bad input, 3 internal error, 4 not converged, 5 write failed
expect_code() {  # expect_code CODE args...
    local code="$1"; shift
    "$bin" "$@" >"$tmp/o.txt" 2>"$tmp/e.txt"
    local rc=$?
    [ $rc -eq "$code" ] && ok || bad "exit $rc (expected $code) for: $*: $(cat "$tmp/e.txt")"
}
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
"$bin" roots --system "$tmp/cyc.json" --degree 2 --count 10 | grep -q 'UNDECIDED' && ok || bad "not converged: the table says undecided"
# the folder is fine, but PREFIX.json is a folder: the write fails after the computation, nothing half-written
mkdir -p "$tmp/w.json"
expect_code 5 classify --out "$tmp/w"
grep -q "cannot write" "$tmp/e.txt" && ok || bad "write failure message"
[ ! -e "$tmp/w.csv" ] && ! ls "$tmp" | grep -q '\.part$' && ok || bad "a failed write left files"

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

# help on every command, with units
for c in roots string sweep boundary; do
    if "$bin" $c --help >"$tmp/h.txt" && grep -q '1/s^2' "$tmp/h.txt" && grep -q -- '--tau' "$tmp/h.txt"; then ok; else bad "$c --help"; fi
done
"$bin" --help >/dev/null && ok || bad "--help"

# Bounded and visible (README "Limits and progress"): sizes refused before any work, no NaN or inf
expect_error "estimated" sweep --th 1.5 --tau 0.5 --k1 0:1:5000 --k2 0:1:5000 --out "$tmp/big"
expect_error "memory" sweep --th 1.5 --tau 0.5 --k1 0:1:100000 --k2 0:1:100000 --out "$tmp/big"   # was std::bad_alloc, exit 3
[ ! -e "$tmp/big.csv" ] && ok || bad "a refused sweep wrote a file"
expect_error "1e+09 s" simulate --fleet A_min --t-end 1e9 --out "$tmp/simbig"                      # was exit 3 (vector max_size)
expect_error "more than this machine has" simulate --fleet A_min --t-end 1e9 --allow-large --out "$tmp/simbig"
python3 -c "print('time_s,lead_speed_mps'); print('0,20'); print('100000,20')" >"$tmp/longlead.csv"
expect_error "estimated output files" simulate --fleet A_min --lead "$tmp/longlead.csv" --out "$tmp/simlong"   # was 340 MB written
printf '{"dimension": 20000, "delays": [1], "A0": {"triplets": []}, "A": [{"triplets": [[0, 0, -1]]}]}\n' >"$tmp/dim20000.json"
expect_error "20000-state system" roots --system "$tmp/dim20000.json"
printf '{"dimension": 2, "delays": [1], "A0": [[1e300, 1e-300], [1e-300, -1e300]], "A": [[[1e-300, 1e300], [0, 1]]]}\n' >"$tmp/range.json"
expect_error "1e-100 to 1e100" roots --system "$tmp/range.json"                # was a Schur decomposition failure
printf 'title = "t"\nring = 22\nfixed = { th = 1.5, tau = 0.5 }\npanel_width = 1e308\nx = { name = "k1", lo = 0.01, hi = 1, count = 5 }\ny = { name = "k2", lo = 0.01, hi = 1, count = 5 }\n' >"$tmp/wide.toml"
expect_error "panel_width" chart "$tmp/wide.toml" --out "$tmp/wide"
sed 's/panel_width = 1e308/panel_width = -300/' "$tmp/wide.toml" >"$tmp/neg.toml"
expect_error "panel_width" chart "$tmp/neg.toml" --out "$tmp/neg"
# a constant lead (a flat speed plot): the figure's tick loop once never ended
python3 -c "print('time_s,lead_speed_mps'); print('0,20'); print('50,20')" >"$tmp/flat.csv"
timeout 60 "$bin" simulate --fleet A_min --lead "$tmp/flat.csv" --out "$tmp/flat" >/dev/null 2>&1 && xmllint --noout "$tmp/flat.svg" && ok || bad "simulate behind a constant lead"
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
printf 'name,k1,k2,th,tau\nX,1000,1000,1.5,0.5\n' >"$tmp/wild.csv"
"$bin" simulate --fleet "$tmp/wild.csv" --out "$tmp/wild" --format json >"$tmp/o.txt" 2>"$tmp/e.txt"
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

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
