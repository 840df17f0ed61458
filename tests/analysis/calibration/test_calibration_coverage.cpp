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
    CalibrationOptions o;
    o.design_points = 16;  // the minimum is easy to find on this trace; the intervals are the point
    o.starts = 2;
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
    CalibrationOptions o;
    o.design_points = 16;
    o.starts = 2;
    const int realisations = 200;
    const double lead_noise = 0.05;
    std::vector<Trace> traces;
    for (int s = 0; s < realisations; ++s) {
        Trace tr = calib_test::noisy(clean, 1000u + static_cast<unsigned>(s), 0.05, 0.2, 0.0);
        std::mt19937 rng(77777u + static_cast<unsigned>(s));
        std::normal_distribution<double> z(0.0, 1.0);
        for (double& v : tr.lead) v += lead_noise * z(rng);
        traces.push_back(std::move(tr));
    }
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
