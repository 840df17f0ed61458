// Calibration: recovery of known parameters from noisy synthetic traces (several parameter sets
// from the paper's table and beyond, several lead profiles), the objective never above the
// truth's, repeatability over design seeds, warnings, profile likelihoods and options.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "analysis/calibration/calibration_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

bool has_warning(const CalibrationResult& r, const std::string& part) {
    return std::any_of(r.warnings.begin(), r.warnings.end(), [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

/// fits `tr` and checks the truth against the fit's own intervals: every parameter within 4
/// standard errors (the 95 % interval is 1.96), the objective not above the truth's
void check_recovery(const Trace& tr, const double (&truth)[5], const CalibrationOptions& o = {}) {
    const CalibrationResult r = calibrate(tr, o);
    const ParameterMap p = calib_test::ovrv(truth);
    CHECK(r.status_code == Status::Converged);
    CHECK(r.status == "converged");
    CHECK(r.starts == o.starts);
    CHECK(r.evaluations >= o.design_points + r.starts);
    CHECK(r.jacobian_evaluations > 0);
    // the global minimum: never above the objective at the parameters that made the data
    CHECK(r.objective <= calibration_objective(tr, p, o) * (1.0 + 1e-9));
    for (int i = 0; i < 5; ++i) {
        const ParameterEstimate& e = r.estimates[static_cast<std::size_t>(i)];
        CAPTURE(e.name);
        CAPTURE(e.value);
        CAPTURE(truth[i]);
        CAPTURE(e.standard_error);
        CHECK(e.name == calibration_parameter_names()[static_cast<std::size_t>(i)]);
        CHECK(e.value == r.parameters.at(e.name));
        CHECK(std::isfinite(e.standard_error));
        CHECK(e.standard_error > 0.0);
        CHECK(std::abs(e.value - truth[i]) <= 4.0 * e.standard_error);
        CHECK(e.lower95 < e.value);
        CHECK(e.upper95 > e.value);
        CHECK(e.standard_error == doctest::Approx(std::sqrt(r.covariance(i, i))));
    }
    CHECK(r.k1 == r.parameters.at("k1"));
    CHECK(r.eta == r.parameters.at("eta"));
    CHECK(r.covariance.isApprox(r.covariance.transpose()));
    CHECK(r.correlation.diagonal().isOnes(1e-12));
    CHECK(r.correlation.cwiseAbs().maxCoeff() <= 1.0 + 1e-12);
    CHECK(r.rmse_speed < 0.06);  // the noise level: nothing left to explain
    CHECK(r.rmse_speed < r.naive_rmse_speed);
    CHECK(r.naive_rmse_speed == r.naive.rmse_speed);
    CHECK(!has_warning(r, "bound"));
    CHECK(!has_warning(r, "not determined"));
    CHECK(r.warnings.empty());
}

}  // namespace

TEST_CASE("calibration recovers known parameters within its own intervals (three sines, 150 s)") {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    check_recovery(calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(150), 150), 11), truth);
}

TEST_CASE("calibration recovers known parameters: the paper's table and beyond, several lead profiles" * doctest::test_suite("slow")) {
    struct Case {
        double p[5];
        const char* lead;  // a built-in profile or "sines"
        double duration;
    };
    const Case cases[] = {
        {{0.052, 0.338, 0.819, 0.948, 8.03}, "oscillatory", 0},  // A min
        {{0.022, 0.116, 2.020, 0.153, 8.21}, "sines", 300},      // B max
        {{0.029, 0.269, 0.907, 0.368, 10.07}, "step-low", 0},    // C min
        {{0.071, 0.191, 0.696, 0.582, 10.09}, "dip", 0},         // F min
        {{0.15, 0.6, 1.0, 0.6, 6.0}, "sines", 200},              // stiffer than any in the table
        {{0.012, 0.08, 2.5, 0.3, 12.0}, "oscillatory", 0},       // more sluggish than any
    };
    unsigned seed = 21;
    for (const Case& c : cases) {
        CAPTURE(c.lead);
        CAPTURE(c.p[0]);
        const bool sines = std::string(c.lead) == "sines";
        const LeadProfile lead = sines ? calib_test::three_sines(c.duration) : LeadProfile::builtin(c.lead);
        const double duration = sines ? c.duration : lead.duration() + 20.0;
        check_recovery(calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(c.p), lead, duration), seed++), c.p);
    }
}

TEST_CASE("calibration: other design seeds find the same minimum" * doctest::test_suite("slow")) {
    const double truth[5] = {0.052, 0.338, 0.819, 0.948, 8.03};
    const Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(120), 120), 5);
    CalibrationOptions o;
    const CalibrationResult r1 = calibrate(tr, o);
    for (unsigned seed : {2u, 3u}) {
        o.seed = seed;
        const CalibrationResult r = calibrate(tr, o);
        CHECK(r.objective == doctest::Approx(r1.objective).epsilon(1e-7));
        for (int i = 0; i < 5; ++i)
            CHECK(std::abs(r.estimates[static_cast<std::size_t>(i)].value - r1.estimates[static_cast<std::size_t>(i)].value) <=
                  0.01 * r1.estimates[static_cast<std::size_t>(i)].standard_error);
    }
}

TEST_CASE("calibration warns: a parameter on a bound, an undetermined parameter, a model worse than the naive predictor" * doctest::test_suite("slow")) {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(100), 100), 4);
    {
        CalibrationOptions o;
        o.set_bounds("tau", 0.0, 0.2);  // the truth (0.43 s) outside
        const CalibrationResult r = calibrate(tr, o);
        CHECK(r.estimates[3].at_bound);
        CHECK(r.tau == doctest::Approx(0.2));
        CHECK(has_warning(r, "tau = 0.2 is at its upper bound (0.2)"));
    }
    {
        // a fixed parameter: no uncertainty, no warning
        CalibrationOptions o;
        o.set_bounds("eta", 8, 8);
        const CalibrationResult r = calibrate(tr, o);
        CHECK(r.estimates[4].fixed);
        CHECK(r.estimates[4].standard_error == 0.0);
        CHECK(r.covariance.row(4).isZero());
        CHECK(!has_warning(r, "eta"));
    }
    {
        // a constant lead at equilibrium: only eta + th v* is seen, eta and th are not determined
        Trace flat = tr;
        for (std::size_t k = 0; k < flat.t.size(); ++k) {
            flat.lead[k] = 20.0;
            flat.speed[k] = 20.0 + 0.05 * std::sin(7.0 * k);
            flat.gap[k] = 32.0 + 0.2 * std::cos(5.0 * k);
        }
        const CalibrationResult r = calibrate(flat, {});
        CHECK(has_warning(r, "not determined"));
    }
    {
        // a follower that is the lead 3 s later, with a gap that contradicts the speeds
        Trace lag = tr;
        for (std::size_t k = 0; k < lag.t.size(); ++k) {
            lag.speed[k] = tr.lead[k >= 30 ? k - 30 : 0];
            lag.gap[k] = 25.0;
        }
        CalibrationOptions o;
        o.gap_weight = 1.0;
        const CalibrationResult r = calibrate(lag, o);
        CHECK(r.rmse_speed >= r.naive_rmse_speed);
        CHECK(r.naive_delay == doctest::Approx(3.0));
        CHECK(has_warning(r, "no better than the naive predictor"));
    }
}

TEST_CASE("calibration: profile likelihoods of tau and th agree with the intervals" * doctest::test_suite("slow")) {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(120), 120), 8);
    CalibrationOptions o;
    o.profile = {"tau", "th"};
    o.profile_points = 15;
    const CalibrationResult r = calibrate(tr, o);
    REQUIRE(r.profiles.size() == 2);
    for (const ProfileLikelihood& pl : r.profiles) {
        CAPTURE(pl.parameter);
        const int i = pl.parameter == "tau" ? 3 : 2;
        const ParameterEstimate& e = r.estimates[static_cast<std::size_t>(i)];
        REQUIRE(pl.values.size() == 15);
        REQUIRE(pl.objective.size() == 15);
        CHECK(std::is_sorted(pl.values.begin(), pl.values.end()));
        // the fit is the minimum of its own profile
        CHECK(*std::min_element(pl.objective.begin(), pl.objective.end()) >= r.minimised_objective * (1.0 - 1e-9));
        CHECK(pl.lower95 < e.value);
        CHECK(pl.upper95 > e.value);
        CHECK(!pl.lower_open);
        CHECK(!pl.upper_open);
        // near-quadratic here: the profile interval is close to the Wald interval
        const double wald = e.upper95 - e.lower95, prof = pl.upper95 - pl.lower95;
        CHECK(prof == doctest::Approx(wald).epsilon(0.3));
    }
    CHECK(!has_warning(r, "profile"));
}

TEST_CASE("calibration options: validate names the option") {
    CalibrationOptions o;
    CHECK(o.is_valid());
    o.starts = 0;
    CHECK(!o.is_valid());
    CHECK_THROWS_WITH_AS(o.validate(), "starts = 0: expected 1 to design points (64)", std::invalid_argument);
    o = {};
    o.design_points = 0;
    CHECK_THROWS_WITH_AS(o.validate(), "design points = 0: expected at least 1", std::invalid_argument);
    o = {};
    o.max_iterations = 0;
    CHECK_THROWS_WITH_AS(o.validate(), "max iterations = 0: expected at least 1", std::invalid_argument);
    o = {};
    o.profile = {"tau", "k4"};
    CHECK_THROWS_WITH_AS(o.validate(), "profile 'k4': unknown parameter, expected one of k1, k2, th, tau, eta", std::invalid_argument);
    o.profile = {"tau", "tau"};
    CHECK_THROWS_WITH_AS(o.validate(), "profile 'tau' is requested twice", std::invalid_argument);
    o.profile = {"eta"};
    o.set_bounds("eta", 8, 8);
    CHECK_THROWS_WITH_AS(o.validate(), "profile 'eta': the parameter is fixed by its bounds", std::invalid_argument);
    o = {};
    o.profile = {"th"};
    o.profile_points = 2;
    CHECK_THROWS_WITH_AS(o.validate(), "profile points = 2: expected at least 3", std::invalid_argument);
    o = {};
    o.function_tolerance = -1;
    CHECK_THROWS_WITH_AS(o.validate(), doctest::Contains("tolerance = -1"), std::invalid_argument);
}

TEST_SUITE_END();
