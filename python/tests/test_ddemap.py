"""The Python module against the command line: every function on the same input as
``ddemap COMMAND --format json`` (the program given by $DDEMAP, run as a subprocess), the
results compared key by key and number by number (the same library on the same input: equal
to the last bit). Also: bad input is ValueError with the message the program prints, the GIL is
released during a computation, Ctrl-C stops a long sweep, and examples/stability_chart.py runs.

Run: PYTHONPATH=build/python DDEMAP=build/ddemap python3 -m pytest python/tests -q
"""
import csv
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import ddemap

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
CLI = os.environ.get("DDEMAP", os.path.join(SOURCE, "build", "ddemap"))
OVRV = dict(k1=0.2, k2=0.2, th=1.5, tau=0.1)
TIMING = {"seconds", "points_per_second"}  # wall-clock times differ between two runs


def cli(*args, expect=0):
    r = subprocess.run([CLI, *map(str, args)], capture_output=True, text=True, timeout=120)
    assert r.returncode == expect, (args, r.returncode, r.stderr)
    return r


def cli_json(*args, expect=0):
    return json.loads(cli(*args, "--format", "json", expect=expect).stdout)


def same(py, ref, path="result"):
    """py (the module's value) equals ref (the CLI's JSON value): a list of records is a dict of
    columns in Python, a list of numbers an array, null a NaN in a numeric column."""
    if isinstance(ref, dict):
        assert isinstance(py, dict), path
        missing = set(ref) - set(py)
        assert not missing, (path, missing)
        for k, v in ref.items():
            if k not in TIMING:
                same(py[k], v, path + "." + k)
    elif isinstance(ref, list):
        if ref and all(isinstance(v, dict) for v in ref) and all(v.keys() == ref[0].keys() for v in ref):
            assert isinstance(py, dict) and set(py) == set(ref[0]), path
            for k in ref[0]:
                if k not in TIMING:
                    same(py[k], [v[k] for v in ref], path + "." + k)
        else:
            assert len(py) == len(ref), (path, len(py), len(ref))
            for i, v in enumerate(ref):
                same(py[i], v, "%s[%d]" % (path, i))
    elif ref is None:
        assert py is None or (isinstance(py, float) and math.isnan(py)), (path, py)
    elif isinstance(ref, bool):
        assert bool(py) == ref and isinstance(py, (bool, np.bool_)), (path, py, ref)
    elif isinstance(ref, (int, float)):
        assert not isinstance(py, (bool, np.bool_)) and py == ref, (path, py, ref)  # exact
    else:
        assert py == ref, (path, py, ref)


def same_envelope(r, e, compare_inputs=True):
    assert r.command == e["command"] and r.version == e["version"]
    assert r.status == e["status"] and r.message == e["message"] and r.solver == e["solver"]
    if compare_inputs:
        assert r.inputs == e["inputs"]
    same(r, e["result"])


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# ------------------------------------------------------------------ every function against the CLI


@pytest.mark.parametrize("ring", [22, "inf"])
def test_roots(ring):
    r = ddemap.roots(ring=ring, count=5, **OVRV)
    same_envelope(r, cli_json("roots", "--ring", ring, "--count", 5, *flags(OVRV)))
    assert isinstance(r["roots"]["re"], np.ndarray) and r["roots"]["re"].dtype == float and len(r["roots"]["re"]) >= 5


def test_roots_idm():
    p = dict(model="idm", th=1.5, tau=0.3, speed=15)
    r = ddemap.roots(**p)
    same_envelope(r, cli_json("roots", *flags(p)))


def test_roots_system(tmp_path):
    linear = os.path.join(SOURCE, "examples", "system.json")
    same_envelope(ddemap.roots(system=linear, count=4), cli_json("roots", "--system", linear, "--count", 4))
    same_envelope(ddemap.roots(system=linear, solver="dense"), cli_json("roots", "--system", linear, "--solver", "dense"))
    nonlinear = tmp_path / "nl.json"
    nonlinear.write_text(json.dumps({"variables": ["x1", "x2"], "parameters": {"a": 0.5, "b": 0.6, "d": 0.05, "tau": 2.0},
                                     "equations": ["x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"],
                                     "equilibrium": [0.1, 0.0]}))
    r = ddemap.roots(system=nonlinear)
    same_envelope(r, cli_json("roots", "--system", nonlinear))
    assert set(r) == {"equilibrium", "linearisation"}
    # x' = x^2 + 1 has no equilibrium: undecided (exit 4 in the command line), not an exception
    none = tmp_path / "none.json"
    none.write_text('{"variables": ["x"], "equations": ["x^2 + 1"], "equilibrium": [0.5]}')
    r = ddemap.roots(system=none)
    same_envelope(r, cli_json("roots", "--system", none, expect=4))
    assert not r.converged


def test_string():
    same_envelope(ddemap.string(**OVRV), cli_json("string", *flags(OVRV)))
    r = ddemap.string(ring="inf", **OVRV)
    same_envelope(r, cli_json("string", "--ring", "inf", *flags(OVRV)))
    assert r["string_stable"] is False and r["sup_gamma"] > 1


@pytest.mark.slow
def test_design():
    # the same result as the command, bit for bit (one library on one input)
    r = ddemap.design("C_max", objective="nearest", progress=False)
    same_envelope(r, cli_json("design", "C_max", "--objective", "nearest"))
    assert r.status == "converged" and r["verdicts"]["string_stable"] is True and r["initial"]["verdicts"]["string_stable"] is False
    assert r["attenuation_margin"] >= 0.1 and r["margin_met"] is True
    r = ddemap.design("A_min", free="k1,k2,th", bounds={"th": (0.5, 3.0)}, starts=2, progress=False)
    same_envelope(r, cli_json("design", "A_min", "--free", "k1,k2,th", "--bounds", "th=0.5:3", "--starts", 2))
    assert set(r["gains"]) == {"k1", "k2", "th"} and 0.5 <= r["gains"]["th"] <= 3.0
    # a one-row DataFrame is a car; more rows are refused as the command refuses them
    pd = pytest.importorskip("pandas")
    cars = pd.read_csv(os.path.join(SOURCE, "examples", "mycars.csv"), comment="#")
    r = ddemap.design(cars[cars.name == "SUV"], objective="nearest", progress=False)
    assert r.status == "converged" and r["verdicts"]["string_stable"] is True
    with pytest.raises(ValueError, match="expected one car"):
        ddemap.design(cars)
    with pytest.raises(ValueError, match="expected sup-gamma, peak, abscissa or nearest"):
        ddemap.design("C_max", objective="fastest")
    with pytest.raises(ValueError, match="expected a pair"):
        ddemap.design("C_max", bounds={"k1": 0.3})
    with pytest.raises(ValueError, match="not free"):
        ddemap.design("C_max", bounds={"th": (1, 2)})


def test_sweep(tmp_path):
    r = ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 17), k2=(0.05, 0.9, 13), ring=10)
    e = cli_json("sweep", "--th", 1.5, "--tau", 0.1, "--k1", "0.01:1:17", "--k2", "0.05:0.9:13", "--ring", 10,
                 "--out", tmp_path / "s")
    same_envelope(r, e)
    # the grid against the CSV: row-major, y outer, x inner
    rows = read_csv(tmp_path / "s.csv")
    g = r["grid"]
    assert g["region"].shape == (13, 17) and len(rows) == 13 * 17
    for i, row in enumerate(rows):
        iy, ix = divmod(i, 17)
        assert float(row["k1_per_s2"]) == g["x"][ix] == r["x"]["values"][ix]
        assert float(row["k2_per_s"]) == g["y"][iy] == r["y"]["values"][iy]
        # the CSV's columns carry their units, the grid's keys are the quantities' names
        for k, column in (("spectral_abscissa", "spectral_abscissa_per_s"), ("sup_gamma", "sup_gamma"),
                          ("omega_peak", "omega_peak_rad_per_s"), ("plant_abscissa", "plant_abscissa_per_s"),
                          ("lowfreq_margin", "lowfreq_margin"), ("peak_gain", "peak_gain")):
            assert float(row[column]) == g[k][iy, ix], (k, i)
        for k in ("plant_stable", "ring_stable", "string_stable", "certified"):
            assert (row[k] == "true") == g[k][iy, ix], (k, i)
        for k in ("unstable_roots", "abscissa_mode"):
            assert (int(row[k]) if row[k] else -1) == g[k][iy, ix], (k, i)
        region = 0 if not row["plant_stable"] == "true" else 1 if not row["ring_stable"] == "true" else \
            2 if not row["string_stable"] == "true" else 3
        assert g["region"][iy, ix] == region
    same_curves(r["curves"], read_csv(tmp_path / "s-boundaries.csv"), "k1_per_s2", "k2_per_s")
    assert r["boundaries"]["curves"] == len(r["curves"]) > 0


def same_curves(curves, rows, x, y):
    for c in curves:
        pts = [row for row in rows if int(row["branch"]) == c["branch"]]
        assert len(pts) == len(c["x"]) > 1
        assert all(row["kind"] == c["kind"] and row["subkind"] == c["subkind"] for row in pts)
        assert (int(pts[0]["mode"]) if pts[0]["mode"] else None) == c["mode"]
        assert [float(row[x]) for row in pts] == list(c["x"])
        assert [float(row[y]) for row in pts] == list(c["y"])
        assert [float(row["omega_rad_per_s"]) for row in pts] == list(c["omega"])


def test_boundary(tmp_path):
    r = ddemap.boundary(th=1.5, tau=0.1, k1=(0.01, 1), k2=(0.01, 1), seed_grid=15, ring="inf")
    e = cli_json("boundary", "--th", 1.5, "--tau", 0.1, "--k1", "0.01:1", "--k2", "0.01:1", "--seed-grid", 15, "--ring", "inf",
                 "--out", tmp_path / "b")
    assert r.status == e["status"] and r.message == e["message"] and r.inputs == e["inputs"]
    summary = e["result"]["curves"]
    assert len(r["curves"]) == len(summary) > 0
    for c, s in zip(r["curves"], summary):
        for k in ("branch", "kind", "subkind", "mode", "points", "max_residual", "closed"):
            assert c[k] == s[k], k
    assert r["seeds"] == e["result"]["seeds"] and r["rejected_seeds"] == e["result"]["rejected_seeds"]
    same_curves(r["curves"], read_csv(tmp_path / "b.csv"), "k1_per_s2", "k2_per_s")


def test_classify():
    r = ddemap.classify()
    same_envelope(r, cli_json("classify"))
    assert not r["vehicles"]["string_stable"].any()  # the paper: all 14 settings string unstable
    r = ddemap.classify(os.path.join(SOURCE, "examples", "vehicles.csv"), ring="inf")
    same_envelope(r, cli_json("classify", os.path.join(SOURCE, "examples", "vehicles.csv"), "--ring", "inf"))
    # the peak (L-infinity) verdict: sup |Gamma| <= ||h||_1, so every string-unstable car is peak unstable
    r = ddemap.classify(peak=True)
    same_envelope(r, cli_json("classify", "--peak"))
    v = r["vehicles"]
    assert all(x == "unstable" for x in v["peak_verdict"]) and (np.asarray(v["sup_gamma"]) <= np.asarray(v["peak_norm"])).all()
    with pytest.raises(ValueError, match="peak = 1: expected True or False"):
        ddemap.classify(peak=1)
    # the distance to the other verdict: as the command's, and a stable car of a DataFrame-like
    # dict turns unstable at the parameters reported
    r = ddemap.classify("C_max", distance=True)
    same_envelope(r, cli_json("classify", "C_max", "--distance"))
    r = ddemap.classify({"name": ["mine"], "k1": [0.2], "k2": [0.6], "th": [2.0], "tau": [0.2]}, distance=True)
    d = r["vehicles"]["verdict_distance"]  # columns, one entry per vehicle
    assert r["vehicles"]["string_stable"][0] and d["to"][0] == "string unstable" and 0 < d["distance"][0] < 1, d
    flipped = ddemap.classify([dict(name="flip", **{k: float(v[0]) for k, v in d["at"].items()})])
    assert not flipped["vehicles"]["string_stable"][0]
    with pytest.raises(ValueError, match="distance = 'yes': expected True or False"):
        ddemap.classify(distance="yes")


def test_simulate(tmp_path):
    r = ddemap.simulate("A_min*2,E_max", lead_profile="oscillatory", t_end=20, step=0.05, output_dt=0.5)
    e = cli_json("simulate", "--fleet", "A_min*2,E_max", "--lead-profile", "oscillatory", "--t-end", 20, "--step", 0.05,
                 "--output-dt", 0.5, "--out", tmp_path / "sim")
    same_envelope(r, e)
    s = r["series"]
    rows = read_csv(tmp_path / "sim.csv")
    assert s["speed"].shape == (4, len(s["time"])) and s["time"][-1] == 20
    header = list(rows[0].keys())
    times = sorted({float(row[header[0]]) for row in rows})
    assert times == list(s["time"])


def test_calibrate():
    trace = os.path.join(SOURCE, "tests", "data", "openacc_excerpt_rav4_to_etron.csv")
    r = ddemap.calibrate(trace, bounds={"eta": (5, 20)}, train=(0, 45))
    same_envelope(r, cli_json("calibrate", trace, "--bounds", "eta=5:20", "--train", "0:45"))
    assert len(r["fits"]["status"]) == 1
    # plain least squares on request, as --lead-noise-correction off
    plain = ddemap.calibrate(trace, bounds={"eta": (5, 20)}, train=(0, 45), lead_noise_correction=False)
    same_envelope(plain, cli_json("calibrate", trace, "--bounds", "eta=5:20", "--train", "0:45", "--lead-noise-correction", "off"))
    assert plain["fits"]["lead_noise_corrected"] == [False] and r["fits"]["lead_noise_corrected"] == [True]


def test_calibrate_runs_joint_report(tmp_path):
    # what the command offers for several runs: --joint, --runs (with --data-dir) and --report
    trace = os.path.join(SOURCE, "tests", "data", "openacc_excerpt_rav4_to_etron.csv")
    data = tmp_path / "data"
    data.mkdir()
    for name in ("a.csv", "b.csv"):
        (data / name).write_text(open(trace).read())
    r = ddemap.calibrate(str(data / "a.csv"), str(data / "b.csv"), joint=True, car="rav4", train=(0, 45))
    same_envelope(r, cli_json("calibrate", "--joint", "--car", "rav4", data / "a.csv", data / "b.csv", "--train", "0:45", "--quiet"))
    runs = tmp_path / "runs.csv"
    runs.write_text("car,file,role,type\nrav4,a.csv,train,\nrav4,b.csv,test,same\n")
    r = ddemap.calibrate(runs=runs, data_dir=data, report=tmp_path / "py")
    same_envelope(r, cli_json("calibrate", "--runs", runs, "--data-dir", data, "--report", tmp_path / "cli", "--quiet"))
    assert r["fits"]["tests"][0]["type"] == ["same"]
    files = sorted(os.listdir(tmp_path / "cli"))
    assert files == sorted(os.listdir(tmp_path / "py")) and len(files) == 5, files  # 3 tables, 2 figures
    for f in files:
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    with pytest.raises(ValueError, match="data_dir = .*: only with runs"):
        ddemap.calibrate(trace, data_dir=data)
    with pytest.raises(ValueError, match="joint: not with runs"):
        ddemap.calibrate(runs=runs, data_dir=data, joint=True)


def test_mixed_ring():
    r = ddemap.mixed_ring("A_min,C_max*3", count=4)
    same_envelope(r, cli_json("roots", "--fleet", "A_min,C_max*3", "--count", 4))
    r = ddemap.mixed_ring("A_min,E_max", ring=6, length=200, solver="dense")
    same_envelope(r, cli_json("roots", "--fleet", "A_min,E_max", "--ring", 6, "--length", 200, "--solver", "dense"))


@pytest.mark.slow
def test_equilibria(tmp_path):
    # x' = p - x(t - 1)^2: a fold at p = 0 and a Hopf point at p = (pi/4)^2
    system = tmp_path / "fold.json"
    system.write_text(json.dumps({"variables": ["x"], "parameters": {"p": 1}, "equations": ["p - x(t - 1)^2"],
                                  "equilibrium": [1]}))
    r = ddemap.equilibria("p", 0.9, -1, system=system)
    same_envelope(r, cli_json("equilibria", "--system", system, "--par", "p", "--from", 0.9, "--to", -1))
    assert len(r["hopf"]["par"]) == 1 and len(r["folds"]["par"]) == 1  # the closed forms: tests/cli/test_cli.sh
    r = ddemap.equilibria("alpha", 0.5, 2, model="ov", ring=3, count=2, max_points=60)
    same_envelope(r, cli_json("equilibria", "--model", "ov", "--ring", 3, "--par", "alpha", "--from", 0.5, "--to", 2,
                              "--count", 2, "--max-points", 60))

    # the idm ring by name, as --model idm
    r = ddemap.equilibria("gap", 6, 40, model="idm", ring=5, th=1.2, tau=0.6)
    same_envelope(r, cli_json("equilibria", "--model", "idm", "--ring", 5, "--th", 1.2, "--tau", 0.6, "--par", "gap", "--from", 6, "--to", 40))


def test_fold_curves(tmp_path):
    # x' = p1 + x^2 + p2 x(t - 2): the fold curve p1 = p2^2 / 4 with a Bogdanov-Takens point at p2 = -1/2
    # (closed forms: tests/analysis/bifurcation/test_fold_curve.cpp); the same envelope as equilibria --par2
    system = tmp_path / "bt.json"
    system.write_text(json.dumps({"variables": ["x"], "parameters": {"p1": -0.5, "p2": 0.5, "tau": 2},
                                  "equations": ["p1 + x^2 + p2*x(t - tau)"], "equilibrium": [-1]}))
    r = ddemap.equilibria("p1", -0.5, 2, system=system, par2="p2", from2=-1.5, to2=1.5)
    same_envelope(r, cli_json("equilibria", "--system", system, "--par", "p1", "--from", -0.5, "--to", 2, "--par2", "p2",
                              "--from2", -1.5, "--to2", 1.5))
    assert r.status == "converged"
    with pytest.raises(ValueError, match="par2 needs from2 and to2"):
        ddemap.equilibria("p1", -0.5, 2, system=system, par2="p2")


@pytest.mark.slow
def test_bistability():
    # the 3-car ov ring's chart (README tour step 5): the same envelope as the command
    args = dict(model="ov", ring=3, headway=1.2)
    r = ddemap.bistability("headway", 1.2, 3, "tau", 0.3, 2, **args)
    same_envelope(r, cli_json("bistability", "--model", "ov", "--ring", 3, "--headway", 1.2, "--par", "headway", "--from", 1.2, "--to", 3,
                              "--par2", "tau", "--from2", 0.3, "--to2", 2))
    cells = r["cells"]
    flags = cells["bistable"] if isinstance(cells, dict) else [c["bistable"] for c in cells]
    assert r.status == "converged" and any(flags)
    with pytest.raises(ValueError, match="expected a parameter other than par"):
        ddemap.bistability("headway", 1.2, 3, "headway", 0.3, 2, model="ov", ring=3)


@pytest.mark.slow
def test_hopf(tmp_path):
    # Wright's equation: one supercritical Hopf point at alpha = pi/2 (closed forms: tests/cli/test_cli.sh)
    system = tmp_path / "wright.json"
    system.write_text(json.dumps({"variables": ["y"], "parameters": {"alpha": 1, "b": 1}, "equations": ["-alpha*y(t - 1)*(1 + b*y)"]}))
    r = ddemap.hopf("alpha", 1, 2, system=system)
    same_envelope(r, cli_json("hopf", "--system", system, "--par", "alpha", "--from", 1, "--to", 2))
    assert r["hopf"]["criticality"] == ["supercritical"] and abs(r["hopf"]["par"][0] - math.pi / 2) < 1e-8
    r = ddemap.hopf("alpha", 1, 2, system=system, par2="b", from2=0.5, to2=2, max_points=40)
    same_envelope(r, cli_json("hopf", "--system", system, "--par", "alpha", "--from", 1, "--to", 2, "--par2", "b", "--from2", 0.5,
                              "--to2", 2, "--max-points", 40))
    r = ddemap.hopf("gap", 6, 40, model="idm", ring=5, th=1.2, tau=0.6)
    same_envelope(r, cli_json("hopf", "--model", "idm", "--ring", 5, "--th", 1.2, "--tau", 0.6, "--par", "gap", "--from", 6, "--to", 40))
    with pytest.raises(ValueError, match="expected from < to"):
        ddemap.hopf("alpha", 2, 1, system=system)


@pytest.mark.slow
def test_orbits():
    r = ddemap.orbits("headway", 2, 3.5, model="ov", ring=3, points=12)
    same_envelope(r, cli_json("orbits", "--model", "ov", "--ring", 3, "--par", "headway", "--from", 2, "--to", 3.5, "--points", 12))
    assert len(r["points"]["period"]) == 12
    with pytest.raises(ValueError, match="hopf = 7: expected an index from 0"):
        ddemap.orbits("headway", 2, 3.5, model="ov", ring=3, hopf=7, points=12)


def test_acc_ring_hopf():
    # the ACC ring with acceleration limits: the same envelope as the command with the same gains
    gains = dict(k1=0.052, k2=0.338, th=0.819, tau=0.948, eta=8.03, gap=30)
    r = ddemap.hopf("k2", 0.2, 1.2, model="acc", ring=8, **gains)
    same_envelope(r, cli_json("hopf", "--model", "acc", "--ring", 8, "--k1", 0.052, "--k2", 0.338, "--th", 0.819, "--tau", 0.948,
                              "--eta", 8.03, "--gap", 30, "--par", "k2", "--from", 0.2, "--to", 1.2))
    assert len(r["hopf"]["par"]) == 2
    with pytest.raises(ValueError, match="a_min = 1: expected a finite braking limit < 0"):
        ddemap.hopf("k2", 0.2, 1.2, model="acc", ring=8, a_min=1, **gains)


def test_orbits_period_doubling():
    # the branch of twice the period switched onto at the period doubling of Mackey-Glass: the
    # command's envelope, and the doubled branch starts at the doubling with twice its period
    system = os.path.join(SOURCE, "examples", "mackey_glass.json")
    r = ddemap.orbits("tau", 0.3, 2, system=system, points=200, period_doubling=0)
    same_envelope(r, cli_json("orbits", "--system", system, "--par", "tau", "--from", 0.3, "--to", 2, "--points", 200,
                              "--period-doubling", 0))
    d = r["period_doubled"]
    assert d["from"]["par"] == r["period_doublings"]["par"][0]
    assert d["points"]["period"][0] > 1.9 * d["from"]["period"]
    with pytest.raises(ValueError, match="period_doubling = 3: expected an index from 0 to 0"):
        ddemap.orbits("tau", 0.3, 1.5, system=system, points=200, period_doubling=3)


def test_orbits_par2():
    # the curves of period doublings in two parameters: the command's envelope
    system = os.path.join(SOURCE, "examples", "mackey_glass.json")
    r = ddemap.orbits("tau", 0.3, 2, system=system, points=200, par2="n", from2=9, to2=10.5)
    same_envelope(r, cli_json("orbits", "--system", system, "--par", "tau", "--from", 0.3, "--to", 2, "--points", 200, "--par2", "n",
                              "--from2", 9, "--to2", 10.5))
    assert len(r["period_doubling_curves"]["points"]) == 1 and r["fold_curves"] == []  # (a list of curves comes back as columns)
    with pytest.raises(ValueError, match="par2 needs from2 and to2"):
        ddemap.orbits("tau", 0.3, 2, system=system, par2="n", from2=9)
    assert r["torus_curves"] == []
    # the curve of torus bifurcations of DDE-BIFTOOL's minimal demo in (tau, b)
    duffing = os.path.join(SOURCE, "examples", "duffing.json")
    t = ddemap.orbits("tau", 0, 20, system=duffing, hopf=1, points=12, intervals=30, par2="b", from2=0.3, to2=0.9)
    same_envelope(t, cli_json("orbits", "--system", duffing, "--par", "tau", "--from", 0, "--to", 20, "--hopf", 1, "--points", 12,
                              "--intervals", 30, "--par2", "b", "--from2", 0.3, "--to2", 0.9))
    curve = t["torus_curves"]
    assert curve["stop_backward"] == ["hopf"] and len(curve["points"][0]["par"]) > 10, curve["points"][0].keys()


def test_equilibria_branch_point():
    # the other branch of Hutchinson's equation through its branch point: the command's envelope, x = p
    system = os.path.join(SOURCE, "examples", "hutchinson.json")
    r = ddemap.equilibria("p", -1, 2, system=system, branch_point=0)
    same_envelope(r, cli_json("equilibria", "--system", system, "--par", "p", "--from", -1, "--to", 2, "--branch-point", 0))
    sw = r["switched"]
    assert all(abs(x[0] - p) < 1e-12 for x, p in zip(sw["points"]["x"], sw["points"]["par"]))
    with pytest.raises(ValueError, match="branch_point = 2: expected an index from 0 to 0"):
        ddemap.equilibria("p", -1, 2, system=system, branch_point=2)


def test_orbits_from_simulation_and_guess(tmp_path):
    # the starts other than a Hopf point: the command's envelopes, and the same orbit of Wright's
    # equation at alpha = 1.7 from a file, a DataFrame and a pair of arrays
    system = os.path.join(SOURCE, "examples", "wright.json")
    r = ddemap.orbits("alpha", 2, 2.5, system=system, points=3, from_simulation=300)
    same_envelope(r, cli_json("orbits", "--system", system, "--par", "alpha", "--from", 2, "--to", 2.5, "--points", 3, "--from-simulation", 300))
    assert r["start"]["kind"] == "simulation" and r["start"]["crossings_per_period"] == 1
    r = ddemap.orbits("alpha", 2, 2.5, system=system, points=3, from_simulation=300, history=[0.5])
    same_envelope(r, cli_json("orbits", "--system", system, "--par", "alpha", "--from", 2, "--to", 2.5, "--points", 3, "--from-simulation", 300,
                              "--history", 0.5))
    t = [4.1 * i / 100 for i in range(101)]
    y = [0.8 * math.sin(2 * math.pi * s / 4.1) for s in t]
    path = tmp_path / "guess.csv"
    path.write_text("t,y\n" + "".join("%r,%r\n" % (a, b) for a, b in zip(t, y)))
    r = ddemap.orbits("alpha", 1.7, 2.5, system=system, points=3, guess=str(path))
    same_envelope(r, cli_json("orbits", "--system", system, "--par", "alpha", "--from", 1.7, "--to", 2.5, "--points", 3, "--guess", str(path)))
    pd = pytest.importorskip("pandas")
    periods = [r["points"]["period"][0]]
    periods.append(ddemap.orbits("alpha", 1.7, 2.5, system=system, points=3, guess=pd.DataFrame({"t": t, "y": y}))["points"]["period"][0])
    periods.append(ddemap.orbits("alpha", 1.7, 2.5, system=system, points=3, guess=(t, [[v] for v in y]))["points"]["period"][0])
    assert periods[0] == periods[1] == periods[2]
    with pytest.raises(ValueError, match="from_simulation and guess: expected one start"):
        ddemap.orbits("alpha", 1.7, 2.5, system=system, from_simulation=100, guess=str(path))
    with pytest.raises(ValueError, match="history: expected 1 values"):
        ddemap.orbits("alpha", 2, 2.5, system=system, from_simulation=100, history=[1, 2])


def _tolerance(name):
    """A tolerance of tests/tolerances.hpp (the one list of them, with why each has its size)."""
    with open(os.path.join(SOURCE, "tests", "tolerances.hpp")) as f:
        for line in f:
            words = line.split()
            if words[:4] == ["constexpr", "double", name, "="]:
                return float(words[4].rstrip(";"))
    raise KeyError(name)


@pytest.mark.slow
def test_orbits_max_step():
    # max_step is the command's --max-step: the same envelope (inputs include it) ...
    ring = dict(model="ov", ring=3)
    r = ddemap.orbits("headway", 2, 3.5, points=200, max_step=1, **ring)
    same_envelope(r, cli_json("orbits", "--model", "ov", "--ring", 3, "--par", "headway", "--from", 2, "--to", 3.5, "--points", 200,
                              "--max-step", 1))
    assert r.inputs["max_step"] == 1
    # ... and the same branch as with the default step: from the Hopf point (headway 2.49) both
    # end on the face headway = 2, on the same orbit, the longer steps with fewer orbits
    short = ddemap.orbits("headway", 2, 3.5, points=200, **ring)
    assert "max_step" not in short.inputs
    assert r["stop"] == short["stop"] == "bound"
    assert r["points"]["par"][-1] == 2 and short["points"]["par"][-1] == 2
    assert len(r["points"]["par"]) < len(short["points"]["par"])
    t_long, t_short = r["points"]["period"][-1], short["points"]["period"][-1]
    assert abs(t_long - t_short) <= _tolerance("orbit_step_interpolation") * t_short, (t_long, t_short)
    # a bad value is ValueError naming it, with the command's range
    for bad in (0.01, 2e6):
        with pytest.raises(ValueError, match=r"max_step = .*: expected a value from 0\.02 \(the first step\) to 1e6"):
            ddemap.orbits("headway", 2, 3.5, max_step=bad, **ring)
        cli("orbits", "--model", "ov", "--ring", 3, "--par", "headway", "--from", 2, "--to", 3.5, "--max-step", bad, expect=2)
    with pytest.raises(ValueError, match="max_step = nan: expected a finite number"):
        ddemap.orbits("headway", 2, 3.5, max_step=float("nan"), **ring)


def flags(params):
    out = []
    for k, v in params.items():
        out += ["--" + k.replace("_", "-"), v]
    return out


# ------------------------------------------------------------------ errors, GIL, Ctrl-C


@pytest.mark.parametrize("call, args", [
    (lambda: ddemap.roots(k1=-1, k2=0.2, th=1.5, tau=0.1), ["roots", "--k1", -1, "--k2", 0.2, "--th", 1.5, "--tau", 0.1]),
    (lambda: ddemap.string(k1=0.2, k2=0.2, th=1.5), ["string", "--k1", 0.2, "--k2", 0.2, "--th", 1.5]),
    (lambda: ddemap.roots(model="idm", k1=0.2), ["roots", "--model", "idm", "--k1", 0.2]),
    (lambda: ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 1), k2=(0.01, 1, 5)),
     ["sweep", "--th", 1.5, "--tau", 0.1, "--k1", "0.01:1:1", "--k2", "0.01:1:5", "--out", "/dev/null/x"]),
    (lambda: ddemap.mixed_ring("A_min,NOPE"), ["roots", "--fleet", "A_min,NOPE"]),
    (lambda: ddemap.classify("A_min,NOPE"), ["classify", "A_min,NOPE"]),
])
def test_bad_input_is_value_error_with_the_library_message(call, args):
    with pytest.raises(ValueError) as info:
        call()
    message = str(info.value)
    err = cli(*args, expect=2).stderr
    assert message and message in err, (message, err)


def test_bad_python_arguments():
    with pytest.raises(ValueError, match="ring = 1: expected an integer N >= 2"):
        ddemap.roots(ring=1, **OVRV)
    with pytest.raises(ValueError, match="expected exactly two swept parameters"):
        ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 10), k2=0.2)
    with pytest.raises(ValueError, match="k2 = nan: expected a finite number"):
        ddemap.string(k1=0.2, k2=float("nan"), th=1.5, tau=0.1)
    with pytest.raises(ValueError, match="speed and length"):
        ddemap.mixed_ring("A_min", speed=20, length=100)


def test_the_gil_is_released_during_a_computation():
    ticks = []
    done = threading.Event()

    def work():
        ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 200), k2=(0.01, 1, 200), ring=22, boundaries=False)
        done.set()

    t = threading.Thread(target=work)
    start = time.perf_counter()
    t.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.005)
    t.join()
    took = time.perf_counter() - start
    # Python ran on the main thread all along: with the GIL held the loop could not tick
    assert len(ticks) >= 10 and len(ticks) > took / 0.005 / 4, (took, len(ticks))


def test_ctrl_c_stops_a_long_sweep():
    code = textwrap.dedent("""
        import signal, sys, ddemap
        # Python's own SIGINT handler even when started with SIGINT ignored (a background job)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        in_call = False
        try:
            print("start", flush=True)
            in_call = True  # the KeyboardInterrupt must come from inside the call
            ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 60), k2=(0.01, 1, 3000), ring=22)  # short rows; 8 s on 2 idle cores
            in_call = False
        except KeyboardInterrupt:
            print("interrupted" if in_call else "outside the call", flush=True)
            sys.exit(7)
        sys.exit(0)
    """)
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, env=dict(os.environ))
    assert p.stdout.readline().strip() == "start"
    time.sleep(0.5)
    sent = time.perf_counter()
    p.send_signal(signal.SIGINT)
    rc = p.wait(timeout=30)
    stopped = time.perf_counter() - sent
    assert rc == 7 and p.stdout.read().strip() == "interrupted"
    assert stopped < 5, stopped  # the full sweep takes minutes


@pytest.mark.slow
def test_ctrl_c_stops_orbits_and_a_later_call_works():
    # SIGINT while the orbits are computed: the 10-car IDM ring's branch of 100 orbits, measured
    # uninterrupted first (CPU time of the main thread, where the library computes), is
    # interrupted a fifth into its orbit phase
    ring = dict(model="idm", ring=10, th=1.2, tau=0.6)
    start = _main_thread_cpu()
    branch = ddemap.equilibria("gap", 6, 40, count=2, **ring)
    t_branch = _main_thread_cpu() - start
    start = _main_thread_cpu()
    full = ddemap.orbits("gap", 6, 40, points=100, **ring)
    t_full = _main_thread_cpu() - start
    assert len(full["points"]["par"]) == 100
    phase = t_full - t_branch  # the orbits themselves
    at, took = _interrupted_at(lambda: ddemap.orbits("gap", 6, 40, points=100, **ring), t_branch + 0.2 * phase)
    # stopped within a few orbits of the signal (100 orbits take `phase`), long before the branch would end
    assert took - at < max(0.5, 0.2 * phase), (took, at, phase)
    assert took < t_branch + 0.6 * phase, (took, t_branch, phase)
    # the module still works, and gives what it gave before
    again = ddemap.equilibria("gap", 6, 40, count=2, **ring)
    assert list(again["points"]["par"]) == list(branch["points"]["par"])


@pytest.mark.slow
def test_stability_chart_example(tmp_path):
    png = tmp_path / "chart.png"
    subprocess.run([sys.executable, os.path.join(SOURCE, "examples", "stability_chart.py"), str(png), "--count", "15"],
                   check=True, timeout=120)
    with open(png, "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def _main_thread_cpu():
    """CPU seconds of the main thread, where the library computes (the GIL released, the same
    thread): unlike wall time, the machine's load does not change how much of it a call needs."""
    return time.clock_gettime(time.pthread_getcpuclockid(threading.main_thread().ident))


def _interrupted_at(call, at):
    """Runs `call()` with a watcher thread that sends SIGINT once the call has used `at` seconds
    of the main thread's CPU time; returns (CPU time at the signal, CPU time at the
    KeyboardInterrupt), both from the start of the call. The signal is placed by the work done,
    not by the clock, so a busier or idler machine neither lets the call finish before it nor
    delays it; and the KeyboardInterrupt must come from inside the call (pytest.raises)."""
    sent, done = [], threading.Event()

    def watch(begin):
        while not done.is_set():
            used = _main_thread_cpu() - begin
            if used >= at:
                sent.append(used)
                os.kill(os.getpid(), signal.SIGINT)
                return
            time.sleep(0.002)

    begin = _main_thread_cpu()
    watcher = threading.Thread(target=watch, args=(begin,))
    watcher.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
        took = _main_thread_cpu() - begin
    finally:
        done.set()
        watcher.join()
    assert sent, "no signal was sent"
    return sent[0], took


def _interrupted_after(call, fraction):
    """Runs `call()` uninterrupted and measures the main thread's CPU time it needs (`full`),
    then runs it again interrupted once it has used `fraction` of that (_interrupted_at).
    Returns (full, CPU time at the signal, CPU time at the KeyboardInterrupt)."""
    start = _main_thread_cpu()
    call()
    full = _main_thread_cpu() - start
    return (full, *_interrupted_at(call, fraction * full))


@pytest.mark.slow
def test_ctrl_c_stops_a_long_mixed_ring():
    # a 300,000-car ring on the product path (contour counts of a few tenths of a second each),
    # interrupted a quarter into its work
    call = lambda: ddemap.mixed_ring("A_min,C_max", ring=300000, count=6)
    full, at, took = _interrupted_after(call, 0.25)
    assert full > 1, full  # long enough that stopping early is visible
    # the callback checks after every contour count (at most 20 times a second): the call stops
    # within a few counts of the signal, long before its end (it would need 0.75 full more)
    assert took - at <= 0.35 * full, (took, at, full)
    assert took < 0.6 * full, (took, at, full)
    # the module still works
    assert ddemap.mixed_ring("A_min,C_max", ring=20, count=4)["ring_stable"] in (True, False)


@pytest.mark.slow
def test_ctrl_c_stops_a_long_system_roots(tmp_path):
    # a sparse circulant system x_i' = -x_i + 0.95 x_{i-1}(t - 1) of 6000 states, 200 roots (a
    # dense band of them, about 2.5 s): the sparse path's Arnoldi shifts, interrupted between shifts
    n = 6000
    triplets = [[i, (i - 1) % n, 0.95] for i in range(n)]
    system = tmp_path / "circulant.json"
    system.write_text(json.dumps({"dimension": n, "delays": [1.0], "A0": {"triplets": [[i, i, -1.0] for i in range(n)]},
                                  "A": [{"triplets": triplets}]}))
    call = lambda: ddemap.roots(system=str(system), count=200, solver="sparse")
    full, at, took = _interrupted_after(call, 0.25)
    assert full > 1, full
    # checked before every shift: stopped within a few shifts of the signal, long before the end
    assert took - at <= 0.35 * full, (took, at, full)
    assert took < 0.6 * full, (took, at, full)


@pytest.mark.slow
def test_ctrl_c_stops_the_dense_step_of_an_infinite_ring():
    # N = inf near the edge of the computable range: after a short scan of wave numbers, the search
    # for the 5 roots at the abscissa's wave number climbs from M = 22 to M = 400 in one dense degree (a
    # complex eigenvalue problem of 802 states, most of the call). The check comes between stages
    # of that eigenvalue problem (every 16 Householder columns or 32 QR steps), so a signal half
    # way through the call stops it within a small part of the whole, where it used to run the
    # degree to its end.
    call = lambda: ddemap.roots(k1=19, k2=0.2, th=1.5, tau=0.2, ring="inf", count=5)
    full, at, took = _interrupted_after(call, 0.5)
    assert full > 1, full
    assert took - at <= 0.1 * full, (took, at, full)
    # the module still works, and gives the ring's verdict
    assert ddemap.roots(k1=0.2, k2=0.2, th=1.5, tau=0.1, ring="inf", count=2)["ring_stable"] in (True, False)


@pytest.mark.slow
def test_atlas_matches_the_command_bit_for_bit_and_a_sweep(tmp_path):
    # the module's atlas against `ddemap atlas` (an independent driver: chunk store, slabs): the
    # same HDF5 bytes; and one (k1, k2) plane against `sweep` over the same axes
    spec = os.path.join(SOURCE, "maps", "atlas-example.toml")
    r = ddemap.atlas(spec, out=tmp_path / "py")
    cli("atlas", spec, "--out", str(tmp_path / "cli") + "/", "--quiet")
    with open(tmp_path / "py" / "atlas.h5", "rb") as a, open(tmp_path / "cli" / "atlas.h5", "rb") as b:
        assert a.read() == b.read()
    assert list(r["shape"]) == [2, 2, 2, 16, 16] and r["points"] == 2048 and r.status == "converged"
    assert sum(r["regions"].values()) == 2048
    f, c = r["fields"], r["coordinates"]
    assert f["string_stable"].shape == (2, 2, 2, 16, 16) and list(c["ring"]) == [22, 0]
    s = ddemap.sweep(th=2.0, tau=0.4, eta=10.0, k1=(0.01, 1.0, 16), k2=(0.01, 1.0, 16), ring=22, boundaries=False)
    # sweep grids are (k2, k1), the atlas's last two axes (k1, k2); the sweep continues its peak
    # search along k1, the atlas's chunks along k2: the same maxima to rounding (measured: 1 ulp)
    assert np.array_equal(np.asarray(s["grid"]["string_stable"], dtype=bool), f["string_stable"][0, 1, 1].T.astype(bool))
    assert np.allclose(s["grid"]["sup_gamma"], f["sup_gamma"][0, 1, 1].T, rtol=1e-13, atol=0)
    # a result that round-trips through JSON keeps its arrays
    back = ddemap.Result.from_json(r.to_json())
    assert back["fields"]["sup_gamma"].shape == f["sup_gamma"].shape


def test_atlas_is_sized_before_the_work():
    big = textwrap.dedent("""
        model = "ovrv"
        rings = [1000000]
        ring_method = "modes"
        [fixed]
        eta = 10.0
        th = 1.5
        [[axis]]
        name = "tau"
        lo = 0.1
        hi = 0.5
        count = 100
        [[axis]]
        name = "k1"
        lo = 0.01
        hi = 1
        count = 100
        [[axis]]
        name = "k2"
        lo = 0.01
        hi = 1
        count = 100
        """)
    t = time.monotonic()
    with pytest.raises(ValueError, match="above the limit of 600 s"):
        ddemap.atlas(big)
    assert time.monotonic() - t < 5


@pytest.mark.slow
def test_design_of_a_fit_is_judged_under_its_uncertainty_as_the_command(tmp_path):
    # a car with a covariance (what calibrate writes): the same envelope as the command, with the
    # probability of string stability and the worst margin over the ellipsoid (once missing in Python)
    names = ["k1", "k2", "th", "tau", "eta"]
    cols = ["cov_%s_%s" % (names[i], names[j]) for i in range(5) for j in range(i, 5)]
    cov = dict.fromkeys(cols, 0.0)
    cov.update(cov_tau_tau=0.02 ** 2, cov_th_th=0.05 ** 2, cov_k1_k1=1e-6, cov_k2_k2=1e-4)
    path = tmp_path / "fit.csv"
    path.write_text("name,k1,k2,th,tau,eta," + ",".join(cols) + "\nCfit,0.018,0.152,1.986,0.324,13.81," + ",".join(repr(cov[c]) for c in cols) + "\n")
    r = ddemap.design(path, objective="nearest", progress=False)
    same_envelope(r, cli_json("design", path, "--objective", "nearest"))
    u = r["uncertainty"]
    assert 0 <= u["design"]["p_string_stable"] <= 1 and u["worst_case"]["design"]["held"] == ["th", "tau"]
    assert u["worst_case"]["design"]["attenuation_margin"] <= r["attenuation_margin"]
    # robust: the margin of the worst point of the ellipsoid, as --robust; refused without a covariance
    rr = ddemap.design(path, objective="nearest", robust=True, progress=False)
    same_envelope(rr, cli_json("design", path, "--objective", "nearest", "--robust"))
    assert rr["robust"]["met"] is True and len(rr["robust"]["steps"]) >= 1
    assert rr["uncertainty"]["worst_case"]["design"]["attenuation_margin"] >= 0.1 * (1 - 1e-6)
    assert r["robust"] is None
    with pytest.raises(ValueError, match="robust: the car C_max has no covariance"):
        ddemap.design("C_max", robust=True, progress=False)


def test_sweep_peak_as_the_command(tmp_path):
    # the peak notion in a sweep: the grid's peak_stable implies string_stable, the same envelope as --peak
    r = ddemap.sweep(k1=(0.005, 0.2, 4), k2=(0.7, 1.1, 4), th=1.5, tau=0.3, boundaries=False, peak=True, progress=False)
    same_envelope(r, cli_json("sweep", "--k1", "0.005:0.2:4", "--k2", "0.7:1.1:4", "--th", "1.5", "--tau", "0.3", "--no-boundaries", "--peak",
                              "--out", str(tmp_path / "s")))
    g = r["grid"]
    assert (g["peak_stable"] <= g["string_stable"]).all()
    assert g["peak_stable"].any() and (g["string_stable"] & ~g["peak_stable"]).any()
    assert r["regions"]["peak_stable"] == int(g["peak_stable"].sum())
