// Spectral convergence of the collocation in the degree M, against Lambert W.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "ddemap/discretize/collocation.hpp"
#include "ddemap/solve/roots.hpp"
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
