// Spectral convergence of the collocation in the degree M, against Lambert W.
#include <doctest/doctest.h>

#include <algorithm>
#include <functional>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "ddemap/discretize/collocation.hpp"
#include "ddemap/solve/roots.hpp"
#include "argument_count.hpp"
#include "lambert_w.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("the rightmost collocation eigenvalue converges as M grows") {
    // x'(t) = -x(t - 1): rightmost root W_0(-1)
    MatrixXc a0 = MatrixXc::Zero(1, 1), a1(1, 1);
    a1(0, 0) = -1.0;
    const LinearDDE dde(a0, {{a1, 1.0}});
    const cplx exact = ddemap::test::lambert_w(cplx(-1.0, 0.0), 0);
    double previous = 1e300;
    for (int m : {2, 4, 6, 8, 12}) {
        const MatrixXc a = collocation_matrix(dde, m);
        Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
        double err = 1e300;
        for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) err = std::min(err, std::abs(es.eigenvalues()(i) - exact));
        CAPTURE(m);
        CAPTURE(err);
        CHECK(err < previous * 0.5);
        previous = err;
    }
    CHECK(previous < 1e-8);
}

TEST_CASE("the adaptive degree reports why it is trusted") {
    MatrixXc a0 = MatrixXc::Zero(1, 1), a1(1, 1);
    a1(0, 0) = -2.0;
    const LinearDDE dde(a0, {{a1, 1.5}});
    const RootResult r = rightmost_roots(dde);
    CHECK(r.status == Status::Converged);
    CHECK(r.collocation_error <= 1e-10);
    CHECK(r.message.find("spectral accuracy") != std::string::npos);
    // forced to start low, the same roots come out through the two-degree certificate
    RootOptions low;
    low.degree = 4;
    low.dense.spectral_tolerance = 1e-300;
    const RootResult r2 = rightmost_roots(dde, low);
    CHECK(r2.status == Status::Converged);
    CHECK(r2.previous_degree > 0);
    CHECK(r2.degree > r2.previous_degree);
    CHECK(r2.degree_change <= 1e-11);
    CHECK(r2.message.find("agree between") != std::string::npos);
    REQUIRE(r2.roots.size() == r.roots.size());
    for (std::size_t i = 0; i < r.roots.size(); ++i) CHECK(std::abs(r.roots[i].value - r2.roots[i].value) < 1e-12);
}

TEST_SUITE_END();


// D(l) = l^2 + a l + b e^{-l tau}, the plant of an OVRV car (a = k1 th + k2, b = k1, tau = 0.5 s)
// at gains where its two rightmost roots nearly coincide (a pair -0.859163 -+ 2.6e-6 i, what a
// minimiser of the spectral abscissa drives them to). Rounding splits the pair into two real
// collocation eigenvalues at some degrees; Newton from a real start stays real and failed, the
// two were dropped, and the next roots (-10.73 -+ 9.41 i) were certified as the rightmost. The
// pair must be listed, and nothing may be certified without it: checked against Newton on the
// scalar D from a complex start and an argument-principle count right of the answer.
TEST_CASE("a nearly double complex pair split by rounding into two real eigenvalues is refined, never skipped" * doctest::test_suite("fast")) {
    const double k1 = 0.8421560728366616, k2 = 1.5232043282553798, th = 1.0, tau = 0.5;
    const double a = k1 * th + k2, b = k1;
    const auto D = [&](cplx l) { return l * l + a * l + b * std::exp(-l * tau); };
    const auto dD = [&](cplx l) { return 2.0 * l + a - tau * b * std::exp(-l * tau); };
    cplx z(-0.86, 1e-3);
    for (int i = 0; i < 100 && std::abs(D(z)) > 1e-15; ++i) z -= D(z) / dD(z);
    REQUIRE(std::abs(D(z)) < 1e-13);
    // x = (s, v) as the plant of a car is written: s' = -v, v' = b s(t - tau) - a v
    MatrixXc a0 = MatrixXc::Zero(2, 2), a1 = MatrixXc::Zero(2, 2);
    a0(0, 1) = -1.0;
    a0(1, 1) = -a;
    a1(1, 0) = b;
    const LinearDDE dde(a0, {{a1, tau}});
    for (int count : {1, 2, 4}) {
        CAPTURE(count);
        RootOptions ro;
        ro.count = count;
        const RootResult r = rightmost_roots(dde, ro);
        CAPTURE(r.message);
        REQUIRE(!r.roots.empty());
        // (once undecided at some counts: the pair's Newton values moved by 1e-6 between degrees)
        REQUIRE(r.status == Status::Converged);
        CHECK(std::abs(r.roots.front().value.real() - z.real()) < 1e-6);
        // nothing right of the reported abscissa (|l| <= 10 bounds every root with Re >= -1 here;
        // steps of 2e-4 against a distance of 1e-3 from the pair), and the pair counted left of it
        const double x = r.roots.front().value.real();
        CHECK(test::zeros_in_rectangle(D, x + 1e-3, 5.0, -10.0, 10.0, 100000) == 0);
        CHECK(test::zeros_in_rectangle(D, x - 1e-3, 5.0, -10.0, 10.0, 100000) == 2);
    }
}

namespace {

/// The plant of an OVRV car, s' = -v, v' = b s(t - tau) - a v: D(l) = l^2 + a l + b e^{-l tau}.
LinearDDE ovrv_plant(double a, double b, double tau) {
    MatrixXc a0 = MatrixXc::Zero(2, 2), a1 = MatrixXc::Zero(2, 2);
    a0(0, 1) = -1.0;
    a0(1, 1) = -a;
    a1(1, 0) = b;
    return LinearDDE(a0, {{a1, tau}});
}

}  // namespace

TEST_CASE("a double real root and two real roots 1.3e-6 apart are certified, each root listed" * doctest::test_suite("fast")) {
    const double tau = 0.5;
    // 1. D = D' = 0 at l0 = -1.5: b e^{-l0 tau} = (2 l0 + a) / tau and l0^2 + a l0 + (2 l0 + a) / tau = 0,
    // so a = 7.5, b = 9 e^{-0.75}: a double root at -1.5 exactly. Newton stalls 1e-8 from it, and
    // the values it stalled at moved between degrees: the roots were undecided
    {
        const double a = 7.5, b = 9.0 * std::exp(-0.75);
        const auto D = [&](cplx l) { return l * l + a * l + b * std::exp(-l * tau); };
        for (int count : {1, 2, 4}) {
            CAPTURE(count);
            RootOptions ro;
            ro.count = count;
            const RootResult r = rightmost_roots(ovrv_plant(a, b, tau), ro);
            CAPTURE(r.message);
            REQUIRE(r.status == Status::Converged);
            CHECK(std::abs(r.roots.front().value - cplx(-1.5, 0.0)) < 1e-7);  // a double root: sqrt(eps) accuracy
            // the argument principle: two zeros within 1e-3 of -1.5, none right of it
            CHECK(test::zeros_in_rectangle(D, -1.5 - 1e-3, -1.5 + 1e-3, -1e-3, 1e-3, 4000) == 2);
            CHECK(test::zeros_in_rectangle(D, -1.5 + 1e-3, 5.0, -10.0, 10.0, 100000) == 0);
        }
    }
    // 2. the minimum of the spectral abscissa that design_gains found at k1 = 5 (its bound),
    // th = 1: two real roots 2e-6 apart. Newton from both eigenvalues met one of them, and which
    // one changed with the degree: the plant was undecided (max degree reached) and so was the
    // design's verdict. Both must be listed, each where D changes sign on the real axis.
    {
        const double k1 = 4.999991689748873, a = k1 + 3.5518626863260914, b = k1;
        const auto D = [&](double l) { return l * l + a * l + b * std::exp(-l * tau); };
        RootOptions ro;
        ro.count = 2;
        const RootResult r = rightmost_roots(ovrv_plant(a, b, tau), ro);
        CAPTURE(r.message);
        REQUIRE(r.status == Status::Converged);
        REQUIRE(r.roots.size() >= 2);
        const double r1 = r.roots[0].value.real(), r2 = r.roots[1].value.real();
        CHECK(r.roots[0].value.imag() == 0.0);
        CHECK(r.roots[1].value.imag() == 0.0);
        CHECK(r1 - r2 > 1e-6);
        CHECK(r1 - r2 < 3e-6);
        for (const double x : {r1, r2}) CHECK(D(x - 1e-9) * D(x + 1e-9) < 0.0);
        CHECK(test::zeros_in_rectangle([&](cplx l) { return l * l + a * l + b * std::exp(-l * tau); }, r1 + 1e-3, 5.0, -10.0, 10.0, 100000) == 0);
    }
}
