// Calibration: synthetic recovery (data from the platoon simulator, with noise) and real
// measured traces (data/openacc of the repository).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/study/growth.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
/// 300 s at 10 Hz behind a lead with three frequencies, follower from simulate_platoon (its own
/// equilibrium history, an independent code path from simulate_follower), noise added.
Trace synthetic(const ParameterMap& p, unsigned seed) {
    std::vector<double> t, v;
    for (int k = 0; k <= 3000; ++k) {
        const double x = 0.1 * k;
        t.push_back(x);
        v.push_back(20 + 2 * std::sin(0.1 * x) + 1.5 * std::sin(0.27 * x + 1) + 0.8 * std::sin(0.6 * x));
    }
    std::shared_ptr<const CarModel> m = make_model("ovrv", p);
    SimOptions o;
    o.t_end = 300;
    o.step = 0.02;
    const SimResult r = simulate_platoon(LeadProfile(t, v), {SimCar{m, 0.0, "x"}}, o);
    std::mt19937 rng(seed);
    std::normal_distribution<double> nv(0, 0.05), ng(0, 0.2);
    Trace tr;
    tr.source = "synthetic";
    for (std::size_t k = 0; k < r.time.size(); ++k) {
        tr.t.push_back(r.time[k]);
        tr.lead.push_back(r.speed[0][k]);
        tr.speed.push_back(r.speed[1][k] + nv(rng));
        tr.gap.push_back(r.gap[1][k] + ng(rng));
    }
    return tr;
}
}  // namespace

TEST_CASE("calibration recovers known parameters from noisy synthetic data" * doctest::test_suite("slow")) {
    // tolerances: 10% (+0.002) in k1, 5% in k2, 0.05 s in th, 0.03 s in tau, 0.5 m in eta, with
    // noise of 0.05 m/s on speed and 0.2 m on gap
    const double sets[][5] = {{0.05, 0.3, 1.2, 0.4, 8}, {0.1, 0.2, 1.8, 0.9, 6}, {0.03, 0.5, 0.8, 0.15, 12}};
    unsigned seed = 1;
    for (const auto& s : sets) {
        const ParameterMap p{{"k1", s[0]}, {"k2", s[1]}, {"th", s[2]}, {"tau", s[3]}, {"eta", s[4]}};
        const CalibrationResult r = calibrate(synthetic(p, seed++));
        CAPTURE(s[3]);
        CHECK(std::abs(r.parameters.at("k1") - s[0]) <= 0.1 * s[0] + 0.002);
        CHECK(std::abs(r.parameters.at("k2") - s[1]) <= 0.05 * s[1]);
        CHECK(std::abs(r.parameters.at("th") - s[2]) <= 0.05);
        CHECK(std::abs(r.parameters.at("tau") - s[3]) <= 0.03);
        CHECK(std::abs(r.parameters.at("eta") - s[4]) <= 0.5);
        CHECK(r.all.rmse_speed < 0.06);  // the noise level: nothing left to explain
        CHECK(r.status != "failure");
    }
}

TEST_CASE("calibrate_many gives each trace the fit of calibrate alone, in order, and rethrows errors" * doctest::test_suite("slow")) {
    CalibrationOptions o;
    const std::vector<Trace> traces = {synthetic({{"k1", 0.05}, {"k2", 0.3}, {"th", 1.2}, {"tau", 0.4}, {"eta", 8}}, 1),
                                       synthetic({{"k1", 0.1}, {"k2", 0.2}, {"th", 1.8}, {"tau", 0.9}, {"eta", 6}}, 2)};
    const auto fits = calibrate_many(traces, o);
    REQUIRE(fits.size() == 2);
    for (std::size_t i = 0; i < 2; ++i) {
        const CalibrationResult one = calibrate(traces[i], o);
        for (const char* k : {"k1", "k2", "th", "tau", "eta"}) CHECK(fits[i].parameters.at(k) == one.parameters.at(k));
    }
    o.train_start = 0.0;
    o.train_end = 5.0;  // shorter than 20 s: every trace is rejected inside the parallel loop
    CHECK_THROWS_AS(calibrate_many(traces, o), std::invalid_argument);
}

TEST_CASE("bad traces are rejected with the line and column") {
    std::string ok = "time_s,lead_speed_mps,follower_speed_mps,gap_m\n";
    for (int k = 0; k < 300; ++k) ok += std::to_string(0.1 * k) + ",20,20,30\n";
    CHECK_NOTHROW(read_trace_csv(ok, "ok.csv"));
    CHECK_THROWS_WITH_AS(read_trace_csv("time_s,lead_speed_mps,follower_speed_mps,gap_m\n0,1,1,nan\n", "a.csv"),
                         "a.csv:2: column 'gap_m' = 'nan': expected a finite number", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_trace_csv("time_s,lead_speed_mps,follower_speed_mps,gap_m\n0,1,1,1\n0,1,1,1\n", "b.csv"),
                         "b.csv:3: time_s = 0 after 0: expected increasing times", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_trace_csv("time_s,lead_speed_mps,gap_m\n0,1,1\n", "c.csv"),
                         "c.csv:1: missing column 'follower_speed_mps' (expected time_s, lead_speed_mps, follower_speed_mps, gap_m)",
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_trace_csv("time_s,lead_speed_mps,follower_speed_mps,gap_m\n0,1,1,1\n0.1,1,1,1\n", "d.csv"),
                         "d.csv: 2 rows over 0.1 s: expected at least 100 rows and 20 s", std::invalid_argument);
    CalibrationOptions o;
    o.set_bounds("eta", 20, 15);
    CHECK_THROWS_AS(o.validate(), std::invalid_argument);
    // gaps a sensor cannot mean are refused with the sample
    std::string huge = ok;
    huge.replace(huge.find("30\n", 50), 3, "1e160\n");
    CHECK_THROWS_WITH_AS(read_trace_csv(huge, "h.csv"), doctest::Contains("gap_m = 1e+160: expected at most 10000 m"), std::invalid_argument);
    std::string deep = ok;
    deep.replace(deep.find("30\n", 50), 3, "-200\n");
    CHECK_THROWS_WITH_AS(read_trace_csv(deep, "g.csv"), doctest::Contains("gap_m = -200: expected a gap above -100 m"), std::invalid_argument);
    // a sampling step of exactly 1 ms (as decimal times: 0.001 * k rounds below 1e-3) is accepted
    std::string ms = "time_s,lead_speed_mps,follower_speed_mps,gap_m\n";
    char line[64];
    for (int k = 0; k <= 20500; ++k) {
        std::snprintf(line, sizeof line, "%.3f,20,20,30\n", 0.001 * k);
        ms += line;
    }
    CHECK_NOTHROW(read_trace_csv(ms, "ms.csv"));
}

TEST_CASE("calibrate warns of a gap of 0 m or less that it keeps, naming the sample" * doctest::test_suite("slow")) {
    Trace tr = synthetic({{"k1", 0.1}, {"k2", 0.4}, {"th", 1.2}, {"tau", 0.4}, {"eta", 8}}, 11);
    tr.gap[1000] = -5.0;  // one bad reading of 3,001: kept (at most 1 % may be), but said
    CalibrationOptions o;
    o.design_points = 8;
    o.starts = 1;
    o.lead_noise = 0.0;
    const CalibrationResult r = calibrate(tr, o);
    bool said = false;
    for (const auto& w : r.warnings) said = said || w.find("1 of 3001 gaps are 0 m or less (the first at sample 1001") != std::string::npos;
    CHECK(said);
}

TEST_CASE("calibration bounds are named: defaults are the paper's, errors name the parameter") {
    CalibrationOptions o;
    CHECK_NOTHROW(o.validate());
    const double expect[5][2] = {{0, 1}, {0, 1}, {0, 3}, {0, 1}, {5, 15}};
    for (int i = 0; i < 5; ++i) {
        const BoundedParameter b = o.bound(calibration_parameter_names()[i]);
        CHECK(b.lower == expect[i][0]);
        CHECK(b.upper == expect[i][1]);
    }
    o.set_bounds("eta", 0, 15);
    CHECK(o.bound("eta").lower == 0.0);
    CHECK(o.bounds.size() == 5);  // replaced, not added
    CHECK_NOTHROW(o.validate());
    {
        CalibrationOptions u;
        u.set_bounds("k4", 0, 1);
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'k4': unknown parameter, expected one of k1, k2, th, tau, eta", std::invalid_argument);
        CHECK_THROWS_WITH_AS(u.bound("k4"), doctest::Contains("'k4'"), std::invalid_argument);
    }
    {
        CalibrationOptions u;
        u.set_bounds("th", 2, 1);
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'th' = 2:1: expected lower <= upper", std::invalid_argument);
    }
    {
        CalibrationOptions u;
        u.set_bounds("k2", 0, INFINITY);
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'k2' = 0:inf: expected finite bounds", std::invalid_argument);
        u.set_bounds("k2", NAN, 1);
        CHECK_THROWS_WITH_AS(u.validate(), doctest::Contains("bounds for 'k2'"), std::invalid_argument);
    }
    {
        CalibrationOptions u;
        u.set_bounds("k1", -1, 1);
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'k1' = -1:1: expected lower >= 0", std::invalid_argument);
        u.set_bounds("k1", 0, 1);
        u.set_bounds("tau", 0, 6);
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'tau': upper = 6: expected at most 5 s", std::invalid_argument);
    }
    {
        CalibrationOptions u;
        u.bounds.push_back({"k1", 0.1, 0.2});
        CHECK_THROWS_WITH_AS(u.validate(), "bounds for 'k1' are given twice", std::invalid_argument);
    }
    {
        // listing only some parameters keeps the paper's bounds for the rest
        CalibrationOptions u;
        u.bounds = {{"tau", 0.2, 0.2}};
        CHECK_NOTHROW(u.validate());
        CHECK(u.bound("eta").lower == 5.0);
        CHECK(u.bound("tau").upper == 0.2);
    }
}

TEST_SUITE_END();
