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

TEST_SUITE_END();
