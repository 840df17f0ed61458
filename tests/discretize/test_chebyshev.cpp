#include <doctest/doctest.h>

#include <cmath>

#include "ddemap/discretize/chebyshev.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("Chebyshev differentiation is exact for polynomials up to the degree") {
    for (int m : {4, 9, 16}) {
        const Eigen::VectorXd x = chebyshev_points(m);
        CHECK(x(0) == 1.0);
        CHECK(x(m) == -1.0);
        const Eigen::MatrixXd d = chebyshev_differentiation(m);
        // p(x) = x^m + 3x^2 - x
        Eigen::VectorXd p(m + 1), dp(m + 1);
        for (int j = 0; j <= m; ++j) {
            p(j) = std::pow(x(j), m) + 3 * x(j) * x(j) - x(j);
            dp(j) = m * std::pow(x(j), m - 1) + 6 * x(j) - 1;
        }
        CHECK((d * p - dp).cwiseAbs().maxCoeff() < 1e-11 * m * m);
    }
}

TEST_CASE("barycentric Lagrange row interpolates polynomials and reproduces nodes") {
    const int m = 12;
    const Eigen::VectorXd x = chebyshev_points(m);
    Eigen::VectorXd p(m + 1);
    for (int j = 0; j <= m; ++j) p(j) = std::cos(3 * x(j)) * 0 + std::pow(x(j), 7) - 2 * x(j);
    for (double t : {-0.95, -0.3, 0.0, 0.41, 0.999}) {
        const double v = chebyshev_lagrange_row(m, t).dot(p);
        CHECK(v == doctest::Approx(std::pow(t, 7) - 2 * t).epsilon(1e-13));
    }
    const Eigen::VectorXd at_node = chebyshev_lagrange_row(m, x(3));
    CHECK(at_node(3) == 1.0);
    CHECK(at_node.sum() == 1.0);
}

TEST_SUITE_END();
