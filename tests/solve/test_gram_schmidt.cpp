// The tall-matrix kernels of the compact Krylov basis (src/solve/internal/gram_schmidt.hpp)
// against Eigen's plain products, on sizes that are not multiples of the kernels' blocks
// (1000 rows, blocks of 256; 0 to 130 columns, unrolled by 4) and on a block of a wider matrix
// (an outer stride larger than the rows).
#include <doctest/doctest.h>

#include <random>

#include <Eigen/Dense>

#include "../tolerances.hpp"
#include "../../src/solve/internal/gram_schmidt.hpp"

TEST_SUITE_BEGIN("fast");

namespace {
Eigen::MatrixXcd random_matrix(Eigen::Index rows, Eigen::Index cols, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    Eigen::MatrixXcd m(rows, cols);
    for (Eigen::Index j = 0; j < cols; ++j)
        for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = {g(rng), g(rng)};
    return m;
}
}  // namespace

TEST_CASE("gram_schmidt: Q p, Q X and CGS2 against Eigen's products") {
    const Eigen::Index n = 1000;
    // an orthonormal basis of 150 columns, stored in the top rows of a taller matrix (outer
    // stride n + 37) and used through its leading r columns
    Eigen::MatrixXcd stored = random_matrix(n + 37, 150, 5);
    stored.topRows(n) = Eigen::HouseholderQR<Eigen::MatrixXcd>(random_matrix(n, 150, 1)).householderQ() *
                        Eigen::MatrixXcd::Identity(n, 150);
    for (Eigen::Index r : {0, 1, 3, 4, 7, 130}) {
        CAPTURE(r);
        const auto q = stored.topLeftCorner(n, r);
        if (r >= 2) REQUIRE(ddemap::detail::GsMatrix(q).outerStride() == n + 37);  // (one column: no stride)
        const Eigen::VectorXcd p = random_matrix(r, 1, 2 + static_cast<unsigned>(r)).col(0);
        const Eigen::VectorXcd w0 = random_matrix(n, 1, 3).col(0);
        const double scale = w0.norm() + (r > 0 ? p.norm() : 0.0);

        Eigen::VectorXcd w = w0;
        ddemap::detail::add_times(q, p, w);
        const Eigen::VectorXcd expect = w0 + q * p;
        CHECK((w - expect).norm() <= ddemap::test::tol::kernel_rel * scale);

        const Eigen::MatrixXcd x = random_matrix(r, 3, 4);
        const Eigen::MatrixXcd y = ddemap::detail::times_columns(q, x);
        CHECK(y.rows() == n);
        CHECK(y.cols() == 3);
        CHECK((y - q * x).norm() <= ddemap::test::tol::kernel_rel * (1.0 + x.norm()));

        // CGS2: w0 = Q h + w, w orthogonal to Q; with Q orthonormal, h = Q^H w0 and w the projection
        w = w0;
        const Eigen::VectorXcd h = ddemap::detail::orthogonalise_twice(q, w);
        REQUIRE(h.size() == r);
        CHECK((h - q.adjoint() * w0).norm() <= ddemap::test::tol::kernel_rel * w0.norm());
        CHECK((w - (w0 - q * (q.adjoint() * w0))).norm() <= ddemap::test::tol::kernel_rel * w0.norm());
        CHECK((q.adjoint() * w).norm() <= ddemap::test::tol::kernel_rel * w0.norm());
        CHECK((q * h + w - w0).norm() <= ddemap::test::tol::kernel_rel * w0.norm());
    }
}

TEST_SUITE_END();
