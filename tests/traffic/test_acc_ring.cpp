#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/traffic/acc_ring.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"
#include "../tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
// the paper's A_min setting (k1, k2, th, tau, eta) with the default limits, mean gap 30 m
AccRing acc_test_ring(int n, double k2 = 0.338) { return AccRing(n, 0.052, k2, 0.819, 0.948, 8.03, 2.0, -3.0, 30.0); }
}  // namespace

TEST_CASE("acc ring: the saturation passes 0 with slope 1, stays between the limits and has the derivatives of its closed form") {
    for (const std::pair<double, double>& limits : {std::pair<double, double>{2.0, -3.0}, {2.0, -2.0}, {1.0, -6.0}}) {
        const double hi = limits.first, lo = limits.second;  // (clang 14: no structured bindings inside CAPTURE's lambda)
        CAPTURE(hi);
        CAPTURE(lo);
        CHECK(std::abs(AccRing::saturate(0.0, hi, lo)) < 1e-15);
        const double h = 1e-4;
        const double d1 = (AccRing::saturate(h, hi, lo) - AccRing::saturate(-h, hi, lo)) / (2 * h);
        CHECK(std::abs(d1 - 1.0) < 1e-7);
        // sat''(0) = 2 m k / A and sat'''(0) = -2 k^2 (1 - 3 (m / A)^2), m = (hi + lo) / 2, A = (hi - lo) / 2
        const double m = 0.5 * (hi + lo), A = 0.5 * (hi - lo), r = m / A, k = 1.0 / (A * (1.0 - r * r));
        const double H = 1e-3;
        const double f2 = AccRing::saturate(H, hi, lo), f1 = AccRing::saturate(-H, hi, lo), f0 = AccRing::saturate(0.0, hi, lo);
        const double f3 = AccRing::saturate(2 * H, hi, lo), fm3 = AccRing::saturate(-2 * H, hi, lo);
        CHECK(std::abs((f2 - 2 * f0 + f1) / (H * H) - 2 * m * k / A) < 1e-5);
        CHECK(std::abs((f3 - 2 * f2 + 2 * f1 - fm3) / (2 * H * H * H) + 2 * k * k * (1 - 3 * r * r)) < 1e-4);
        CHECK(AccRing::saturate(1e3, hi, lo) <= hi);
        CHECK(AccRing::saturate(1e3, hi, lo) > hi - 1e-9);
        CHECK(AccRing::saturate(-1e3, hi, lo) >= lo);
        CHECK(AccRing::saturate(-1e3, hi, lo) < lo + 1e-9);
    }
}

TEST_CASE("acc ring: the uniform flow is the OVRV equilibrium and its linearisation is the linear OVRV ring's (Hopf points where its ring roots cross)") {
    const AccRing ring = acc_test_ring(8);
    const Eigen::VectorXd x = ring.uniform_flow();
    CHECK(std::abs(x[ring.cars() - 1] - (30.0 - 8.03) / 0.819) < 1e-12);
    CHECK(ring.f(ring.stack_constant(x)).cwiseAbs().maxCoeff() < 1e-13);
    // the branch in k2: the equilibrium does not move; its Hopf points are where the linear ring
    // of OvrvModel cars (the Fourier-mode analysis, independent code) has a root on the axis
    EquilibriumBranchOptions o;
    o.parameter = "k2";
    o.from = 0.2;
    o.to = 1.2;
    o.roots.count = 2;
    const EquilibriumBranch br = equilibrium_branch(ring, x, o);
    REQUIRE(br.status == Status::Converged);
    REQUIRE(br.hopf.size() == 2);
    for (const HopfPoint& hp : br.hopf) {
        CAPTURE(hp.par);
        REQUIRE(hp.status == Status::Converged);
        const OvrvModel m({{"k1", 0.052}, {"k2", hp.par}, {"th", 0.819}, {"tau", 0.948}, {"eta", 8.03}, {"speed", x[ring.cars() - 1]}});
        RingOptions ro;
        ro.roots.count = 4;
        const RingResult rr = analyse_ring(m.linearise(), 8, ro);
        bool on_axis = false;
        for (const RingRoot& r : rr.roots)
            on_axis = on_axis || (std::abs(r.root.value.real()) < tol::special_point && std::abs(std::abs(r.root.value.imag()) - hp.omega) < tol::special_point);
        CHECK(on_axis);
    }
    // with asymmetric limits the criticality is decided: the upper Hopf point (the ring stable above
    // it) is supercritical, and its stable orbits are waves of bounded acceleration
    const HopfCoefficients upper = hopf_coefficients(ring, ring.parameter_index("k2"), br.hopf.back());
    REQUIRE(upper.status == Status::Converged);
    CHECK(upper.l1 < 0.0);
}

TEST_CASE("acc ring: a stable wave from the supercritical Hopf point is the orbit a simulation settles on" * doctest::test_suite("slow")) {
    AccRing ring = acc_test_ring(8);
    EquilibriumBranchOptions o;
    o.parameter = "k2";
    o.from = 0.2;
    o.to = 1.2;
    o.roots.count = 2;
    const EquilibriumBranch br = equilibrium_branch(ring, ring.uniform_flow(), o);
    REQUIRE(br.hopf.size() == 2);
    PeriodicOrbitOptions po;
    po.parameter = "k2";
    po.from = 0.68;  // the branch ends on this face, below the Hopf point at 0.708
    po.to = 1.2;
    po.max_points = 400;
    po.max_step = 2.0;
    const OrbitBranch b = orbit_branch_from_hopf(ring, br.hopf.back(), po);
    REQUIRE(b.stop == "bound");
    const PeriodicOrbit& end = b.points.back();
    REQUIRE(end.par == doctest::Approx(0.68).epsilon(1e-14));
    CHECK(end.stable);
    // the simulation at k2 = 0.68 from the uniform flow with one gap raised by 1 m
    ring.set_parameter("k2", 0.68);
    Eigen::VectorXd start = ring.uniform_flow();
    start[0] += 1.0;
    const PeriodicMesh mesh(4, 40);
    // (the wave attracts slowly, multiplier 0.914 per period of 20 s, and the other modes decay
    // slower still: 3000 s leave the period varying by 1.1 %, 10000 s settle it)
    const SimulatedOrbitGuess g = orbit_guess_from_simulation(ring, "k2", mesh, start, 10000.0, 0.01);
    REQUIRE(g.status == Status::Converged);
    CHECK(std::abs(g.period - end.period) < 1e-4 * end.period);
    // and its speed range is the orbit's (max of v0 over the last period of the run)
    const double v_max = g.guess.profile.col(ring.cars() - 1).maxCoeff();
    CHECK(std::abs(v_max - end.max[ring.cars() - 1]) < 1e-2);
    MESSAGE("k2 = 0.68: orbit period ", end.period, ", simulated ", g.period, "; max v0 ", end.max[ring.cars() - 1], ", simulated ", v_max);
}

TEST_CASE("acc ring by name: required parameters, defaults and refusals") {
    const NonlinearRing r = make_nonlinear_ring("acc", 4, {{"k1", 0.05}, {"k2", 0.3}, {"th", 1.0}, {"tau", 0.9}, {"eta", 8.0}, {"gap", 30.0}});
    CHECK(r.system->parameter("a_max") == 2.0);
    CHECK(r.system->parameter("a_min") == -3.0);
    CHECK(r.variables.front() == "s0");
    CHECK(r.units.at("k1") == "1/s^2");
    CHECK_THROWS_WITH_AS(make_nonlinear_ring("acc", 4, {{"k1", 0.05}}), doctest::Contains("needs k2"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(AccRing(4, 0.05, 0.3, 1.0, 0.9, 8.0, 2.0, 0.5, 30.0), doctest::Contains("a_min = 0.5: expected a finite braking limit < 0"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(AccRing(4, 0.05, 0.3, 1.0, 0.9, 8.0, 2.0, -3.0, 5.0), doctest::Contains("gap = 5: expected a finite mean gap > eta"),
                         std::invalid_argument);
}
