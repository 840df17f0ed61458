#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/idm_ring.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"
#include "ddemap/traffic/ring_system.hpp"
#include "../tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
// a, b, v0, delta, th, eta, tau and the mean gap of the tests
IdmRing test_ring(int n, double tau = 0.6, double gap = 25.0) { return IdmRing(n, 1.1, 1.6, 32.0, 4.0, 1.2, 2.0, tau, gap); }
ParameterMap law_of(const IdmRing& r, double speed) {
    return {{"a", r.parameter("a")}, {"b", r.parameter("b")}, {"v0", r.parameter("v0")}, {"delta", r.parameter("delta")},
            {"th", r.parameter("th")}, {"eta", r.parameter("eta")}, {"tau", r.parameter("tau")}, {"speed", speed}};
}
}  // namespace

TEST_CASE("idm ring: the uniform flow is the equilibrium of IdmModel at the speed whose equilibrium gap is the mean gap") {
    const IdmRing ring = test_ring(5);
    const Eigen::VectorXd x = ring.uniform_flow();
    const double v = x[ring.cars() - 1];
    CHECK(v > 0.0);
    CHECK(v < ring.parameter("v0"));
    // IdmModel's closed form s*(v) (an independent formula) gives back the gap
    const IdmModel m(law_of(ring, v));
    CHECK(std::abs(m.equilibrium_gap(v) - 25.0) < 1e-12 * 25.0);
    CHECK(ring.f(ring.stack_constant(x)).cwiseAbs().maxCoeff() < 1e-13);
    CHECK_THROWS_WITH_AS(test_ring(3, 0.6, 1.5), doctest::Contains("gap = 1.5: expected a finite mean gap > eta"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(IdmRing(1, 1, 1, 30, 4, 1, 2, 0.5, 20), doctest::Contains("at least 2 cars"), std::invalid_argument);
}

TEST_CASE("idm ring: the reduced ring has the nontrivial roots of the full ring system of IdmModel cars") {
    for (int n : {3, 6}) {
        CAPTURE(n);
        const IdmRing ring = test_ring(n);
        const Eigen::VectorXd x = ring.uniform_flow();
        const double v = x[n - 1];
        RootOptions o;
        o.count = 6;
        const RootResult reduced = rightmost_roots(linearise(ring, x), o);
        REQUIRE(reduced.status == Status::Converged);
        // the full 2N ring (RingSystem of IdmModel, independent code) at the same speed
        const IdmModel m(law_of(ring, v));
        const RingSystem full(m, n);
        o.count = 7;
        const RootResult all = rightmost_roots(linearise(full, full.equilibrium(v)), o);
        REQUIRE(all.status == Status::Converged);
        std::vector<cplx> nontrivial;
        for (const Root& r : all.roots)
            if (std::abs(r.value) > 1e-9) nontrivial.push_back(r.value);
        REQUIRE(nontrivial.size() >= 4);
        for (std::size_t j = 0; j < 4; ++j) {
            CAPTURE(j);
            const bool found = std::any_of(reduced.roots.begin(), reduced.roots.end(),
                                           [&](const Root& r) { return std::abs(r.value - nontrivial[j]) < tol::same_root; });
            CHECK(found);
        }
        for (const Root& r : reduced.roots) CHECK(std::abs(r.value) > 1e-6);  // no structural zero
    }
}

TEST_CASE("idm ring: exact Jacobians, parameter derivatives and second derivatives against central differences") {
    const IdmRing ring = test_ring(4);
    const int n = ring.dimension();
    Eigen::VectorXd u(2 * n);
    for (int i = 0; i < 2 * n; ++i) u[i] = (i % n < 3 ? 24.0 : 12.0) + 0.7 * std::sin(1.3 * i);
    const double h = 1e-5;
    const auto jac = ring.jacobians(u);
    for (int k = 0; k < 2; ++k)
        for (int c = 0; c < n; ++c) {
            Eigen::VectorXd up = u, um = u;
            up[k * n + c] += h;
            um[k * n + c] -= h;
            const Eigen::VectorXd fd = (ring.f(up) - ring.f(um)) / (2 * h);
            CHECK((jac[static_cast<std::size_t>(k)].col(c) - fd).cwiseAbs().maxCoeff() < tol::finite_difference * (1.0 + fd.cwiseAbs().maxCoeff()));
        }
    // d f / d gap and d f / d delta
    for (int j : {3, 7}) {
        CAPTURE(j);
        std::vector<double> pp = ring.parameter_values(), pm = pp;
        const double hj = h * std::max(1.0, std::abs(pp[static_cast<std::size_t>(j)]));
        pp[static_cast<std::size_t>(j)] += hj;
        pm[static_cast<std::size_t>(j)] -= hj;
        const Eigen::VectorXd fd = (ring.f(u, pp) - ring.f(u, pm)) / (2 * hj);
        const Eigen::VectorXd ex = ring.parameter_derivative(u, j, ring.parameter_values());
        CHECK((ex - fd).cwiseAbs().maxCoeff() < tol::finite_difference * (1.0 + fd.cwiseAbs().maxCoeff()));
    }
    // D^2 f [a, b] against differences of the exact Jacobian
    Eigen::VectorXd a = Eigen::VectorXd::LinSpaced(2 * n, -0.5, 0.5), b = Eigen::VectorXd::LinSpaced(2 * n, 0.3, -0.2);
    Eigen::VectorXd jp = Eigen::VectorXd::Zero(n), jm = jp;
    const auto jup = ring.jacobians(u + h * b), jum = ring.jacobians(u - h * b);
    for (int k = 0; k < 2; ++k) {
        jp += jup[static_cast<std::size_t>(k)] * a.segment(k * n, n);
        jm += jum[static_cast<std::size_t>(k)] * a.segment(k * n, n);
    }
    const Eigen::VectorXd fd2 = (jp - jm) / (2 * h);
    CHECK((ring.second_derivative(u, a, b) - fd2).cwiseAbs().maxCoeff() < tol::finite_difference * (1.0 + fd2.cwiseAbs().maxCoeff()));
}

TEST_CASE("idm ring: the Hopf points of the branch in the mean gap are where the Fourier-mode analysis of IdmModel has abscissa 0") {
    const IdmRing ring = test_ring(5, 0.6, 6.0);
    EquilibriumBranchOptions o;
    o.parameter = "gap";
    o.from = 6.0;  // unstable uniform flow (the ring analysis: abscissa +0.08 at 2 m/s, -0.05 at 8 m/s)
    o.to = 40.0;
    const EquilibriumBranch br = equilibrium_branch(ring, ring.uniform_flow(), o);
    REQUIRE(br.status == Status::Converged);
    REQUIRE(!br.hopf.empty());
    for (const HopfPoint& hp : br.hopf) {
        CAPTURE(hp.par);
        REQUIRE(hp.status == Status::Converged);
        IdmRing at = ring;
        at.set_parameter("gap", hp.par);
        const double v = at.equilibrium_speed(hp.par);
        const IdmModel m(law_of(at, v));
        RingOptions ro;
        ro.roots.count = 4;
        const RingResult rr = analyse_ring(m.linearise(), 5, ro);
        // one mode has a root on the axis at i omega
        bool on_axis = false;
        for (const RingRoot& r : rr.roots)
            on_axis = on_axis || (std::abs(r.root.value.real()) < tol::special_point && std::abs(std::abs(r.root.value.imag()) - hp.omega) < tol::special_point);
        CHECK(on_axis);
    }
}

TEST_CASE("nonlinear rings by name: defaults, required parameters and refusals") {
    const NonlinearRing r = make_nonlinear_ring("idm", 4, {{"th", 1.2}, {"tau", 0.6}, {"gap", 25.0}});
    const IdmRing direct(4, 1.0, 1.5, 33.3, 4.0, 1.2, 2.0, 0.6, 25.0);
    CHECK(r.system->parameter_values() == direct.parameter_values());
    CHECK((r.uniform_flow - direct.uniform_flow()).cwiseAbs().maxCoeff() == 0.0);
    CHECK(r.variables.size() == 7);
    CHECK(r.variables.front() == "s0");
    CHECK(r.units.at("gap") == "m");
    const NonlinearRing ov = make_nonlinear_ring("ov", 3, {{"headway", 1.7}});
    CHECK(ov.variables.front() == "h0");
    CHECK(ov.system->parameter("headway") == 1.7);
    CHECK_THROWS_WITH_AS(make_nonlinear_ring("idm", 4, {{"th", 1.2}}), doctest::Contains("the idm ring needs tau"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(make_nonlinear_ring("ov", 4, {{"th", 1.2}}), doctest::Contains("th is not a parameter of the ov ring"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(make_nonlinear_ring("ccc", 4, {}), doctest::Contains("expected ov, idm or acc"), std::invalid_argument);
    CHECK_THROWS_AS(make_nonlinear_ring("ov", 1, {}), std::invalid_argument);
}
