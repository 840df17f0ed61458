// Scalar DDEs with analytic roots: x'(t) = a x(t - tau) has the roots W_k(a tau) / tau.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "ddemap/solve/roots.hpp"
#include "lambert_w.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

LinearDDE scalar_delayed(double a, double tau) {
    MatrixXc a0 = MatrixXc::Zero(1, 1);
    MatrixXc a1(1, 1);
    a1(0, 0) = a;
    return LinearDDE(a0, {{a1, tau}});
}

std::vector<cplx> lambert_roots(double a, double tau, int count) {
    std::vector<cplx> w;
    for (int k = -8; k <= 7; ++k) {
        const cplx wk = ddemap::test::lambert_w(cplx(a * tau, 0.0), k);
        // the reference must satisfy its own definition
        REQUIRE(std::abs(wk * std::exp(wk) - a * tau) < 1e-13 * std::max(1.0, std::abs(wk * std::exp(wk))));
        w.push_back(wk / tau);
    }
    std::sort(w.begin(), w.end(), [](cplx x, cplx y) {
        return x.real() != y.real() ? x.real() > y.real() : x.imag() > y.imag();
    });
    w.resize(count);
    return w;
}

}  // namespace

TEST_CASE("x'(t) = a x(t - tau): rightmost roots are W_k(a tau)/tau") {
    const double cases[][2] = {{-1.0, 1.0}, {-0.5, 2.0}, {0.3, 1.0}, {-2.0, 0.7}, {-3.0, 1.3}, {1.5, 0.4}, {-0.2, 0.5}};
    for (const auto& c : cases) {
        const double a = c[0], tau = c[1];
        CAPTURE(a);
        CAPTURE(tau);
        RootOptions opt;
        opt.count = 6;
        const RootResult r = rightmost_roots(scalar_delayed(a, tau), opt);
        REQUIRE(r.status == Status::Converged);
        REQUIRE(r.roots.size() >= 6);
        const auto ref = lambert_roots(a, tau, 6);
        for (int i = 0; i < 6; ++i) {
            CAPTURE(i);
            CAPTURE(r.roots[i].value);
            CAPTURE(ref[i]);
            CHECK(std::abs(r.roots[i].value - ref[i]) < tol::root_abs * std::max(1.0, std::abs(ref[i])));
            CHECK(r.roots[i].residual < 1e-13);
        }
    }
}

TEST_CASE("x'(t) = -a x(t - tau) is stable iff a tau < pi/2") {
    for (double tau : {0.25, 1.0, 3.0}) {
        for (double eps : {1e-2, 1e-4, 1e-7}) {
            const double a_below = (M_PI / 2 - eps) / tau, a_above = (M_PI / 2 + eps) / tau;
            const double below = rightmost_roots(scalar_delayed(-a_below, tau)).spectral_abscissa();
            const double above = rightmost_roots(scalar_delayed(-a_above, tau)).spectral_abscissa();
            CAPTURE(tau);
            CAPTURE(eps);
            CHECK(below < 0.0);
            CHECK(above > 0.0);
        }
        // on the boundary the rightmost pair is +-i pi / (2 tau)
        const RootResult r = rightmost_roots(scalar_delayed(-M_PI / 2 / tau, tau));
        CHECK(std::abs(r.roots[0].value - cplx(0.0, M_PI / 2 / tau)) < tol::root_abs);
    }
}

TEST_CASE("tau = 0 is the ODE and small tau converges to it") {
    // x' = A0 x + A1 x(t - tau): 2x2 real, ODE matrix A0 + A1 has eigenvalues -1 +- 2i
    MatrixXc a0(2, 2), a1(2, 2);
    a0 << -1.0, 3.0, -1.0, -0.5;
    a1 << 0.0, 1.0, -1.0, -0.5;
    // A0 + A1 = [[-1, 4], [-2, -1]] -> lambda = -1 +- i sqrt(8)
    const cplx exact(-1.0, std::sqrt(8.0));
    const RootResult ode = rightmost_roots(LinearDDE(a0, {{a1, 0.0}}));
    CHECK(ode.degree == 0);
    REQUIRE(ode.roots.size() == 2);
    CHECK(std::abs(ode.roots[0].value - exact) < tol::root_abs);
    CHECK(std::abs(ode.roots[1].value - std::conj(exact)) < tol::root_abs);
    double previous = 1e300;
    for (double tau : {1e-2, 1e-4, 1e-6, 1e-8}) {
        const RootResult r = rightmost_roots(LinearDDE(a0, {{a1, tau}}));
        REQUIRE(r.status == Status::Converged);
        const double err = std::abs(r.roots[0].value - exact);
        CAPTURE(tau);
        CHECK(err < previous);
        CHECK(err < 10.0 * tau);  // first-order in tau: lambda(tau) = lambda(0) + O(tau)
        previous = err;
    }
}

TEST_CASE("complex coefficients and several delays: residuals and Newton refinement") {
    MatrixXc a0(2, 2), a1(2, 2), a2(2, 2);
    a0 << cplx(-1.0, 0.5), 0.3, cplx(0.0, -0.2), -2.0;
    a1 << 0.4, cplx(0.1, 0.1), -0.5, cplx(0.2, -0.3);
    a2 << cplx(0.0, 0.7), 0.0, 0.25, -0.6;
    const LinearDDE dde(a0, {{a1, 0.4}, {a2, 1.1}});
    CHECK_FALSE(dde.is_real());
    const RootResult r = rightmost_roots(dde);
    REQUIRE(r.status == Status::Converged);
    for (const auto& root : r.roots) {
        CHECK(root.residual < 1e-13);
        // the determinant vanishes at the root
        CHECK(std::abs(dde.characteristic_matrix(root.value).determinant()) < 1e-12 * (1.0 + std::norm(root.value)));
    }
}

TEST_CASE("bad problem descriptions are rejected with a message") {
    MatrixXc a0 = MatrixXc::Zero(2, 2);
    CHECK_THROWS_AS(LinearDDE(a0, {{MatrixXc::Zero(3, 3), 1.0}}), std::invalid_argument);
    CHECK_THROWS_WITH_AS(LinearDDE(a0, {{MatrixXc::Zero(2, 2), -1.0}}), "delay 1 = -1: expected a finite delay >= 0",
                         std::invalid_argument);
    MatrixXc bad = MatrixXc::Zero(2, 2);
    bad(0, 1) = std::nan("");
    CHECK_THROWS_AS(LinearDDE(bad, {}), std::invalid_argument);
    RootOptions o;
    o.count = 0;
    CHECK_THROWS_AS(o.validate(), std::invalid_argument);
}

TEST_SUITE_END();
