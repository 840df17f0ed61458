// The structured sparse shift-invert against the dense collocation matrix of the same degree.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "ddemap/discretize/collocation.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/solve/shift_invert.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
/// A ring of N OVRV cars with their own parameters (random, fixed seed), car i following i-1.
LinearDDE random_ring(int cars, unsigned seed, std::vector<double>& delays_out) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int n = 2 * cars;
    std::vector<Eigen::Triplet<double>> a0;
    std::vector<std::vector<Eigen::Triplet<double>>> by_delay(3);
    const double delays[3] = {0.3, 0.55, 0.8};
    for (int i = 0; i < cars; ++i) {
        const double k1 = 0.02 + 0.5 * u(rng), k2 = 0.05 + 0.6 * u(rng), th = 0.5 + 1.5 * u(rng);
        const int d = static_cast<int>(3 * u(rng)) % 3;
        const int ahead = (i + cars - 1) % cars;
        const int s = 2 * i, v = 2 * i + 1, va = 2 * ahead + 1;
        a0.emplace_back(s, va, 1.0);
        a0.emplace_back(s, v, -1.0);
        a0.emplace_back(v, v, -(k1 * th + k2));
        by_delay[d].emplace_back(v, s, k1);
        by_delay[d].emplace_back(v, va, k2);
    }
    SparseMatrixXd m0(n, n);
    m0.setFromTriplets(a0.begin(), a0.end());
    std::vector<SparseDelayTerm> terms;
    for (int d = 0; d < 3; ++d) {
        if (by_delay[d].empty()) continue;
        Eigen::SparseMatrix<double> m(n, n);
        m.setFromTriplets(by_delay[d].begin(), by_delay[d].end());
        terms.push_back({m, delays[d]});
        delays_out.push_back(delays[d]);
    }
    return LinearDDE(m0, terms);
}
}  // namespace

TEST_CASE("structured shift-invert eigenvalues equal the dense collocation eigenvalues") {
    for (unsigned seed : {1u, 2u, 3u}) {
        std::vector<double> delays;
        const LinearDDE dde = random_ring(8, seed, delays);
        const int degree = 12;
        const SparseEigenResult sp = sparse_collocation_eigenvalues(dde, degree, {cplx(0.1, 0.0), cplx(0.1, 0.6)}, 8);
        CHECK(sp.status == Status::Converged);
        REQUIRE(sp.values.size() >= 8);
        const MatrixXc a = collocation_matrix(dde.to_dense(), degree);
        Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
        for (cplx z : sp.values) {
            double nearest = 1e300;
            for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) nearest = std::min(nearest, std::abs(es.eigenvalues()(i) - z));
            CAPTURE(seed);
            CAPTURE(z);
            CHECK(nearest < 1e-9 * std::max(1.0, std::abs(z)));
        }
        // the eigenvalue nearest each shift is among those found
        for (cplx sigma : {cplx(0.1, 0.0), cplx(0.1, 0.6)}) {
            cplx best = es.eigenvalues()(0);
            for (Eigen::Index i = 1; i < es.eigenvalues().size(); ++i)
                if (std::abs(es.eigenvalues()(i) - sigma) < std::abs(best - sigma)) best = es.eigenvalues()(i);
            const bool found = std::any_of(sp.values.begin(), sp.values.end(), [&](cplx z) { return std::abs(z - best) < 1e-9; });
            CHECK(found);
        }
    }
}

TEST_CASE("restarted compact Krylov runs at complex shifts find the dense collocation eigenvalues") {
    // A basis of 24 vectors for 8 eigenvalues: the runs restart and compress their n x r basis
    // (TOAR). At a complex shift the coefficients are complex, and the compressed basis must be
    // Q conj(W) for coefficients a W (a wrong conjugate broke the Krylov relation by O(|theta|)
    // and produced 'converged' Ritz values that were no eigenvalues).
    for (unsigned seed : {1u, 2u, 3u}) {
        std::vector<double> delays;
        const LinearDDE dde = random_ring(8, seed, delays);
        const int degree = 12;
        const MatrixXc a = collocation_matrix(dde.to_dense(), degree);
        Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
        const std::vector<cplx> shifts{cplx(0.1, 0.6), cplx(-0.2, 1.1), cplx(0.05, 0.3)};
        SparseEigenOptions o;
        o.arnoldi = "compact";
        o.basis = 24;
        o.restarts = 60;
        o.tolerance = 1e-12;
        const SparseEigenResult sp = sparse_collocation_eigenvalues(dde, degree, shifts, 8, o);
        CAPTURE(seed);
        CHECK(sp.status == Status::Converged);
        CHECK(sp.restarts > 0);
        REQUIRE(sp.values.size() >= 8);
        for (cplx z : sp.values) {
            double nearest = 1e300;
            for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) nearest = std::min(nearest, std::abs(es.eigenvalues()(i) - z));
            CAPTURE(z);
            CHECK(nearest < 1e-9 * std::max(1.0, std::abs(z)));
        }
        // and the 8 nearest each shift are all there
        for (cplx sigma : shifts) {
            std::vector<cplx> ev(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
            std::sort(ev.begin(), ev.end(), [&](cplx x, cplx y) { return std::abs(x - sigma) < std::abs(y - sigma); });
            for (int i = 0; i < 8; ++i) {
                const bool found = std::any_of(sp.values.begin(), sp.values.end(), [&](cplx z) { return std::abs(z - ev[i]) < 1e-9; });
                CAPTURE(sigma);
                CAPTURE(i);
                CHECK(found);
            }
        }
    }
}

TEST_CASE("a compact Krylov run at a shift on an eigenvalue (lambda = 0 of a ring) still finds the eigenvalues around it") {
    // lambda = 0 is an exact eigenvalue of a ring's collocation matrix (the constant history s_i =
    // th_i c, v_i = c): at sigma = 0 its |theta| is about 1/eps, and every Krylov vector carries a
    // rounding error that large along it; the run is made again beside it
    for (unsigned seed : {4u, 5u}) {
        std::vector<double> delays;
        const LinearDDE dde = random_ring(8, seed, delays);
        const int degree = 12;
        const MatrixXc a = collocation_matrix(dde.to_dense(), degree);
        Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
        std::vector<cplx> ev(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
        std::sort(ev.begin(), ev.end(), [](cplx x, cplx y) { return std::abs(x) < std::abs(y); });
        REQUIRE(std::abs(ev[0]) < 1e-12);
        SparseEigenOptions o;
        o.arnoldi = "compact";
        o.basis = 60;
        o.tolerance = 1e-12;
        const SparseEigenResult sp = sparse_collocation_eigenvalues(dde, degree, {cplx(0.0, 0.0)}, 10, o);
        CAPTURE(seed);
        CHECK(sp.status == Status::Converged);
        REQUIRE(sp.values.size() >= 10);
        for (cplx z : sp.values) {
            double nearest = 1e300;
            for (cplx w : ev) nearest = std::min(nearest, std::abs(w - z));
            CAPTURE(z);
            CHECK(nearest < 1e-9 * std::max(1.0, std::abs(z)));
        }
    }
}

TEST_SUITE_END();
