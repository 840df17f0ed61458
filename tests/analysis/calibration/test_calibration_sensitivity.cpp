// The calibration's exact derivatives: the forward sensitivities of the simulated follower
// against central finite differences of the simulation itself.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "analysis/calibration/calibration_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

/// largest |sensitivity - finite difference| of speed and gap, relative to the largest |derivative|
void check_against_differences(const Trace& tr, const CalibrationVector& theta, double tol_tau) {
    const double t_a = tr.t.front(), t_b = tr.t.back(), step = 0.05;
    const FollowerTrajectory f = simulate_follower(tr, theta, t_a, t_b, step, true);
    REQUIRE(f.dspeed.rows() == static_cast<Eigen::Index>(f.speed.size()));
    REQUIRE(f.dgap.cols() == 5);
    for (int i = 0; i < 5; ++i) {
        // tau: forward differences. Where t0 = t_a + tau is a sample time the start value, read from
        // the piecewise-linear data, has a kink in tau; the sensitivities give the right derivative.
        const double h = (i == 3 ? 1e-7 : 1e-6) * std::max(1.0, std::abs(theta[i]));
        CalibrationVector up = theta, down = theta;
        up[i] += h;
        if (i != 3) down[i] -= h;
        const FollowerTrajectory fu = simulate_follower(tr, up, t_a, t_b, step, false);
        const FollowerTrajectory fd = simulate_follower(tr, down, t_a, t_b, step, false);
        double err = 0.0, scale = 0.0;
        for (std::size_t k = 0; k < f.speed.size(); ++k) {
            const auto r = static_cast<Eigen::Index>(k);
            const double width = i == 3 ? h : 2 * h;
            const double dv = (fu.speed[k] - fd.speed[k]) / width, ds = (fu.gap[k] - fd.gap[k]) / width;
            err = std::max({err, std::abs(dv - f.dspeed(r, i)), std::abs(ds - f.dgap(r, i))});
            scale = std::max({scale, std::abs(dv), std::abs(ds)});
        }
        CAPTURE(i);
        CAPTURE(err);
        CAPTURE(scale);
        REQUIRE(scale > 0.0);
        // tau moves the start t0 = t_a + tau and the steps' breakpoints t_k + tau: the finite
        // difference of the discrete simulation then differs from the continuous sensitivity by
        // the discretisation error (O(step)), while the other parameters agree to rounding
        CHECK(err <= (i == 3 ? tol_tau : 1e-5) * scale);
    }
}

}  // namespace

TEST_CASE("calibration sensitivities agree with finite differences of the simulation") {
    const double truth[5] = {0.05, 0.3, 1.2, 0.43, 8};
    const Trace tr = calib_test::noisy(calib_test::clean_trace(calib_test::ovrv(truth), calib_test::three_sines(120), 120), 3);
    CalibrationVector theta;
    theta << 0.06, 0.25, 1.1, 0.47, 9;  // away from the truth: residuals of both signs
    check_against_differences(tr, theta, 5e-3);
    theta << 0.15, 0.6, 0.8, 0.9, 6;    // stiff, long delay
    check_against_differences(tr, theta, 5e-3);
    theta << 0.12, 0.5, 0.8, 0.03, 6;   // delay shorter than the step: delayed values inside the step
    check_against_differences(tr, theta, 2e-2);
}

TEST_CASE("calibration sensitivities through a stop: the car rests at v = 0 and S_v resets to 0") {
    // the lead brakes to a stop, waits 10 s and drives off; the follower data from the model
    const LeadProfile lead({0, 20, 30, 40, 55, 120}, {10, 10, 0, 0, 10, 10});
    Trace tr;
    for (int k = 0; k <= 1200; ++k) {
        tr.t.push_back(0.1 * k);
        tr.lead.push_back(lead.speed(0.1 * k));
        tr.speed.push_back(lead.speed(0.1 * k));
        tr.gap.push_back(15.0);
    }
    CalibrationVector truth;
    truth << 0.08, 0.4, 1.0, 0.5, 5;
    const FollowerTrajectory data = simulate_follower(tr, truth, 0.0, 120.0, 0.05, false, 1.0);
    int resting = 0;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
        tr.speed[k] = data.speed[k];
        tr.gap[k] = data.gap[k];
        CHECK(data.speed[k] >= 0.0);
        resting += data.speed[k] == 0.0;
    }
    CHECK(resting > 50);
    CalibrationVector theta;
    theta << 0.1, 0.35, 1.1, 0.6, 6;
    const FollowerTrajectory f = simulate_follower(tr, theta, 0.0, 120.0, 0.05, true, 1.0);
    for (int i = 0; i < 5; ++i) {
        const double h = 1e-6 * std::max(1.0, std::abs(theta[i]));
        CalibrationVector up = theta, down = theta;
        up[i] += h;
        down[i] -= h;
        const FollowerTrajectory fu = simulate_follower(tr, up, 0.0, 120.0, 0.05, false, 1.0);
        const FollowerTrajectory fd = simulate_follower(tr, down, 0.0, 120.0, 0.05, false, 1.0);
        double err = 0.0, scale = 0.0;
        for (std::size_t k = 0; k < f.speed.size(); ++k) {
            const auto r = static_cast<Eigen::Index>(k);
            const double dv = (fu.speed[k] - fd.speed[k]) / (2 * h), ds = (fu.gap[k] - fd.gap[k]) / (2 * h);
            err = std::max({err, std::abs(dv - f.dspeed(r, i)), std::abs(ds - f.dgap(r, i))});
            scale = std::max({scale, std::abs(dv), std::abs(ds)});
            if (f.speed[k] == 0.0) CHECK(f.dspeed(r, i) == 0.0);
        }
        CAPTURE(i);
        CAPTURE(err);
        CHECK(err <= (i == 3 ? 5e-3 : 1e-5) * scale);
    }
}

TEST_CASE("calibration sensitivities: the plain simulation is the same with and without them") {
    const double truth[5] = {0.052, 0.338, 0.819, 0.948, 8.03};
    const Trace tr = calib_test::clean_trace(calib_test::ovrv(truth), ddemap::LeadProfile::builtin("dip"), 90);
    CalibrationVector theta;
    theta << 0.052, 0.338, 0.819, 0.948, 8.03;
    const FollowerTrajectory a = simulate_follower(tr, theta, 0.0, 90.0, 0.05, false);
    const FollowerTrajectory b = simulate_follower(tr, theta, 0.0, 90.0, 0.05, true);
    REQUIRE(a.speed.size() == b.speed.size());
    double diff = 0.0, err = 0.0;
    for (std::size_t k = 0; k < a.speed.size(); ++k) {
        diff = std::max(diff, std::abs(a.speed[k] - b.speed[k]) + std::abs(a.gap[k] - b.gap[k]));
        err = std::max(err, std::abs(a.speed[k] - tr.speed[k]) + std::abs(a.gap[k] - tr.gap[k]));
    }
    CHECK(diff == 0.0);
    CHECK(err < 1e-4);  // the truth reproduces the independent platoon simulation
    CHECK(a.dspeed.size() == 0);
}

TEST_SUITE_END();
