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
        if (r.status != Status::Converged) continue;  // undecided is allowed; a wrong certificate is not
        CHECK(std::abs(r.roots.front().value.real() - z.real()) < 1e-6);
        // nothing right of the reported abscissa (|l| <= 10 bounds every root with Re >= -1 here;
        // steps of 2e-4 against a distance of 1e-3 from the pair), and the pair counted left of it
        const double x = r.roots.front().value.real();
        CHECK(test::zeros_in_rectangle(D, x + 1e-3, 5.0, -10.0, 10.0, 100000) == 0);
        CHECK(test::zeros_in_rectangle(D, x - 1e-3, 5.0, -10.0, 10.0, 100000) == 2);
    }
}
