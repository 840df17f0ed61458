// Calibration intervals: over many noise realisations of one synthetic trace, with noise
// correlated in time like GNSS errors (AR(1), correlation time about 1 s at 10 Hz), the
// corrected 95 % intervals contain the truth in about 95 % of the cases; the textbook
// sigma^2 (J^T J)^-1, which treats the 10 Hz samples as independent, covers far less.
#include <doctest/doctest.h>

#include <cmath>

#include "analysis/calibration_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("calibration intervals cover the truth at their level under correlated noise" * doctest::test_suite("slow")) {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace clean = calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(150), 150);
    CalibrationOptions o;
    o.design_points = 16;  // the minimum is easy to find on this trace; the intervals are the point
    o.starts = 2;
    const int realisations = 40;
    int covered = 0, covered_independent = 0, total = 0;
    for (int s = 0; s < realisations; ++s) {
        const CalibrationResult r = calibrate(calib_test::noisy(clean, 1000u + static_cast<unsigned>(s), 0.05, 0.2, 0.9), o);
        REQUIRE(r.status_code == Status::Converged);
        for (int i = 0; i < 5; ++i) {
            const auto& e = r.estimates[static_cast<std::size_t>(i)];
            covered += e.lower95 <= truth[i] && truth[i] <= e.upper95;
            covered_independent += std::abs(e.value - truth[i]) <= 1.96 * std::sqrt(r.covariance_independent(i, i));
            ++total;
        }
    }
    const double rate = static_cast<double>(covered) / total, rate_independent = static_cast<double>(covered_independent) / total;
    MESSAGE("coverage of the 95 % intervals: corrected " << rate << ", uncorrected " << rate_independent << " (" << total << " intervals)");
    CHECK(rate >= 0.88);
    CHECK(rate <= 0.995);
    CHECK(rate_independent < 0.75);  // the uncorrected covariance fails this band
}

TEST_SUITE_END();
