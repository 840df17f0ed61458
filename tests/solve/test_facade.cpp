// The rightmost_roots facade: dispatch of "auto", forced methods that do not apply, the three
// backends on the same problem, the one residual definition, and RootOptions::is_valid.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/SVD>

#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/ring_determinant.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"
#include "numeric_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::nearest;
using ddemap::test::linearised;
using ddemap::test::ovrv;
using ddemap::test::random_car;

namespace {

/// x' = a x(t - tau)
LinearDDE scalar_delayed(cplx a, double tau) {
    return LinearDDE(MatrixXc::Zero(1, 1), {{MatrixXc::Constant(1, 1, a), tau}});
}

/// A small mixed ring of one-leader cars (random OVRV cars, fixed seed).
std::vector<Linearisation> small_ring(int n, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<Linearisation> cars;
    for (int i = 0; i < n; ++i) cars.push_back(linearised(random_car(rng, false)));
    return cars;
}

RootOptions with(const std::string& method, int count) {
    RootOptions o;
    o.method = method;
    o.count = count;
    return o;
}

}  // namespace

TEST_CASE("facade dispatch: auto takes contour with a characteristic function, dense for small, complex or delay-free problems, shift_invert for large real ones") {
    // a one-leader ring has a characteristic function: contour
    const RootProblem ring = ring_root_problem(small_ring(10, 3));
    REQUIRE(ring.characteristic != nullptr);
    CHECK(choose_root_method(ring, RootOptions{}) == "contour");
    const RootResult rc = rightmost_roots(ring, with("auto", 4));
    CHECK(rc.method_given == "auto");
    CHECK(rc.method_used == "contour");
    CHECK(rc.status == Status::Converged);
    // ... unless a collocation degree is asked: then 20 real states with delays go to shift_invert
    RootOptions deg;
    deg.degree = 30;
    CHECK(choose_root_method(ring, deg) == "shift_invert");
    // the same system without its characteristic function: shift_invert (20 > 16 states)
    CHECK(choose_root_method(RootProblem{ring.dde, nullptr}, RootOptions{}) == "shift_invert");
    // ... and dense when the limit is raised
    RootOptions wide;
    wide.dense_limit = 20;
    CHECK(choose_root_method(RootProblem{ring.dde, nullptr}, wide) == "dense");
    // small, complex, delay-free: dense
    CHECK(choose_root_method(RootProblem{scalar_delayed(-1.0, 1.0), nullptr}, RootOptions{}) == "dense");
    const RootResult rd = rightmost_roots(scalar_delayed(-1.0, 1.0), RootOptions{});
    CHECK(rd.method_used == "dense");
    MatrixXc big = MatrixXc::Identity(40, 40) * cplx(-1.0, 0.5);
    CHECK(choose_root_method(RootProblem{LinearDDE(big, {{MatrixXc::Identity(40, 40) * 0.1, 1.0}}), nullptr}, RootOptions{}) ==
          "dense");
    CHECK(choose_root_method(RootProblem{LinearDDE(MatrixXc::Identity(40, 40) * -1.0, {}), nullptr}, RootOptions{}) == "dense");
}

TEST_CASE("facade dispatch: a forced method that does not apply throws std::invalid_argument saying why") {
    // contour without a characteristic function (a ring written out as a plain LinearDDE); a
    // ring with a CCC car has one (the transfer-matrix determinant), so auto takes contour
    std::mt19937 rng(5);
    std::vector<Linearisation> ccc{linearised(random_car(rng, false)), linearised(random_car(rng, true)),
                                   linearised(random_car(rng, false))};
    const RootProblem with_ccc = ring_root_problem(ccc);
    CHECK(with_ccc.characteristic != nullptr);
    CHECK(choose_root_method(with_ccc, RootOptions{}) == "contour");
    const RootProblem p{with_ccc.dde, nullptr};
    CHECK_THROWS_WITH_AS(rightmost_roots(p, with("contour", 4)), doctest::Contains("needs a scalar characteristic function"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(rightmost_roots(scalar_delayed(-1.0, 1.0), with("contour", 2)),
                         doctest::Contains("method 'contour'"), std::invalid_argument);
    // contour with a collocation degree
    RootOptions o = with("contour", 4);
    o.degree = 20;
    CHECK_THROWS_WITH_AS(rightmost_roots(ring_root_problem(small_ring(4, 1)), o), doctest::Contains("no collocation degree"),
                         std::invalid_argument);
    // shift_invert on complex coefficients or an ODE
    CHECK_THROWS_WITH_AS(rightmost_roots(scalar_delayed(cplx(-1.0, 0.3), 1.0), with("shift_invert", 2)),
                         doctest::Contains("needs real coefficients"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(rightmost_roots(LinearDDE(MatrixXc::Identity(20, 20) * -1.0, {}), with("shift_invert", 2)),
                         doctest::Contains("at least one delay"), std::invalid_argument);
    // an unknown method
    CHECK_THROWS_WITH_AS(rightmost_roots(scalar_delayed(-1.0, 1.0), with("qr", 2)),
                         doctest::Contains("method = 'qr': expected auto, dense, shift_invert or contour"), std::invalid_argument);
}

TEST_CASE("the three backends agree on a small mixed ring (dense, shift_invert, contour to 1e-10)") {
    for (unsigned seed : {11u, 12u}) {
        const RootProblem ring = ring_root_problem(small_ring(5, seed));
        const RootResult d = rightmost_roots(ring, with("dense", 8));
        const RootResult s = rightmost_roots(ring, with("shift_invert", 8));
        const RootResult c = rightmost_roots(ring, with("contour", 8));
        CAPTURE(seed);
        REQUIRE(d.status == Status::Converged);
        REQUIRE(s.status == Status::Converged);
        REQUIRE(c.status == Status::Converged);
        CHECK(d.method_used == "dense");
        CHECK(s.method_used == "shift_invert");
        CHECK(c.method_used == "contour");
        REQUIRE(d.roots.size() >= 8);
        REQUIRE(s.roots.size() == d.roots.size());
        REQUIRE(c.roots.size() == d.roots.size());
        for (const auto& r : d.roots) {
            CAPTURE(r.value);
            CHECK(nearest(s.roots, r.value) < 1e-10);
            CHECK(nearest(c.roots, r.value) < 1e-10);
        }
        // one residual definition: all three report small relative backward errors
        for (const RootResult* r : {&d, &s, &c}) {
            CHECK(r->max_residual < 1e-12);
            for (const auto& x : r->roots) CHECK(x.residual <= r->max_residual);
        }
        // the certificates: contour and shift_invert state the rectangle, every root lies inside it
        for (const RootResult* r : {&s, &c}) {
            CHECK(r->right_bound >= r->spectral_abscissa());
            for (const auto& x : r->roots)
                if (x.value.real() >= r->strip_floor) CHECK(std::abs(x.value.imag()) <= r->height);
        }
        CHECK(c.contour_counts > 0);
        CHECK(c.evaluations > 0);
        CHECK(s.shifts > 0);
        CHECK(d.degree > 0);
    }
}

TEST_CASE("the one residual: ||Delta v|| / (||v|| scale) with v the smallest right singular vector is sigma_min / scale") {
    std::mt19937 rng(2);
    std::normal_distribution<double> g(0.0, 1.0);
    MatrixXc a0(3, 3), a1(3, 3);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            a0(i, j) = cplx(g(rng), 0.3 * g(rng));
            a1(i, j) = cplx(g(rng), 0.0);
        }
    const LinearDDE dde(a0, {{a1, 0.7}});
    for (cplx z : {cplx(0.3, 1.2), cplx(-1.0, 0.0), cplx(2.0, -5.0)}) {
        Eigen::JacobiSVD<MatrixXc> svd(dde.characteristic_matrix(z), Eigen::ComputeFullV);
        const VectorXc v = svd.matrixV().col(2);
        const double smin = svd.singularValues()(2);
        const double scale = std::abs(z) + dde.bounds().radius(z.real());
        CHECK(relative_residual(dde, z) == doctest::Approx(smin / scale).epsilon(1e-12));
        CHECK(relative_residual(dde, z, v) == doctest::Approx(smin / scale).epsilon(1e-10));
        // any other vector has a larger backward error
        CHECK(relative_residual(dde, z, VectorXc::Ones(3)) >= relative_residual(dde, z) * (1.0 - 1e-12));
    }
    // the same definition on sparse storage (its R uses the norm bound sqrt(||.||_1 ||.||_inf))
    const LinearDDE ring = ring_root_problem(small_ring(3, 4)).dde;
    REQUIRE(ring.is_sparse());
    const cplx z(0.1, 0.4);
    const VectorXc v = VectorXc::LinSpaced(ring.dimension(), 1.0, 2.0);
    const double direct = (ring.to_dense().characteristic_matrix(z) * v).norm() / (v.norm() * (std::abs(z) + ring.bounds().radius(z.real())));
    CHECK(relative_residual(ring, z, v) == doctest::Approx(direct).epsilon(1e-12));
    // dense storage has exact 2-norms: a bound at least as tight
    CHECK(ring.to_dense().root_bound(z.real()) <= ring.root_bound(z.real()) * (1.0 + 1e-12));
}

TEST_CASE("the root bound holds for every root found, on both storages") {
    const RootProblem ring = ring_root_problem(small_ring(6, 9));
    const RootResult r = rightmost_roots(ring, with("dense", 10));
    REQUIRE(r.status == Status::Converged);
    const LinearDDE dense = ring.dde.to_dense();
    for (const auto& x : r.roots) {
        CHECK(std::abs(x.value) <= ring.dde.root_bound(x.value.real()) * (1.0 + 1e-12));
        CHECK(std::abs(x.value) <= dense.root_bound(x.value.real()) * (1.0 + 1e-12));
        CHECK(x.value.real() <= ring.dde.bounds().right_bound() + 1e-12);
    }
    // sparse storage refuses dense accessors (no silent O(n^2) copies)
    CHECK_THROWS_AS(ring.dde.a0(), std::logic_error);
    CHECK_THROWS_AS(dense.sparse_a0(), std::logic_error);
    CHECK(dense.to_sparse().sparse_delayed().size() == ring.dde.sparse_delayed().size());
}

TEST_CASE("the height bound |Im lambda| <= H(Re lambda) holds for every root found, and ignores ||A0|| when A0 is symmetric") {
    // random nonsymmetric systems (dense path, many roots) on both storages
    std::mt19937 rng(41);
    std::normal_distribution<double> g(0.0, 1.0);
    for (int trial = 0; trial < 6; ++trial) {
        const int n = 3 + trial % 3;
        MatrixXc a0(n, n), a1(n, n);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                a0(i, j) = g(rng) + (i == j ? -1.0 : 0.0);
                a1(i, j) = 0.6 * g(rng);
            }
        const LinearDDE dde(a0, {{a1, 0.5 + 0.3 * trial}});
        RootOptions o;
        o.method = "dense";
        o.count = 40;
        const RootResult r = rightmost_roots(dde, o);
        REQUIRE(r.status == Status::Converged);
        REQUIRE(r.roots.size() >= 20);
        const LinearDDE sparse = dde.to_sparse();
        for (const auto& x : r.roots) {
            CAPTURE(x.value);
            CHECK(std::abs(x.value.imag()) <= dde.bounds().height(x.value.real()) * (1.0 + 1e-12));
            CHECK(std::abs(x.value.imag()) <= sparse.bounds().height(x.value.real()) * (1.0 + 1e-12));
            CHECK(dde.bounds().height(x.value.real()) <= dde.bounds().radius(x.value.real()) * (1.0 + 1e-12));
            // nor does the numerical range exclude a quadrant that holds a root
            const double x0 = x.value.real() - 1e-9, y0 = std::abs(x.value.imag()) - 1e-9;
            CHECK_FALSE(dde.bounds().excludes(x0, y0));
            CHECK_FALSE(sparse.bounds().excludes(x0, y0));
        }
    }
    // u' = d u_xx - u(t - 1) on 50 points with ||A0|| = 4 d: the roots' |Im| stays below
    // e^{-Re tau} whatever d, while the disc bound R grows with d
    for (double d : {1.0, 1e6}) {
        std::vector<Eigen::Triplet<double>> t0, t1;
        const int n = 50;
        for (int i = 0; i < n; ++i) {
            t0.emplace_back(i, i, -2.0 * d + 0.4);
            if (i > 0) t0.emplace_back(i, i - 1, d);
            if (i + 1 < n) t0.emplace_back(i, i + 1, d);
            t1.emplace_back(i, i, -1.0);
        }
        SparseMatrixXd a0(n, n), a1(n, n);
        a0.setFromTriplets(t0.begin(), t0.end());
        a1.setFromTriplets(t1.begin(), t1.end());
        const LinearDDE dde(a0, {{a1, 1.0}});
        for (double a : {-0.5, 0.0, 0.3}) {
            CHECK(dde.bounds().height(a) == doctest::Approx(std::exp(-a)).epsilon(1e-14));
            CHECK(dde.bounds().radius(a) >= 4.0 * d);
            // W(A0) is real (mu = 0.4 by Gershgorin): right of a the roots are within e^{-a} of it
            CHECK(dde.bounds().excludes(a, 1.001 * std::exp(-a)));
            CHECK_FALSE(dde.bounds().excludes(a, 0.999 * std::exp(-a)));
            CHECK(dde.bounds().excludes(0.4 + 1.001 * std::exp(-a), 0.0));  // right of mu + N(a) >= mu + N(x)
        }
    }
}

TEST_CASE("RootOptions::is_valid names the field in the API's words") {
    std::string why = "untouched";
    CHECK(RootOptions{}.is_valid(&why));
    CHECK(why == "untouched");
    auto message = [](RootOptions o) {
        std::string m;
        CHECK_FALSE(o.is_valid(&m));
        CHECK_THROWS_WITH_AS(o.validate(), m.c_str(), std::invalid_argument);
        return m;
    };
    RootOptions o;
    o.count = 0;
    CHECK(message(o) == "count = 0: expected an integer >= 1");
    o = RootOptions{};
    o.method = "sparse";
    CHECK(message(o) == "method = 'sparse': expected auto, dense, shift_invert or contour");
    o = RootOptions{};
    o.degree = 1;
    CHECK(message(o) == "degree = 1: expected 0 (automatic) or an integer >= 2");
    o = RootOptions{};
    o.residual_tolerance = -1.0;
    CHECK(message(o) == "residual_tolerance = -1: expected a finite value > 0");
    o = RootOptions{};
    o.dense.newton.max_iterations = 0;
    CHECK(message(o) == "dense.newton.max_iterations: expected an integer >= 1");
    o = RootOptions{};
    o.shift_invert.max_shifts = 0;
    CHECK(message(o) == "shift_invert.max_shifts = 0: expected an integer >= 1");
    o = RootOptions{};
    o.contour.max_arg_step = 2.0;
    CHECK(message(o) == "contour.max_arg_step = 2: expected a value in (0, 1] radians");
    o = RootOptions{};
    o.dense.depth = -1.0;
    CHECK(message(o) == "dense.depth = -1: expected a finite value >= 0 (0 = automatic)");
    o = RootOptions{};
    o.dense.max_rows = 2;
    CHECK(message(o) == "dense.max_rows = 2: expected an integer >= 3");
}

TEST_CASE("dense path: the collocation matrix stays within dense.max_rows, and a degree beyond it stops undecided") {
    // 12 states, one delay (fixed seed): the 60 rightmost roots lie deep in the left half plane,
    // where |Im lambda| is large and the degree must grow beyond M = 19
    std::mt19937 rng(41);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int n = 12;
    MatrixXc a0 = MatrixXc::Zero(n, n), a1 = MatrixXc::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        a0(i, i) = -2.0 + 0.5 * u(rng);
        for (int j = 0; j < n; ++j) a1(i, j) = 0.4 * u(rng);
    }
    const LinearDDE dde(a0, {{a1, 0.9}});
    RootOptions o = with("dense", 60);
    o.dense.max_rows = 240;  // M <= 19
    const RootResult capped = rightmost_roots(dde, o);
    CHECK(capped.status == Status::BudgetExhausted);
    CHECK(capped.degree == 19);  // the largest degree within the cap was tried last
    CHECK(capped.message.find("dense.max_rows = 240") != std::string::npos);
    CHECK_FALSE(capped.roots.empty());  // those of M = 19, unsettled
    // a few roots settle within the cap: the same as with the default cap (M <= 249)
    o.count = 4;
    const RootResult few = rightmost_roots(dde, o);
    REQUIRE(few.status == Status::Converged);
    CHECK((few.degree + 1) * n <= 240);
    const RootResult free = rightmost_roots(dde, with("dense", 4));
    REQUIRE(free.status == Status::Converged);
    REQUIRE(few.roots.size() == free.roots.size());
    for (std::size_t i = 0; i < few.roots.size(); ++i)
        CHECK(std::abs(few.roots[i].value - free.roots[i].value) <= test::tol::same_root * std::max(1.0, std::abs(free.roots[i].value)));
}

TEST_SUITE_END();
