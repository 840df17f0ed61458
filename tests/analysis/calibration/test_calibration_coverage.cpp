// Calibration intervals: over many noise realisations of one synthetic trace, with noise
// correlated in time like GNSS errors (AR(1), correlation time about 1 s at 10 Hz), the
// corrected 95 % intervals contain the truth in about 95 % of the cases. Two wrong methods
// fall outside the band: the textbook sigma^2 (J^T J)^-1, which treats the 10 Hz samples as
// independent (covers about a third), and the Newey-West covariance with the normal quantile
// 1.96 instead of the fixed-b critical value (covers about 0.89: with a bandwidth that is a
// sizeable part of the trace the HAC t-statistic has heavier tails than the normal).
// An earlier version used 40 realisations and measured 0.92: with 200 intervals the band had
// to be wide enough to pass the normal-quantile method too; 200 realisations separate them.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <vector>

#include "analysis/calibration/calibration_helpers.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("calibration intervals cover the truth at their level under correlated noise" * doctest::test_suite("slow")) {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace clean = calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(150), 150);
    CalibrationOptions o = calib_test::coverage_options();
    o.lead_noise = 0.0;  // the lead speed of this trace is exact (the next case adds noise to it)
    const int realisations = 200;
    int covered = 0, covered_normal = 0, covered_independent = 0, total = 0;
    int covered_by[5] = {0, 0, 0, 0, 0};
    for (int s = 0; s < realisations; ++s) {
        const CalibrationResult r = calibrate(calib_test::noisy(clean, 1000u + static_cast<unsigned>(s), 0.05, 0.2, 0.9), o);
        REQUIRE(r.status_code == Status::Converged);
        for (int i = 0; i < 5; ++i) {
            const auto& e = r.estimates[static_cast<std::size_t>(i)];
            const bool in = e.lower95 <= truth[i] && truth[i] <= e.upper95;
            covered += in;
            covered_by[i] += in;
            covered_normal += std::abs(e.value - truth[i]) <= 1.96 * e.standard_error;
            covered_independent += std::abs(e.value - truth[i]) <= 1.96 * std::sqrt(r.covariance_independent(i, i));
            ++total;
        }
    }
    const double rate = static_cast<double>(covered) / total, rate_normal = static_cast<double>(covered_normal) / total,
                 rate_independent = static_cast<double>(covered_independent) / total;
    MESSAGE("coverage of the 95 % intervals (" << total << " intervals): fixed-b Newey-West " << rate << " (k1 " << covered_by[0] / static_cast<double>(realisations)
                                                << ", k2 " << covered_by[1] / static_cast<double>(realisations) << ", th " << covered_by[2] / static_cast<double>(realisations) << ", tau "
                                                << covered_by[3] / static_cast<double>(realisations) << ", eta " << covered_by[4] / static_cast<double>(realisations) << "), Newey-West with 1.96 "
                                                << rate_normal << ", independent " << rate_independent);
    const double lo = 0.95 - test::tol::coverage_band, hi = 0.95 + test::tol::coverage_band;
    CHECK(rate >= lo);
    CHECK(rate <= hi);
    // the band separates the method from wrong ones
    CHECK(!(rate_independent >= lo && rate_independent <= hi));
    CHECK(!(rate_normal >= lo && rate_normal <= hi));
}

// Errors in variables: the same trace with white noise on all three measured signals, the lead
// speed included (0.05 m/s on both speeds, 0.2 m on the gap). Least squares takes the lead speed
// as exact; its noise reaches the residuals filtered by the car (and integrated into the gap),
// correlated over times the Newey-West bandwidth does not see: those intervals cover about 0.88.
// With the lead noise's share of the scores' covariance added (its level estimated from the lead
// speed), the pooled coverage is in the band the issue asks and every parameter near 0.95.
TEST_CASE("calibration intervals cover the truth with noise on the lead speed too (errors in variables)" * doctest::test_suite("slow")) {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace clean = calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(150), 150);
    CalibrationOptions o = calib_test::coverage_options();
    const int realisations = 200;
    const double lead_noise = 0.05;
    const std::vector<Trace> traces = calib_test::noisy_with_lead(clean, realisations, 0.05, 0.2, lead_noise);
    const std::vector<CalibrationResult> fits = calibrate_many(traces, o);
    int covered = 0, covered_exact_lead = 0, total = 0;
    int covered_by[5] = {0, 0, 0, 0, 0}, exact_by[5] = {0, 0, 0, 0, 0};
    double mean_noise = 0.0;
    for (const CalibrationResult& r : fits) {
        REQUIRE(r.status_code == Status::Converged);
        REQUIRE(r.lead_noise.size() == 1);
        CHECK(std::abs(r.lead_noise[0] / lead_noise - 1.0) <= 5 * test::tol::lead_noise_estimate);  // one trace: 1,500 samples
        mean_noise += r.lead_noise[0] / realisations;
        for (int i = 0; i < 5; ++i) {
            const auto& e = r.estimates[static_cast<std::size_t>(i)];
            const bool in = e.lower95 <= truth[i] && truth[i] <= e.upper95;
            const bool in_exact = std::abs(e.value - truth[i]) <= r.critical_value * std::sqrt(r.covariance_exact_lead(i, i));
            covered += in;
            covered_by[i] += in;
            covered_exact_lead += in_exact;
            exact_by[i] += in_exact;
            ++total;
        }
    }
    const double rate = static_cast<double>(covered) / total, rate_exact = static_cast<double>(covered_exact_lead) / total;
    std::ostringstream per;
    const char* names[5] = {"k1", "k2", "th", "tau", "eta"};
    for (int i = 0; i < 5; ++i) per << " " << names[i] << " " << covered_by[i] / static_cast<double>(realisations) << " (lead exact " << exact_by[i] / static_cast<double>(realisations) << ")";
    MESSAGE("coverage with lead noise: " << rate << ", lead taken as exact " << rate_exact << ";" << per.str() << "; mean estimated lead noise " << mean_noise);
    CHECK(std::abs(mean_noise / lead_noise - 1.0) <= test::tol::lead_noise_estimate);
    CHECK(std::abs(rate - 0.95) <= test::tol::coverage_band_lead_noise);
    CHECK(std::abs(rate_exact - 0.95) > test::tol::coverage_band_lead_noise);  // the band fails the method that ignores the lead's noise
    for (int i = 0; i < 5; ++i) CHECK(std::abs(covered_by[i] / static_cast<double>(realisations) - 0.95) <= test::tol::coverage_band);
}

// The penalty of the lead-noise correction (one simulation with one lead sample raised, its
// response summed over lags) against its definition: the mean increase of the objective when
// white noise is added to the lead speed, over 400 Monte Carlo draws (relative standard error
// about 0.5 % on a noise-free trace, where the cross term vanishes).
TEST_CASE("lead_noise_penalty is the mean increase of the objective under white lead noise") {
    for (const auto& car : {std::array<double, 5>{0.8, 0.95, 0.9, 0.15, 8}, std::array<double, 5>{0.05, 0.3, 1.2, 0.43, 8}}) {
        const double truth[5] = {car[0], car[1], car[2], car[3], car[4]};
        const Trace clean = calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(100), 100);
        CalibrationOptions o;
        o.lead_noise = 0.05;
        const ParameterMap p = calib_test::ovrv(truth);
        const double base = calibration_objective(clean, p, o), penalty = lead_noise_penalty(clean, p, o);
        const int draws = 400;
        std::mt19937 rng(4242u);
        std::normal_distribution<double> z(0.0, 1.0);
        double mean = 0.0;
        for (int m = 0; m < draws; ++m) {
            Trace noisy = clean;
            for (double& v : noisy.lead) v += 0.05 * z(rng);
            mean += (calibration_objective(noisy, p, o) - base) / draws;
        }
        CAPTURE(car[1]);
        MESSAGE("k2 " << car[1] << ": penalty " << penalty << ", Monte Carlo " << mean);
        CHECK(penalty > 0.0);
        CHECK(std::abs(mean / penalty - 1.0) <= test::tol::lead_noise_penalty_vs_monte_carlo);
        // sigma^2 scaling, and nothing without noise
        o.lead_noise = 0.1;
        CHECK(lead_noise_penalty(clean, p, o) == doctest::Approx(4.0 * penalty).epsilon(1e-12));
        o.lead_noise = 0.0;
        CHECK(lead_noise_penalty(clean, p, o) == 0.0);
    }
}

TEST_CASE("calibrate: the lead-noise correction is applied on even sampling only, and can be switched off") {
    const double truth[5] = {0.8, 0.95, 0.9, 0.15, 8};
    Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(60), 60), 5u, 0.05, 0.2, 0.0);
    std::mt19937 rng(99u);
    std::normal_distribution<double> z(0.0, 1.0);
    for (double& v : tr.lead) v += 0.05 * z(rng);
    CalibrationOptions o = calib_test::coverage_options();
    const CalibrationResult r = calibrate(tr, o);
    CHECK(r.lead_noise_corrected);
    CHECK(r.minimised_objective < r.objective);  // the penalty is positive
    o.lead_noise_correction = false;
    const CalibrationResult plain = calibrate(tr, o);
    CHECK(!plain.lead_noise_corrected);
    CHECK(plain.minimised_objective == plain.objective);
    CHECK(plain.k2 < r.k2);  // the bias the correction removes: plain least squares is slower
    // uneven sampling (every third step 20 % longer): not corrected, and said so
    Trace uneven = tr;
    double shift = 0.0;
    for (std::size_t k = 1; k < uneven.t.size(); ++k) {
        if (k % 3 == 0) shift += 0.02;
        uneven.t[k] += shift;
    }
    o.lead_noise_correction = true;
    const CalibrationResult u = calibrate(uneven, o);
    CHECK(!u.lead_noise_corrected);
    bool warned = false;
    for (const std::string& w : u.warnings) warned = warned || w.find("not evenly spaced") != std::string::npos;
    CHECK(warned);
}

TEST_CASE("lead_noise_estimate: white noise on a smooth speed, uneven sampling, and an exact lead") {
    std::mt19937 rng(5);
    std::normal_distribution<double> z(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.05, 0.15);
    Trace tr;
    double t = 0.0;
    for (int k = 0; k < 20000; ++k) {
        tr.t.push_back(t);
        tr.lead.push_back(20 + 2 * std::sin(0.1 * t) + 0.8 * std::sin(0.6 * t));
        t += u(rng);
    }
    Trace noisy = tr;
    for (double& v : noisy.lead) v += 0.07 * z(rng);
    CHECK(std::abs(lead_noise_estimate(noisy) / 0.07 - 1.0) <= test::tol::lead_noise_estimate);
    // the smooth speed alone leaves about h^2 |v''| / 2 <= 0.01 * 0.4 m/s
    CHECK(lead_noise_estimate(tr) < 0.005);
    // a window of fewer than 10 samples estimates nothing
    CHECK(lead_noise_estimate(noisy, 0.0, 0.5) == 0.0);
}

TEST_CASE("calibrate: lead_noise = 0 takes the lead speed as exact, and a bad level or draw count is refused") {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(40), 40), 3u, 0.05, 0.2, 0.0);
    CalibrationOptions o;
    o.design_points = 4;
    o.starts = 1;
    o.lead_noise = 0.0;
    const CalibrationResult r = calibrate(tr, o);
    CHECK(r.covariance == r.covariance_exact_lead);
    REQUIRE(r.lead_noise.size() == 1);
    CHECK(r.lead_noise[0] == 0.0);
    // a given level adds to the variance of every free parameter
    o.lead_noise = 0.1;
    o.lead_noise_draws = 50;
    const CalibrationResult g = calibrate(tr, o);
    CHECK(g.lead_noise[0] == 0.1);
    for (int i = 0; i < 5; ++i) CHECK(g.covariance(i, i) >= g.covariance_exact_lead(i, i));
    for (double bad : {11.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        o.lead_noise = bad;
        CHECK_THROWS_AS(o.validate(), std::invalid_argument);
    }
    o.lead_noise = -1.0;
    o.lead_noise_draws = 19;
    CHECK_THROWS_AS(o.validate(), std::invalid_argument);
}

TEST_SUITE_END();

// Errors in variables for a quick car (k2 = 0.95 1/s, tau = 0.15 s), the same noise on all
// three signals: least squares takes the noisy lead speed as exact, and the simulated follower
// then carries the noise's response, which grows with the car's responsiveness; the fit buys it
// down with sluggish gains (k2 about 0.75, tau about 0.06 s: its intervals cover k1, k2 and tau
// in about a third of the draws). The corrected objective |r|^2 - P(theta) removes that share
// in expectation: the estimates centre on the truth and the intervals cover at their level.
// Bounds k1, k2 in [0, 3] keep the truth away from the paper's upper bound 1 (where the estimates
// would be cut off). th and eta cover about 0.91 here with or without lead noise (measured: 0.93
// with follower-speed noise alone, 0.96 with gap noise alone): the speed noise also reaches the
// fit through the history the simulation starts from, which the covariance does not count
// (docs/guide/calibration.md, "Known limit: th and eta of a quick car"); their band shows that.
TEST_CASE("calibration corrects the lead noise's bias: a quick car's estimates centre on the truth and its intervals cover" * doctest::test_suite("slow")) {
    const double truth[5] = {0.8, 0.95, 0.9, 0.15, 8};
    const Trace clean = calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(150), 150);
    CalibrationOptions o = calib_test::coverage_options();
    o.set_bounds("k1", 0.0, 3.0);
    o.set_bounds("k2", 0.0, 3.0);
    const int realisations = 200;
    const std::vector<Trace> traces = calib_test::noisy_with_lead(clean, realisations);
    struct Summary {
        double cover[5] = {0, 0, 0, 0, 0}, mean[5] = {0, 0, 0, 0, 0}, sd[5] = {0, 0, 0, 0, 0};
    };
    // (least squares on wide bounds may stop at its iteration limit on the flat k2-tau valley it
    // is pulled into: those fits are summarised as they are)
    auto summarise = [&](const std::vector<CalibrationResult>& fits, bool require_converged) {
        Summary sm;
        const double m = static_cast<double>(fits.size());
        for (const CalibrationResult& r : fits) {
            CAPTURE(r.message);
            if (require_converged) REQUIRE(r.status_code == Status::Converged);
            for (int i = 0; i < 5; ++i) {
                const auto& e = r.estimates[static_cast<std::size_t>(i)];
                sm.cover[i] += (e.lower95 <= truth[i] && truth[i] <= e.upper95) / m;
                sm.mean[i] += e.value / m;
            }
        }
        for (const CalibrationResult& r : fits)
            for (int i = 0; i < 5; ++i) sm.sd[i] += std::pow(r.estimates[static_cast<std::size_t>(i)].value - sm.mean[i], 2) / (m - 1.0);
        for (double& v : sm.sd) v = std::sqrt(v);
        return sm;
    };
    const std::vector<CalibrationResult> fits = calibrate_many(traces, o);
    for (const CalibrationResult& r : fits) CHECK(r.lead_noise_corrected);
    const Summary c = summarise(fits, true);
    o.lead_noise_correction = false;
    const std::vector<CalibrationResult> plain_fits = calibrate_many(std::vector<Trace>(traces.begin(), traces.begin() + 60), o);
    for (const CalibrationResult& r : plain_fits) CHECK(!r.lead_noise_corrected);
    const Summary p = summarise(plain_fits, false);
    const char* names[5] = {"k1", "k2", "th", "tau", "eta"};
    std::ostringstream per;
    for (int i = 0; i < 5; ++i)
        per << " " << names[i] << ": corrected " << c.mean[i] << " (sd " << c.sd[i] << ", covers " << c.cover[i] << "), least squares " << p.mean[i] << " (covers "
            << p.cover[i] << ");";
    MESSAGE("quick car, truth k1 0.8, k2 0.95, th 0.9, tau 0.15, eta 8:" << per.str());
    for (int i : {0, 1, 3}) {
        CAPTURE(i);
        // unbiased: the mean of 200 estimates within 3 of its standard errors of the truth
        CHECK(std::abs(c.mean[i] - truth[i]) <= 3.0 * c.sd[i] / std::sqrt(static_cast<double>(realisations)));
        CHECK(std::abs(c.cover[i] - 0.95) <= test::tol::coverage_band);
        // least squares fails both
        CHECK(std::abs(p.mean[i] - truth[i]) > 3.0 * p.sd[i] / std::sqrt(60.0));
        CHECK(p.cover[i] < 0.95 - 4 * test::tol::coverage_band);
    }
    for (int i : {2, 4}) {
        CAPTURE(i);
        CHECK(std::abs(c.mean[i] - truth[i]) <= 3.0 * c.sd[i] / std::sqrt(static_cast<double>(realisations)));
        CHECK(std::abs(c.cover[i] - 0.95) <= test::tol::coverage_band_history);
    }
}
