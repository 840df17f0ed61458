# Python inputs as a Python user has them: DataFrames, dicts of arrays, lists of rows, (t, v)
# pairs, os.PathLike, Results passed on; the answers are checked against the command line given
# the same cars as files (the CLI reads them with its own parser and prints JSON), and the
# simulate -> calibrate round trip against the parameters the platoon was simulated with.
import json
import math
import os
import pathlib
import subprocess
import warnings

import numpy as np
import pytest

import ddemap

from test_ddemap import CLI, _interrupted_after, cli, cli_json

pd = pytest.importorskip("pandas")

CARS = {"name": ["Sedan", "SUV", "Hatchback"], "k1": [0.12, 0.08, 0.2], "k2": [0.45, 0.3, 0.6],
        "th": [1.2, 1.6, 1.0], "tau": [0.6, 0.4, 0.3]}


def write_cars(path):
    with open(path, "w") as f:
        f.write(",".join(CARS) + "\n")
        for i in range(3):
            f.write(",".join(str(CARS[c][i]) for c in CARS) + "\n")


def verdicts(result):
    v = result["vehicles"]
    return list(v["name"]), list(v["string_stable"]), [float(x) for x in v["sup_gamma"]]


def test_classify_takes_a_dataframe_a_dict_rows_and_a_pathlike_like_the_cli(tmp_path):
    path = tmp_path / "mycars.csv"
    write_cars(path)
    reference = cli_json("classify", path)["result"]["vehicles"]
    expected = ([r["name"] for r in reference], [r["string_stable"] for r in reference], [r["sup_gamma"] for r in reference])
    rows = [{c: CARS[c][i] for c in CARS} for i in range(3)]
    for given in (pd.DataFrame(CARS), CARS, rows, path, str(path), [pd.DataFrame(CARS).iloc[:1], rows[1:]]):
        assert verdicts(ddemap.classify(given)) == expected, type(given)


def test_one_row_dict_and_a_mix_of_kinds():
    r = ddemap.classify([{"name": "Mine", "k1": 0.1, "k2": 0.4, "th": 1.5, "tau": 0.5}, "A_min"])
    assert list(r["vehicles"]["name"]) == ["Mine", "A_min"]


def test_wrong_types_are_type_errors_naming_the_accepted_ones():
    for bad in (3.5, object(), {1, 2}):
        with pytest.raises(TypeError, match="DataFrame"):
            ddemap.classify(bad)
    with pytest.raises(TypeError, match=r"\(t, v\) pair"):
        ddemap.simulate("A_min", lead=3)
    with pytest.raises(TypeError, match="os.PathLike"):
        ddemap.calibrate(42)


def test_bad_tables_name_the_problem():
    with pytest.raises(ValueError, match="columns of different lengths"):
        ddemap.classify({"name": ["a", "b"], "k1": [0.1]})
    with pytest.raises(ValueError, match="k2"):
        ddemap.classify(pd.DataFrame({"name": ["a"], "k1": [0.1], "th": [1.5], "tau": [0.5]}))


def test_simulate_with_a_dataframe_fleet_and_a_t_v_lead_matches_the_cli(tmp_path):
    path = tmp_path / "mycars.csv"
    write_cars(path)
    t = np.array([0.0, 20.0, 25.0, 60.0])
    v = np.array([22.0, 22.0, 19.0, 22.0])
    lead = tmp_path / "lead.csv"
    lead.write_text("time_s,lead_speed_mps\n" + "".join("%r,%r\n" % (a, b) for a, b in zip(t, v)))
    ref = cli_json("simulate", "--fleet", path, "--lead", lead, "--out", tmp_path / "s")["result"]
    r = ddemap.simulate(pd.DataFrame(CARS), lead=(t, v))
    assert [c["min_gap"] for c in ref["cars"]] == list(r["cars"]["min_gap"])
    r2 = ddemap.simulate(path, lead=pd.DataFrame({"time_s": t, "lead_speed_mps": v}))
    assert list(r2["cars"]["min_gap"]) == list(r["cars"]["min_gap"])


@pytest.mark.slow
def test_round_trip_simulate_noise_calibrate_recovers_the_parameters():
    truth = {"k1": 0.1, "k2": 0.5, "th": 1.4, "tau": 0.4, "eta": 8.0}
    sim = ddemap.simulate([truth | {"name": "Known"}, "A_min"], lead_profile="oscillatory", noise=(0.05, 0.1), seed=3)
    assert sim.inputs["noise_speed_sd"] == 0.05
    fits = ddemap.calibrate(sim, follower=1)
    assert list(fits["fits"]["name"]) == ["simulate1-1"]
    ci = fits["fits"]["ci95"]
    for p, value in truth.items():
        lo, hi = ci[p][0]
        assert lo <= value <= hi, (p, lo, hi, value)
    # the fits are cars: classify them, and the same from a DataFrame of the simulated series
    assert ddemap.classify(fits)["vehicles"]["name"][0] == "simulate1-1"
    s = sim["series"]
    frame = pd.DataFrame({"time_s": s["time"], "lead_speed_mps": s["speed"][0], "follower_speed_mps": s["speed"][1], "gap_m": s["gap"][1]})
    again = ddemap.calibrate(frame)
    assert abs(again["fits"]["k1"][0] - fits["fits"]["k1"][0]) < 1e-9


def test_pathlike_everywhere(tmp_path):
    path = tmp_path / "mycars.csv"
    write_cars(path)
    assert ddemap.mixed_ring(path, ring=6)["ring_stable"] in (True, False)
    assert ddemap.growth(pathlib.Path(path), followers=2)["vehicles"] is not None
    assert ddemap.mix(f"{path}:Sedan", "A_min", ring=10, p=(0, 1, 3))["points"]["p"].tolist() == [0.0, 0.5, 1.0]


def test_mix_and_growth_match_the_cli(tmp_path):
    ref = cli_json("mix", "--x", "A_min", "--y", "C_max", "--ring", "12", "--p", "0:1:3", "--out", tmp_path / "m")["result"]
    r = ddemap.mix("A_min", "C_max", ring=12, p=np.linspace(0, 1, 3))
    assert [p["spectral_abscissa"] for p in ref["points"]] == list(r["points"]["spectral_abscissa"])
    ref = cli_json("growth", "--fleet", "A_min", "--followers", "3")["result"]
    g = ddemap.growth("A_min", followers=3)
    assert json.loads(g.to_json())["result"] == ref


def test_axes_as_arrays_and_their_errors():
    a = ddemap.sweep(th=1.5, tau=0.1, k1=np.linspace(0.01, 1, 6), k2=(0.01, 1, 5))
    b = ddemap.sweep(th=1.5, tau=0.1, k1=(0.01, 1, 6), k2=(0.01, 1, 5))
    assert np.array_equal(a["grid"]["region"], b["grid"]["region"])
    with pytest.raises(ValueError, match="not increasing evenly"):
        ddemap.sweep(th=1.5, tau=0.1, k1=np.array([0.1, 0.2, 0.5]), k2=(0.01, 1, 5))


def test_rings_to_a_billion_and_inf_spellings():
    r = ddemap.string(th=1.5, tau=0.3, k1=0.1, k2=0.5, ring=10 ** 9)
    ref = cli_json("string", "--th", "1.5", "--tau", "0.3", "--k1", "0.1", "--k2", "0.5", "--ring", "1000000000")["result"]
    assert r["ring_stable"] == ref["ring_stable"]
    assert ddemap.string(th=1.5, tau=0.3, k1=0.1, k2=0.5, ring="Inf")["ring_stable"] == ddemap.string(th=1.5, tau=0.3, k1=0.1, k2=0.5, ring=math.inf)["ring_stable"]
    with pytest.raises(ValueError, match="10\\^9"):
        ddemap.string(th=1.5, tau=0.3, k1=0.1, k2=0.5, ring=10 ** 9 + 1)


@pytest.mark.slow
def test_calibrate_progress_is_one_counter():
    sim = ddemap.simulate("A_min,B_min", lead_profile="oscillatory", noise=(0.05, 0.1))
    for trace, cars in ((ddemap.simulate("A_min", lead_profile="oscillatory", noise=(0.05, 0.1)), 1), (sim, 2)):
        seen = []
        ddemap.calibrate(trace, warn=False, progress=lambda d, t: seen.append((d, t)))
        assert seen, "no progress reported"
        assert len({t for _, t in seen}) == 1, seen  # one total
        assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:])), seen  # a count that never goes back
        assert seen[-1][0] <= seen[-1][1]


def test_simulate_lead_result_without_car_is_a_type_error():
    s = ddemap.simulate("A_min", t_end=5)
    with pytest.raises(TypeError, match="expected \\(Result of simulate, K\\)"):
        ddemap.simulate("A_min", lead=s)


def test_results_round_trip_through_json():
    r = ddemap.classify("A_min,E_max")
    text = r.to_json()
    back = ddemap.Result.from_json(text)
    assert back.to_dict() == r.to_dict() == json.loads(text)
    assert back.status == r.status and list(back["vehicles"]["name"]) == ["A_min", "E_max"]
    s = ddemap.simulate("A_min", t_end=5)
    d = json.loads(s.to_json())
    assert len(d["extra"]["series"]["time"]) == len(s["series"]["time"])
    back = ddemap.Result.from_json(s.to_json())
    for key in s["series"]:  # the same NumPy arrays, not lists (2-D where the original is)
        assert isinstance(back["series"][key], np.ndarray) and back["series"][key].shape == np.shape(s["series"][key]), key
        assert np.array_equal(back["series"][key], s["series"][key], equal_nan=True), key


def test_progress_callback_and_its_exception():
    seen = []
    ddemap.sweep(th=1.5, tau=0.5, k1=(0.01, 1, 100), k2=(0.01, 1, 100), progress=lambda d, t: seen.append((d, t)))
    assert seen and all(0 <= d <= t for d, t in seen), seen[:3]

    class Stop(Exception):
        pass

    def stop(done, total):
        raise Stop()

    with pytest.raises(Stop):
        ddemap.sweep(th=1.5, tau=0.5, k1=(0.01, 1, 200), k2=(0.01, 1, 200), progress=stop)
    with pytest.raises(TypeError, match="progress"):
        ddemap.classify("A_min", progress="yes")


def test_fit_warnings_are_python_warnings(tmp_path):
    # a short trace whose lead hardly moves: the data hardly determine the parameters
    t = np.arange(0, 30, 0.1)
    frame = {"time_s": t, "lead_speed_mps": 20 + 0.01 * np.sin(t), "follower_speed_mps": 20 + 0.01 * np.sin(t - 0.5),
             "gap_m": 30 + 0.0 * t}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = ddemap.calibrate(frame)
    fit_warnings = [w for w in caught if issubclass(w.category, ddemap.CalibrationWarning)]
    assert fit_warnings and len(fit_warnings) == len(r["fits"]["warnings"][0])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ddemap.calibrate(frame, warn=False)
    assert not [w for w in caught if issubclass(w.category, ddemap.CalibrationWarning)]


@pytest.mark.slow
def test_ctrl_c_stops_one_calibrate_fit_within_a_second():
    # one long synthetic trace, one fit (on the calling thread): interrupted a quarter into it
    t = np.arange(0, 2400, 0.1)
    lead = 22 + 2 * np.sin(t / 15)
    sim = ddemap.simulate("A_min", lead=(t, lead))
    call = lambda: ddemap.calibrate(sim, warn=False, progress=False)
    full, at, took = _interrupted_after(call, 0.25)
    assert full > 1.5, full
    assert took - at < 1.0, (took, at, full)  # within a second of CPU time
    assert took < 0.7 * full, (took, at, full)


def test_chart_writes_what_the_cli_writes(tmp_path):
    spec = tmp_path / "c.toml"
    write_cars(tmp_path / "mycars.csv")
    spec.write_text('title = "My cars"\nring = 22\nvehicles = "mycars.csv"\n'
                    'x = { name = "k1", lo = 0.01, hi = 0.6, count = 12 }\ny = { name = "k2", lo = 0.01, hi = 1, count = 12 }\n')
    cli("chart", spec, "--out", tmp_path / "cli" / "c")
    r = ddemap.chart(spec, out=tmp_path / "py" / "c")
    assert r["panels"] == 3 and len(r["files"]) == 7
    for f in sorted(os.listdir(tmp_path / "cli")):
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    with pytest.raises(ValueError, match="out = ''"):
        ddemap.chart(spec, out="")


@pytest.mark.slow
def test_paper_writes_what_the_cli_writes(tmp_path):
    # the program's figures are the committed maps/*.svg (the paper test checks that): the
    # module's are the same bytes
    r = ddemap.paper(out=tmp_path / "py" / "paper")
    assert r.command == "paper"
    source = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    for mine, committed in (("paper.svg", "paper.svg"), ("paper-classification.svg", "classification.svg")):
        assert (tmp_path / "py" / mine).read_bytes() == pathlib.Path(source, "maps", committed).read_bytes(), mine
    for f in ("paper.json", "paper-classification.csv", "paper-growth.csv", "paper-panel1.csv", "paper-panel1-boundaries.csv"):
        assert (tmp_path / "py" / f).stat().st_size > 0, f


def test_text_that_is_not_utf8_and_control_characters_are_refused(tmp_path):
    # a Latin-1 name from an old spreadsheet: refused naming the line and the byte, as the CLI does
    latin1 = tmp_path / "latin1.csv"
    latin1.write_bytes(b"name,k1,k2,th,tau\nZo\xeb,0.1,0.2,1.5,0.3\n")
    with pytest.raises(ValueError, match=r"latin1.csv:2: byte 3 \(0xEB\) is not UTF-8"):
        ddemap.classify(latin1)
    # the same name as UTF-8 (a str from Python is always UTF-8) is taken and written back
    r = ddemap.classify({"name": ["Zo\u00eb"], "k1": [0.1], "k2": [0.2], "th": [1.5], "tau": [0.3]})
    assert r["vehicles"]["name"] == ["Zo\u00eb"]
    assert json.loads(r.to_json())["result"]["vehicles"][0]["name"] == "Zo\u00eb"
    with pytest.raises(ValueError, match="control characters"):
        ddemap.classify({"name": ["a\x01b"], "k1": [0.1], "k2": [0.2], "th": [1.5], "tau": [0.3]})


@pytest.mark.slow
def test_sweep_marks_cars_from_memory_as_the_command_does(tmp_path):
    # three cars of a DataFrame on one chart: the same SVG as `ddemap sweep --mark FILE`
    import pandas as pd
    cars = pd.DataFrame({"name": ["Sedan", "SUV", "Hatchback"], "k1": [0.2, 0.08, 0.15], "k2": [0.6, 0.3, 0.4],
                         "th": [2.0, 2.0, 2.0], "tau": [0.2, 0.2, 0.2]})
    cars.to_csv(tmp_path / "cars.csv", index=False)
    r = ddemap.sweep(th=2.0, tau=0.2, k1=(0.01, 0.4, 40), k2=(0.01, 1, 40), mark=cars, out=tmp_path / "py")
    subprocess.run([CLI, "sweep", "--th", "2", "--tau", "0.2", "--k1", "0.01:0.4:40", "--k2", "0.01:1:40", "--mark", str(tmp_path / "cars.csv"),
                    "--out", str(tmp_path / "cli"), "--quiet"], check=True, capture_output=True)
    svg = (tmp_path / "py.svg").read_text()
    assert svg == (tmp_path / "cli.svg").read_text()
    assert all(name in svg for name in ("Sedan", "SUV", "Hatchback"))
    assert (tmp_path / "py.csv").read_text() == (tmp_path / "cli.csv").read_text()
    assert r.inputs["mark"] == "<DataFrame 1>"
    # a car of another (tau, th) is named in a warning; a car without an axis's value is refused
    with pytest.warns(UserWarning, match="on a chart that is not its own"):
        ddemap.sweep(th=1.5, tau=0.2, k1=(0.01, 0.4, 8), k2=(0.01, 1, 8), mark=cars, boundaries=False)
    with pytest.raises(ValueError, match="has model idm"):
        ddemap.sweep(th=1.5, tau=0.2, k1=(0.01, 0.4, 8), k2=(0.01, 1, 8), mark="idm:th=1.5,tau=0.2,name=X", boundaries=False)
