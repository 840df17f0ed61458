#!/usr/bin/env bash
# Reference checks of `hopf` and `orbits` against DDE-BIFTOOL (GitHub DDE-BifTool/DDE-Biftool, run
# under Octave 2026-11 with its symbolic right-hand sides demos/neuron/sym_neuron.m and
# demos/Mackey-Glass/sym_MackeyGlass_mf.m). The DDE-BIFTOOL numbers below were computed with its
# own functions on the demos' parameter values:
#   Hopf points: LocateSpecialPoints on the equilibrium branch, then p_tohopf, p_correc, nmfm_hopf
#     (L1 = nmfm.L1, the normalisation the README states);
#   periodic orbits: SetupPsol (degree 4, the demos' interval counts) and br_contn, GetStability;
#   Mackey-Glass period doubling: the psol point corrected at fixed tau (p_correc) and its real
#     negative multiplier driven to -1 by the secant method (p_stabil), with 80 intervals.
# The models are written here as system files from the README's format, not taken from examples/.
set -u
bin="${DDEMAP:?set DDEMAP to the ddemap binary}"
fail=0
pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# DDE-BIFTOOL demo "neuron" (Shayer and Campbell), the equilibrium branch in a21 at taus = 1.5
cat >"$tmp/neuron.json" <<'EOF'
{ "variables": ["x1", "x2"],
  "parameters": {"kappa": 0.5, "beta": -1, "a12": 1, "a21": 0.3, "tau1": 0.2, "tau2": 0.2, "taus": 1.5},
  "equations": ["-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"],
  "equilibrium": [0, 0] }
EOF
# DDE-BIFTOOL demo "Mackey-Glass": beta = 2, n = 10, gamma = 1, the branch in tau
cat >"$tmp/mg.json" <<'EOF'
{ "variables": ["x"],
  "parameters": {"beta": 2, "n": 10, "tau": 0, "gamma": 1},
  "equations": ["beta*x(t - tau)/(1 + x(t - tau)^n) - gamma*x"],
  "equilibrium": [1] }
EOF

# Hopf points and L1. DDE-BIFTOOL: neuron a21 = 0.807123224968, omega = 0.781965162121,
# L1 = -0.396157121451795; Mackey-Glass tau = 0.470819628936, omega = 3.872983346207,
# L1 = -13.342516550137963 (its published demo page still prints -5.695, an older normalisation).
# Both codes use exact derivatives here, so the agreement is to rounding (1e-9 relative is loose).
"$bin" hopf --system "$tmp/neuron.json" --par a21 --from 0.3 --to 2 --format json >"$tmp/nh.json" 2>/dev/null &&
    python3 - "$tmp/nh.json" <<'PY' && ok || bad "neuron Hopf point against DDE-BIFTOOL"
import json, sys
h = json.load(open(sys.argv[1]))["result"]["hopf"]
assert len(h) == 1, h
h = h[0]
for got, ref in ((h["par"], 0.807123224968), (h["omega"], 0.781965162121), (h["l1"], -0.396157121451795)):
    assert abs(got - ref) <= 1e-9 * abs(ref), (got, ref)
assert h["criticality"] == "supercritical"
PY
"$bin" hopf --system "$tmp/mg.json" --par tau --from 0 --to 2 --format json >"$tmp/mh.json" 2>/dev/null &&
    python3 - "$tmp/mh.json" <<'PY' && ok || bad "Mackey-Glass Hopf point against DDE-BIFTOOL"
import json, sys
h = json.load(open(sys.argv[1]))["result"]["hopf"]
assert len(h) == 1, h
h = h[0]
for got, ref in ((h["par"], 0.470819628936), (h["omega"], 3.872983346207), (h["l1"], -13.342516550137963)):
    assert abs(got - ref) <= 1e-9 * abs(ref), (got, ref)
PY

# Beyond a21 = 2.25 (sqrt(a12 a21) = kappa - beta) a real root crosses 0: the branch point of
# the nonzero equilibria (demo1_simple.m: "the branch point at a21=2.25"), not a Hopf point. Before
# it the unstable complex pair meets on the real axis (a21 ~ 2.22), which must not count as a
# Hopf point either; today `equilibria` lists "hopf a21 = 2.25, omega = 1e-18" as converged.
"$bin" equilibria --system "$tmp/neuron.json" --par a21 --from 0.3 --to 3 --format json >"$tmp/ne.json" 2>/dev/null
python3 - "$tmp/ne.json" <<'PY' && ok || bad "equilibria: the branch point at a21 = 2.25 is listed as a Hopf point with omega = 0"
import json, sys
h = json.load(open(sys.argv[1]))["result"]["hopf"]
assert all(p["omega"] > 1e-3 for p in h) and len(h) == 1, h
PY

# The neuron's orbit at a21 = 2 (degree 4, 40 intervals): DDE-BIFTOOL period 16.82535883, largest
# nontrivial multiplier 0.071805, stable. DDE-BIFTOOL adapts its mesh, ddemap keeps it uniform:
# the periods differ by 5e-7 on this mesh, hence 2e-6.
"$bin" orbits --system "$tmp/neuron.json" --par a21 --from 0.3 --to 2 --points 60 --format json >"$tmp/no.json" 2>/dev/null &&
    python3 - "$tmp/no.json" <<'PY' && ok || bad "neuron orbit at a21 = 2 against DDE-BIFTOOL"
import json, sys
p = json.load(open(sys.argv[1]))["result"]["points"][-1]
assert p["par"] == 2 and p["stable"], p["par"]
assert abs(p["period"] - 16.82535883) < 2e-6, p["period"]
mu = sorted((abs(complex(*m)) for m in p["multipliers"]), reverse=True)
assert abs(mu[1] - 0.071805) < 1e-5, mu[:3]
PY

# The Mackey-Glass period doubling, degree 4 on 80 intervals: DDE-BIFTOOL tau = 1.324921526248,
# period 3.919649609048 (with 20 intervals it gives 1.324923092, so 1e-8 is well above the mesh
# difference of the two codes at 80 intervals, about 5e-10).
pd_check() {  # pd_check FILE: one located period doubling at DDE-BIFTOOL's tau
    python3 - "$1" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["result"]
pd = r["period_doublings"]
pts = r["points"]
changes = [(a["par"], b["par"]) for a, b in zip(pts, pts[1:]) if a["stable"] != b["stable"]]
assert len(pd) == 1, ("period doublings", pd, "stability changes between orbits at", changes)
assert pd[0]["located"] and abs(pd[0]["par"] - 1.324921526248) < 1e-8, pd
assert abs(pd[0]["period"] - 3.919649609048) < 1e-8, pd
PY
}
"$bin" orbits --system "$tmp/mg.json" --par tau --from 0 --to 2 --intervals 80 --points 200 --format json >"$tmp/mo.json" 2>/dev/null &&
    pd_check "$tmp/mo.json" && ok || bad "Mackey-Glass period doubling against DDE-BIFTOOL (default step)"
# The same with the demo's step size (MackeyGlass_demo.m: max_step [tau, 0.5]; DDE-BIFTOOL finds
# the doubling from the count of unstable multipliers, 0 -> 1 between tau = 1.276 and 1.424).
# With --max-step 0.3 or more the real multiplier moves by more than 0.25 in one step (-0.99 to
# -1.63) and no period doubling is reported although `stable` changes between the two orbits.
"$bin" orbits --system "$tmp/mg.json" --par tau --from 0 --to 2 --intervals 80 --points 200 --max-step 0.5 --format json >"$tmp/ml.json" 2>/dev/null &&
    pd_check "$tmp/ml.json" && ok || bad "Mackey-Glass period doubling with --max-step 0.5 (DDE-BIFTOOL's demo step) is not reported"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
