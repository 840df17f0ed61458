// Joint calibration: one parameter set fitted to several runs of the same car (the seed paper
// fits each car on its training runs and tests on the others). Two synthetic runs made from the
// same truth behind different leads: the joint fit recovers the truth, is at least as good as
// the truth on the stacked objective, and is better determined than either run alone.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "analysis/calibration/calibration_helpers.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

const double kTruth[5] = {0.05, 0.3, 1.2, 0.43, 8};

std::vector<Trace> two_runs() {
    const ParameterMap p = calib_test::ovrv(kTruth);
    const LeadProfile osc = LeadProfile::builtin("oscillatory");
    return {calib_test::noisy(calib_test::clean_trace(p, calib_test::three_sines(150), 150), 31u),
            calib_test::noisy(calib_test::clean_trace(p, osc, osc.duration() + 20.0), 32u)};
}

}  // namespace

TEST_CASE("joint calibration of two runs recovers the truth with narrower intervals than either run" * doctest::test_suite("slow")) {
    const std::vector<Trace> runs = two_runs();
    const CalibrationOptions o;
    const CalibrationResult joint = calibrate_joint(runs, o);
    const CalibrationResult one = calibrate(runs[0], o), two = calibrate(runs[1], o);
    REQUIRE(joint.status_code == Status::Converged);
    REQUIRE(one.status_code == Status::Converged);
    REQUIRE(two.status_code == Status::Converged);
    // the global minimum of the stacked objective: never above its value at the truth
    const ParameterMap truth = calib_test::ovrv(kTruth);
    CHECK(joint.objective <= calibration_objective(runs, truth, o) * (1.0 + 1e-9));
    CHECK(joint.objective == doctest::Approx(calibration_objective(runs, joint.parameters, o)).epsilon(test::tol::regrouped_sum));
    for (int i = 0; i < 5; ++i) {
        const ParameterEstimate& e = joint.estimates[static_cast<std::size_t>(i)];
        CAPTURE(e.name);
        CAPTURE(e.value);
        CAPTURE(e.standard_error);
        CAPTURE(one.estimates[static_cast<std::size_t>(i)].standard_error);
        CAPTURE(two.estimates[static_cast<std::size_t>(i)].standard_error);
        CHECK(std::isfinite(e.standard_error));
        CHECK(std::abs(e.value - kTruth[i]) <= 4.0 * e.standard_error);  // as the single-run recovery tests
        // more data, the same car: narrower than either run's interval
        CHECK(e.upper95 - e.lower95 < one.estimates[static_cast<std::size_t>(i)].upper95 - one.estimates[static_cast<std::size_t>(i)].lower95);
        CHECK(e.upper95 - e.lower95 < two.estimates[static_cast<std::size_t>(i)].upper95 - two.estimates[static_cast<std::size_t>(i)].lower95);
    }
    CHECK(joint.warnings.empty());
    // per run: its whole-file simulation and errors, pooled into `all`
    REQUIRE(joint.runs.size() == 2);
    CHECK(joint.all.samples == joint.runs[0].errors.samples + joint.runs[1].errors.samples);
    CHECK(joint.train.samples == one.train.samples + two.train.samples);
    for (std::size_t k = 0; k < 2; ++k) {
        CHECK(joint.runs[k].sim_speed.size() == runs[k].t.size());
        CHECK(joint.runs[k].errors.rmse_speed < 0.06);  // the noise level
        CHECK(joint.runs[k].errors.rmse_speed < joint.runs[k].naive.rmse_speed);
    }
}

TEST_CASE("joint calibration: the stacked objective is the sample-weighted mean of the runs' objectives and one run is calibrate") {
    const std::vector<Trace> runs = two_runs();
    const CalibrationOptions o;
    const ParameterMap p = calib_test::ovrv({0.08, 0.2, 1.0, 0.3, 10});
    // samples of each run: the training samples after t_0 + tau_max (tau_max = 1 s)
    auto samples = [](const Trace& tr) {
        int n = 0;
        for (double t : tr.t) n += t >= tr.t.front() + 1.0;
        return n;
    };
    const double n1 = samples(runs[0]), n2 = samples(runs[1]);
    CHECK(calibration_objective(runs, p, o) ==
          doctest::Approx((n1 * calibration_objective(runs[0], p, o) + n2 * calibration_objective(runs[1], p, o)) / (n1 + n2)).epsilon(test::tol::regrouped_sum));
    // a joint fit of one run is that run's fit
    const CalibrationResult j1 = calibrate_joint({runs[0]}, o), c1 = calibrate(runs[0], o);
    for (int i = 0; i < 5; ++i) {
        CHECK(j1.estimates[static_cast<std::size_t>(i)].value == c1.estimates[static_cast<std::size_t>(i)].value);
        CHECK(j1.estimates[static_cast<std::size_t>(i)].standard_error == c1.estimates[static_cast<std::size_t>(i)].standard_error);
    }
    CHECK(j1.all.rmse_speed == doctest::Approx(c1.all.rmse_speed).epsilon(test::tol::regrouped_sum));
    CHECK(j1.naive.rmse_speed == c1.naive.rmse_speed);
    CHECK_THROWS_AS(calibrate_joint({}, o), std::invalid_argument);
}

TEST_SUITE_END();

TEST_CASE("joint calibration: a run stacked with itself halves the covariance (no lags across runs)" * doctest::test_suite("fast")) {
    const Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(kTruth), calib_test::three_sines(90), 90), 41u, 0.05, 0.2, 0.9);
    const CalibrationOptions o;
    const CalibrationResult one = calibrate(tr, o), twice = calibrate_joint({tr, tr}, o);
    REQUIRE(one.status_code == Status::Converged);
    REQUIRE(twice.status_code == Status::Converged);
    // the same objective (the mean over identical runs), so the same minimum
    CHECK(twice.objective == doctest::Approx(one.objective).epsilon(test::tol::regrouped_sum));
    // H and Omega both double when the runs are independent: C = (2H)^-1 (2 Omega) (2H)^-1 = C / 2
    // (a Newey-West sum across the two copies would have kept C)
    double worst = 0.0;
    for (int i = 0; i < 5; ++i) {
        worst = std::max({worst, std::abs(twice.estimates[static_cast<std::size_t>(i)].value / one.estimates[static_cast<std::size_t>(i)].value - 1.0),
                          std::abs(twice.covariance(i, i) / (0.5 * one.covariance(i, i)) - 1.0)});
        CAPTURE(i);
        CHECK(twice.estimates[static_cast<std::size_t>(i)].value == doctest::Approx(one.estimates[static_cast<std::size_t>(i)].value).epsilon(test::tol::same_fit));
        CHECK(twice.covariance(i, i) == doctest::Approx(0.5 * one.covariance(i, i)).epsilon(test::tol::same_fit));
    }
    MESSAGE("largest relative difference from the exact relations: " << worst);
    CHECK(twice.critical_value == one.critical_value);
    CHECK(twice.bandwidth == one.bandwidth);
}
