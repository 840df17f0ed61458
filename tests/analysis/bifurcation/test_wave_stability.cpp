#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/analysis/bifurcation/wave_stability.hpp"
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

TravellingWaveOptions options(const std::string& model, int cars, int wave, double from, double to, int intervals, int points, bool floquet) {
    TravellingWaveOptions o;
    o.model = model;
    o.cars = cars;
    o.wave = wave;
    o.orbit.parameter = model == "ov" ? "headway" : "gap";
    o.orbit.from = from;
    o.orbit.to = to;
    o.orbit.intervals = intervals;
    o.orbit.max_points = points;
    o.orbit.floquet = floquet;
    return o;
}

const ParameterMap kIdm{{"th", 1.2}, {"tau", 0.6}};

/// The dense path's multipliers of wave p (periodic_orbit's orbit_multipliers on the full ring
/// with one headway eliminated, the wave spread to the cars as travelling_wave_branch does for
/// N <= 10).
std::vector<cplx> dense_multipliers(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars, int degree,
                                    const PeriodicOrbit& p) {
    const NonlinearRing ring = make_nonlinear_ring(model, cars, parameters, parameter, p.par);
    const PeriodicMesh mesh(degree, p.breakpoints);
    Eigen::MatrixXd profile(mesh.points(), 2 * cars - 1);
    for (int i = 0; i < mesh.points(); ++i)
        for (int car = 0; car < cars; ++car) {
            const Eigen::VectorXd x = wave_car_state(mesh, p, cars, 1, car, mesh.point(i));
            if (car + 1 < cars) profile(i, car) = x(0);
            profile(i, cars - 1 + car) = x(1);
        }
    return orbit_multipliers(*ring.system, parameter, mesh, profile, p.period, p.par);
}

/// Every multiplier found by the matrix-free path (|mu| above 1e-3, where both are well
/// conditioned) is one of the dense path's, the trivial one included, and the verdicts agree.
void check_against_dense(const std::string& model, const ParameterMap& parameters, int cars, double from, double to) {
    CAPTURE(model);
    CAPTURE(cars);
    const TravellingWaveBranch w = travelling_wave_branch(parameters, options(model, cars, 1, from, to, 40, 8, false));
    REQUIRE(w.branch.points.size() == 8);
    WaveStabilityOptions so;
    so.dense_limit = 0;  // Arnoldi also on these small windows
    int compared = 0;
    for (std::size_t i : {std::size_t{0}, std::size_t{7}}) {  // near the Hopf point and farther
        const PeriodicOrbit& p = w.branch.points[i];
        CAPTURE(p.par);
        const std::vector<cplx> dense = dense_multipliers(model, parameters, w.branch.parameter, cars, w.branch.degree, p);
        REQUIRE(dense.size() >= 2);
        std::size_t k1 = 0;  // the dense path's trivial one: nearest 1
        for (std::size_t k = 1; k < dense.size(); ++k)
            if (std::abs(dense[k] - 1.0) < std::abs(dense[k1] - 1.0)) k1 = k;
        double dense_max = 0.0;
        for (std::size_t k = 0; k < dense.size(); ++k)
            if (k != k1) dense_max = std::max(dense_max, std::abs(dense[k]));
        const WaveStability s = wave_ring_stability(model, parameters, w.branch.parameter, cars, 1, w.branch.degree, p, so);
        INFO(s.message);
        REQUIRE(!s.multipliers.empty());
        CHECK(s.trivial_alignment > 0.99);
        CHECK(std::abs(s.trivial_distance - std::abs(dense[k1] - 1.0)) <= tol::wave_matrix_free_vs_dense);
        CHECK(std::abs(s.max_nontrivial - dense_max) <= tol::wave_matrix_free_vs_dense);
        for (const cplx& mu : s.multipliers) {
            if (std::abs(mu) < 1e-3) continue;
            double best = std::numeric_limits<double>::infinity();
            for (const cplx& nu : dense) best = std::min(best, std::abs(mu - nu));
            CAPTURE(mu);
            CHECK(best <= tol::wave_matrix_free_vs_dense);
            ++compared;
        }
        if (s.status == Status::Converged) CHECK((s.verdict == Verdict::Stable) == (dense_max < 1.0));
    }
    CHECK(compared >= 10);
}

/// min over the phase s (a grid of `samples`) of max_j |X_j - W_j(s)|, W the wave spread to the
/// full ring's state (h_0..h_{N-2}, v_0..v_{N-1}).
double distance_to_wave(const std::vector<Eigen::VectorXd>& wave, const double* x) {
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::VectorXd& w : wave) {
        double d = 0.0;
        for (Eigen::Index j = 0; j < w.size(); ++j) d = std::max(d, std::abs(x[j] - w(j)));
        best = std::min(best, d);
    }
    return best;
}

/// The distance of the simulated full ring from the wave's orbit after 0 and `periods` periods,
/// started on the wave (its history) with car 0's speed raised by eps.
std::pair<double, double> simulate_from_wave(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars,
                                             int k, int degree, const PeriodicOrbit& p, double eps, int periods) {
    NonlinearRing ring = make_nonlinear_ring(model, cars, parameters, parameter, p.par);
    const NonlinearDDE& sys = *ring.system;
    const PeriodicMesh mesh(degree, p.breakpoints);
    auto state = [&](double s) {
        Eigen::VectorXd x(2 * cars - 1);
        for (int i = 0; i < cars; ++i) {
            const Eigen::VectorXd c = wave_car_state(mesh, p, cars, k, i, s);
            if (i + 1 < cars) x(i) = c(0);
            x(cars - 1 + i) = c(1);
        }
        return x;
    };
    std::vector<Eigen::VectorXd> grid;
    const int samples = 4000;
    for (int m = 0; m < samples; ++m) grid.push_back(state(static_cast<double>(m) / samples));
    const int n = sys.dimension(), nd = sys.delay_count();
    const std::vector<double> tau = sys.delays();
    DdeSolver sol(
        n, 0.0,
        [&](double t, double* y) {
            const Eigen::VectorXd x = state(t / p.period);
            for (int j = 0; j < n; ++j) y[j] = x(j);
            y[cars - 1] += eps;  // v_0
        },
        [&](double t, const double* y, const DdeSolver& s, double* dy) {
            Eigen::VectorXd u(static_cast<Eigen::Index>(n) * (nd + 1));
            for (int j = 0; j < n; ++j) u(j) = y[j];
            for (int q = 0; q < nd; ++q)
                for (int j = 0; j < n; ++j) u((q + 1) * n + j) = s.value(j, t - tau[static_cast<std::size_t>(q)]);
            const Eigen::VectorXd f = sys.f(u);
            for (int j = 0; j < n; ++j) dy[j] = f(j);
        });
    const double d0 = distance_to_wave(grid, sol.state());
    sol.integrate(periods * p.period, 0.05, {});
    return {d0, distance_to_wave(grid, sol.state())};
}

}  // namespace

TEST_CASE("wave stability: the matrix-free multipliers equal the dense path's (ov, N = 5 and 10)" * doctest::test_suite("slow")) {
    check_against_dense("ov", {}, 5, 3.5, 2.0);
    check_against_dense("ov", {}, 10, 3.5, 2.0);
}

TEST_CASE("wave stability: the matrix-free multipliers equal the dense path's (idm, N = 10)") {
    check_against_dense("idm", kIdm, 10, 25.0, 8.0);
}

TEST_CASE("wave stability: the trivial multiplier converges to 1 as the mesh is refined (idm, N = 20)") {
    // the same wave (the end of the branch at gap 33 exactly) on 13, 26 and 52 intervals: shifts
    // of k / N = 1 / 20 are not whole intervals, so the spread wave is not exact on the mesh
    double previous = std::numeric_limits<double>::infinity();
    for (int intervals : {13, 26, 52}) {
        CAPTURE(intervals);
        const TravellingWaveBranch w = travelling_wave_branch(kIdm, options("idm", 20, 1, 40.0, 33.0, intervals, 200, false));
        REQUIRE(w.branch.stop == "bound");
        const PeriodicOrbit& p = w.branch.points.back();
        REQUIRE(p.par == 33.0);
        const WaveStability s = wave_ring_stability("idm", kIdm, "gap", 20, 1, w.branch.degree, p);
        INFO(s.message);
        REQUIRE(s.status == Status::Converged);
        CHECK(s.verdict == Verdict::Stable);
        CHECK(s.trivial_distance * tol::wave_trivial_refinement < previous);
        previous = s.trivial_distance;
    }
    CHECK(previous < tol::orbit_trivial_multiplier);
}

TEST_CASE("wave stability: verdicts against simulation of the full ring (N = 20: ov unstable, idm stable)") {
    // ov, K = 1: unstable waves (subcritical branch); the simulation leaves the wave
    {
        const TravellingWaveBranch w = travelling_wave_branch({}, options("ov", 20, 1, 3.5, 2.0, 40, 8, false));
        REQUIRE(w.branch.points.size() == 8);
        const PeriodicOrbit& p = w.branch.points.back();
        const WaveStability s = wave_ring_stability("ov", {}, "headway", 20, 1, w.branch.degree, p);
        INFO(s.message);
        REQUIRE(s.status == Status::Converged);
        REQUIRE(s.verdict == Verdict::Unstable);
        const std::pair<double, double> dd = simulate_from_wave("ov", {}, "headway", 20, 1, w.branch.degree, p, 1e-4, 8);
        const double d0 = dd.first, d1 = dd.second;  // plain variables: INFO captures them in a lambda
        INFO("distance from the wave " << d0 << " -> " << d1 << ", max |mu| = " << s.max_nontrivial);
        CHECK(d1 > tol::wave_simulation_growth * d0);
    }
    // idm, K = 1: stable waves (supercritical); the simulation returns to the wave
    {
        const TravellingWaveBranch w = travelling_wave_branch(kIdm, options("idm", 20, 1, 40.0, 8.0, 40, 60, false));
        REQUIRE(w.branch.points.size() == 60);
        const PeriodicOrbit& p = w.branch.points.back();
        const WaveStability s = wave_ring_stability("idm", kIdm, "gap", 20, 1, w.branch.degree, p);
        INFO(s.message);
        REQUIRE(s.status == Status::Converged);
        REQUIRE(s.verdict == Verdict::Stable);
        const std::pair<double, double> dd = simulate_from_wave("idm", kIdm, "gap", 20, 1, w.branch.degree, p, 0.05, 12);
        const double d0 = dd.first, d1 = dd.second;
        INFO("distance from the wave " << d0 << " -> " << d1 << ", max |mu| = " << s.max_nontrivial);
        CHECK(d1 < tol::wave_simulation_decay * d0);
    }
}

TEST_CASE("wave stability: the branch of a 100-car ring (K = 10) through the library option, undecided never called stable" * doctest::test_suite("slow")) {
    TravellingWaveOptions o = options("ov", 100, 10, 3.5, 2.0, 40, 6, true);
    o.sparse_floquet = true;
    long progress = 0;
    o.stability_progress = [&](long done, long total, double) {
        CHECK(total == 6);
        progress = done;
    };
    const TravellingWaveBranch w = travelling_wave_branch({}, o);
    REQUIRE(w.branch.points.size() == 6);
    CHECK(w.full_ring_stability);
    CHECK(w.stability_method == "matrix_free");
    CHECK(progress == 6);
    REQUIRE(w.stability.size() == 6);
    for (std::size_t i = 0; i < 6; ++i) {
        const WaveStability& s = w.stability[i];
        const PeriodicOrbit& p = w.branch.points[i];
        CHECK(p.stable == (s.verdict == Verdict::Stable));
        if (s.status != Status::Converged) {
            CHECK(s.verdict == Verdict::Undecided);
            CHECK(!p.stable);
            CHECK(!s.message.empty());
        } else {
            // near the Hopf point of mode 10 the waves of 10 cars are unstable on 100 cars
            CHECK(s.verdict == Verdict::Unstable);
            CHECK(s.max_nontrivial > 1.0 + s.error);
        }
    }
}

TEST_CASE("wave stability: bad input") {
    const TravellingWaveBranch w = travelling_wave_branch({}, options("ov", 20, 1, 3.5, 2.0, 40, 2, false));
    REQUIRE(!w.branch.points.empty());
    const PeriodicOrbit& p = w.branch.points.front();
    CHECK_THROWS_AS(wave_ring_stability("ov", {}, "headway", 20, 0, 4, p), std::invalid_argument);
    CHECK_THROWS_AS(wave_ring_stability("ov", {}, "headway", 1, 1, 4, p), std::invalid_argument);
    CHECK_THROWS_AS(wave_ring_stability("ov", {}, "nope", 20, 1, 4, p), std::invalid_argument);
    CHECK_THROWS_AS(wave_ring_stability("xx", {}, "headway", 20, 1, 4, p), std::invalid_argument);
    CHECK_THROWS_AS(wave_ring_stability("ov", {}, "headway", 20, 1, 5, p), std::invalid_argument);
    WaveStabilityOptions so;
    so.max_multipliers = 2;
    CHECK_THROWS_AS(wave_ring_stability("ov", {}, "headway", 20, 1, 4, p, so), std::invalid_argument);
}
