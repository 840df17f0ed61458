#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"

// Long travelling waves (1000 cars, K = 1) checked independently of the reduced equations: the
// full ring's 1999 equations on the wave spread to the 1000 cars, and the resolution control
// that keeps an under-resolved mesh from reporting spurious waves and folds.

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

TravellingWaveOptions long_wave(int intervals, int points) {
    TravellingWaveOptions o;
    o.model = "ov";
    o.cars = 1000;
    o.wave = 1;
    o.orbit.parameter = "headway";
    o.orbit.from = 3.5;
    o.orbit.to = 2.0;
    o.orbit.intervals = intervals;
    o.orbit.max_points = points;
    return o;
}

/// The branch wave at the homotopy's parameter (where both sides of the long-wave branch join).
const PeriodicOrbit& homotopy_wave(const TravellingWaveBranch& w) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < w.branch.points.size(); ++i)
        if (std::abs(w.branch.points[i].par - w.homotopy_par) < std::abs(w.branch.points[best].par - w.homotopy_par)) best = i;
    REQUIRE(std::abs(w.branch.points[best].par - w.homotopy_par) <= 1e-12);
    return w.branch.points[best];
}

/// The period of branch b at parameter p, linear between its two waves around p (b sorted by par).
double period_at(const std::vector<std::pair<double, double>>& b, double p) {
    for (std::size_t i = 0; i + 1 < b.size(); ++i)
        if (b[i].first <= p && p <= b[i + 1].first)
            return b[i + 1].first > b[i].first ? b[i].second + (b[i + 1].second - b[i].second) * (p - b[i].first) / (b[i + 1].first - b[i].first)
                                               : b[i].second;
    return std::nan("");
}

/// The full ov ring of 1000 cars (one headway eliminated) simulated with the project's DDE
/// integrator (RK4, Hermite history) from the wave's own history on [-tau, 0] to t_end with step
/// h: max over the 1999 components and the times 1, 2, .., t_end of |X_sim(t) - X_wave(t)|,
/// divided by the amplitude of car 0's headway.
double simulated_deviation(const PeriodicOrbit& p, double t_end, double h) {
    const int cars = 1000;
    const NonlinearRing ring = make_nonlinear_ring("ov", cars, {{"headway", p.par}});
    const NonlinearDDE& sys = *ring.system;
    const int n = sys.dimension();
    const double tau = sys.delays()[0], T = p.period;
    const PeriodicMesh mesh(4, p.breakpoints);
    auto wave_state = [&](double t, double* y) {
        for (long car = 0; car < cars; ++car) {
            const Eigen::VectorXd x = wave_car_state(mesh, p, cars, 1, car, t / T - std::floor(t / T));
            if (car + 1 < cars) y[car] = x(0);
            y[cars - 1 + car] = x(1);
        }
    };
    double last_t = std::nan("");
    std::vector<double> cache(static_cast<std::size_t>(n));
    DdeSolver s(
        n, 0.0,
        [&](double t, double* y) {
            if (t != last_t) {
                wave_state(t, cache.data());
                last_t = t;
            }
            std::copy(cache.begin(), cache.end(), y);
        },
        [&](double t, const double* y, const DdeSolver& sol, double* dy) {
            Eigen::VectorXd u(2 * n);
            for (int i = 0; i < n; ++i) {
                u(i) = y[i];
                u(n + i) = sol.value(i, t - tau);
            }
            const Eigen::VectorXd f = sys.f(u);
            for (int i = 0; i < n; ++i) dy[i] = f(i);
        });
    s.integrate(t_end, h, {});
    std::vector<double> w(static_cast<std::size_t>(n));
    double dev = 0.0;
    for (double t = 1.0; t <= t_end + 1e-9; t += 1.0) {
        wave_state(t, w.data());
        for (int i = 0; i < n; ++i) dev = std::max(dev, std::abs(s.value(i, t) - w[static_cast<std::size_t>(i)]));
    }
    return dev / (p.max(0) - p.min(0));
}

}  // namespace

TEST_CASE("travelling waves: the long wave of a 1000-car ring (K = 1) on the full ring's 1999 equations, resolved at 100 and 200 intervals" *
          doctest::test_suite("slow")) {
    const TravellingWaveOptions o100 = long_wave(100, 100), o200 = long_wave(200, 100);
    const TravellingWaveBranch w100 = travelling_wave_branch({}, o100);
    const TravellingWaveBranch w200 = travelling_wave_branch({}, o200);
    double start_defect[2] = {0.0, 0.0};
    int k = 0;
    for (const TravellingWaveBranch* w : {&w100, &w200}) {
        INFO(w->branch.message);
        REQUIRE(w->branch.status == Status::Converged);
        REQUIRE(std::isfinite(w->homotopy_par));
        REQUIRE(w->defects.size() == w->branch.points.size());
        CHECK(w->branch.folds.empty());
        // every wave resolved (the control the branch enforces) ...
        for (double d : w->defects) CHECK(d <= o100.defect_tolerance);
        // ... and, independently, on the full ring: the 1999 equations on the 1000 cars rebuilt
        // from car 0's polynomial, every 10th wave and the homotopy's
        for (std::size_t i = 0; i < w->branch.points.size(); i += 10) {
            const WaveRingCheck c = check_wave_on_full_ring("ov", {}, "headway", 1000, 1, 4, w->branch.points[i], 100);
            CAPTURE(w->branch.points[i].par);
            CHECK(c.relative <= tol::wave_full_ring_defect);
            CHECK(c.length_error <= tol::wave_ring_length);
        }
        const PeriodicOrbit& h = homotopy_wave(*w);
        CHECK(h.max(0) - h.min(0) > 3.0);  // a jam, not the uniform flow
        const WaveRingCheck c = check_wave_on_full_ring("ov", {}, "headway", 1000, 1, 4, h, 400);
        CHECK(c.relative <= tol::wave_full_ring_defect);
        CHECK(c.length_error <= tol::wave_ring_length);
        start_defect[k++] = c.relative;
        // the same profile read as a wave of number 2 (car i shifted by 2 i T / N) is no solution
        CHECK(check_wave_on_full_ring("ov", {}, "headway", 1000, 2, 4, h, 100).relative > 100.0 * tol::wave_full_ring_defect);
    }
    // mesh convergence of the full ring's defect at the homotopy's wave: O(h^d) falls 2^4 = 16
    // times when the intervals are doubled
    INFO("full-ring relative defect at 100 intervals " << start_defect[0] << ", at 200 " << start_defect[1]);
    CHECK(start_defect[1] * tol::defect_refinement_factor <= start_defect[0]);
    CHECK(std::abs(homotopy_wave(w100).period - homotopy_wave(w200).period) <= tol::long_wave_period * homotopy_wave(w200).period);
    // the full ring simulated from the wave's history stays on the wave (20 time units: the
    // fronts pass about 5 cars)
    const double dev = simulated_deviation(homotopy_wave(w200), 20.0, 0.02);
    // the same profile with its period 1e-4 too long (the shift from car to car 0.39 time units
    // too long) leaves it
    PeriodicOrbit wrong = homotopy_wave(w200);
    wrong.period *= 1.0 + 1e-4;
    const double dev_wrong = simulated_deviation(wrong, 20.0, 0.02);
    INFO("simulated deviation " << dev << ", with the period 1e-4 too long " << dev_wrong);
    CHECK(dev <= tol::wave_vs_simulation);
    CHECK(dev_wrong > 100.0 * tol::wave_vs_simulation);
}

TEST_CASE("travelling waves: 40 intervals for the 1000-car wave (K = 1) are refined, no spurious folds or periods" * doctest::test_suite("slow")) {
    // before the resolution control this branch on 40 intervals had period jumps of 2e-3 and
    // (with 400 waves) four spurious folds
    const TravellingWaveOptions o40 = long_wave(40, 100), o100 = long_wave(100, 100);
    const TravellingWaveBranch w40 = travelling_wave_branch({}, o40);
    const TravellingWaveBranch w100 = travelling_wave_branch({}, o100);
    INFO(w40.branch.message);
    REQUIRE(w40.branch.status == Status::Converged);
    CHECK(w40.branch.intervals >= 80);  // chosen: more than the 40 given
    CHECK(w40.branch.folds.empty());
    for (double d : w40.defects) CHECK(d <= o40.defect_tolerance);
    // the periods at the same headway as the branch from 100 intervals
    std::vector<std::pair<double, double>> b100;
    for (const PeriodicOrbit& p : w100.branch.points) b100.emplace_back(p.par, p.period);
    std::sort(b100.begin(), b100.end());
    int compared = 0;
    for (const PeriodicOrbit& p : w40.branch.points) {
        const double T = period_at(b100, p.par);
        if (std::isnan(T)) continue;
        ++compared;
        CAPTURE(p.par);
        CHECK(std::abs(p.period - T) <= tol::long_wave_period * T);
    }
    CHECK(compared >= 10);
}

TEST_CASE("travelling waves: the resolution control refuses what it cannot resolve") {
    // at most 40 intervals allowed: the 1000-car wave (K = 1) reached by the homotopy is not
    // resolved on them, an undecided status rather than a branch
    TravellingWaveOptions o = long_wave(40, 12);
    o.max_intervals = 40;
    o.defect_tolerance = 1e-6;
    const TravellingWaveBranch w = travelling_wave_branch({}, o);
    CHECK(w.branch.status != Status::Converged);
    CHECK(w.branch.stop == "unresolved");
    CHECK(w.branch.points.empty());
    CHECK(w.branch.message.find("not resolved") != std::string::npos);
    // on a fixed mesh (the wave from its own Hopf point) the branch stops at the first wave whose
    // defect exceeds unresolved_defect: 100 cars per wave on 20 intervals
    TravellingWaveOptions f = long_wave(20, 40);
    f.wave = 10;
    f.orbit.initial_step = 1e-3;
    const TravellingWaveBranch wf = travelling_wave_branch({}, f);
    CHECK(wf.branch.stop == "unresolved");
    CHECK(wf.branch.status == Status::NumericalIssue);
    REQUIRE(!wf.defects.empty());
    for (double d : wf.defects) CHECK(d <= f.unresolved_defect);
    // bad options
    o = long_wave(40, 12);
    o.defect_tolerance = -1.0;
    CHECK_THROWS_AS(travelling_wave_branch({}, o), std::invalid_argument);
    o = long_wave(40, 12);
    o.max_intervals = 20;
    CHECK_THROWS_AS(travelling_wave_branch({}, o), std::invalid_argument);
    // the full-ring check's own input errors
    PeriodicOrbit empty;
    CHECK_THROWS_AS(check_wave_on_full_ring("ov", {}, "headway", 1000, 1, 4, empty, 10), std::invalid_argument);
}

TEST_CASE("travelling waves: the IDM 1000-car ring (K = 1) through the homotopy past the fold of the K / N = 0.1 branch, on the full ring" *
          doctest::test_suite("slow")) {
    // th = 1.2 s, tau = 0.6 s, gap from 40 down to 6: the K / N = 0.1 branch (Hopf point at gap
    // 22.96) folds at gap 19.29 and comes back to large gaps; the homotopy starts beyond that fold
    // (a start short of it, gap 19.54, met a fold in K / N at 0.086 and failed)
    const ParameterMap parameters{{"th", 1.2}, {"tau", 0.6}};
    double period[2] = {0.0, 0.0};
    const int intervals[2] = {40, 80};
    for (int k = 0; k < 2; ++k) {
        TravellingWaveOptions o;
        o.model = "idm";
        o.cars = 1000;
        o.wave = 1;
        o.orbit.parameter = "gap";
        o.orbit.from = 40.0;
        o.orbit.to = 6.0;
        o.orbit.intervals = intervals[k];
        o.orbit.max_points = 20;
        const TravellingWaveBranch w = travelling_wave_branch(parameters, o);
        INFO(w.branch.message);
        REQUIRE(w.branch.status == Status::Converged);
        REQUIRE(std::isfinite(w.homotopy_par));
        CHECK(w.homotopy_par > 19.29);  // beyond the fold of the K / N = 0.1 branch
        for (double d : w.defects) CHECK(d <= o.defect_tolerance);
        for (std::size_t i = 0; i < w.branch.points.size(); i += 5) {
            const WaveRingCheck c = check_wave_on_full_ring("idm", parameters, "gap", 1000, 1, 4, w.branch.points[i], 100);
            CAPTURE(w.branch.points[i].par);
            CHECK(c.relative <= tol::wave_full_ring_defect);
            CHECK(c.length_error <= tol::wave_ring_length);
        }
        period[k] = homotopy_wave(w).period;
    }
    CHECK(std::abs(period[0] - period[1]) <= tol::long_wave_period * period[1]);
}
