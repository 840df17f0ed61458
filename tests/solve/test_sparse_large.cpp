// The compact Krylov path of shift_invert (large sparse systems, issue 13 item 3) against the
// closed-form (Lambert W) roots of a delayed reaction-diffusion equation and against the reference path
// (Spectra's Arnoldi on the full collocation vectors) on random sparse systems.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "../tolerances.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/solve/shift_invert.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

/// u' = dx u_xx + dy u_yy + a u - b u(t - tau) on an nx x ny grid (Dirichlet, lattice units),
/// as bench/sparse_systems.py writes it.
LinearDDE reaction_diffusion(int nx, int ny, double dx, double dy, double a, double b, double tau) {
    const int n = nx * ny;
    std::vector<Eigen::Triplet<double>> t0, t1;
    auto idx = [&](int i, int j) { return i + nx * j; };
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const int p = idx(i, j);
            t0.emplace_back(p, p, -2.0 * dx - 2.0 * dy + a);
            if (i > 0) t0.emplace_back(p, idx(i - 1, j), dx);
            if (i < nx - 1) t0.emplace_back(p, idx(i + 1, j), dx);
            if (j > 0) t0.emplace_back(p, idx(i, j - 1), dy);
            if (j < ny - 1) t0.emplace_back(p, idx(i, j + 1), dy);
            t1.emplace_back(p, p, -b);
        }
    SparseMatrixXd a0(n, n), a1(n, n);
    a0.setFromTriplets(t0.begin(), t0.end());
    a1.setFromTriplets(t1.begin(), t1.end());
    return LinearDDE(a0, {{a1, tau}});
}

/// Its roots from the closed form: for each Laplacian eigenvalue mu (sum of the 1-D Dirichlet
/// eigenvalues -4 d sin^2(j pi / (2 (n + 1)))), c = mu + a and lambda = c + W_k(-b tau e^{-c tau}) / tau.
/// Each branch |k| <= 4 is found by Newton on lambda - c + b e^{-lambda tau} from the
/// asymptotic W_k ~ L - log L, L = log z + 2 pi i k (and its conjugate), duplicates removed;
/// rightmost first.
std::vector<cplx> closed_form_roots(int nx, int ny, double dx, double dy, double a, double b, double tau) {
    std::vector<cplx> out;
    for (int j = 1; j <= nx; ++j)
        for (int l = 1; l <= ny; ++l) {
            const double sx = std::sin(j * M_PI / (2.0 * (nx + 1))), sy = std::sin(l * M_PI / (2.0 * (ny + 1)));
            const double c = -4.0 * dx * sx * sx - 4.0 * dy * sy * sy + a;
            const cplx z(-b * tau * std::exp(-c * tau), 0.0);
            for (int k = -4; k <= 4; ++k)
                for (int side : {1, -1}) {
                    const cplx big = std::log(z) + cplx(0.0, 2.0 * M_PI * k);
                    cplx w = big - std::log(big);
                    if (side < 0) w = std::conj(w);
                    cplx lambda = c + w / tau;
                    for (int it = 0; it < 100; ++it) {
                        const cplx e = b * std::exp(-lambda * tau);
                        const cplx step = (lambda - c + e) / (1.0 - tau * e);
                        lambda -= step;
                        if (std::abs(step) <= 1e-15 * std::max(1.0, std::abs(lambda))) break;
                    }
                    if (!(std::abs(lambda - c + b * std::exp(-lambda * tau)) <= 1e-12)) continue;  // (NaN: e^{-c tau} overflowed)
                    const bool seen = std::any_of(out.begin(), out.end(), [&](cplx x) { return std::abs(x - lambda) < 1e-9; });
                    if (!seen) out.push_back(lambda);
                }
        }
    std::sort(out.begin(), out.end(), [](cplx x, cplx y) { return x.real() > y.real(); });
    return out;
}

/// A random sparse real system: A0 = -2 I + sparse noise, 1..3 delays with sparse matrices.
LinearDDE random_sparse(int n, int delays, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_int_distribution<int> pick(0, n - 1);
    std::vector<Eigen::Triplet<double>> t0;
    for (int i = 0; i < n; ++i) t0.emplace_back(i, i, -2.0 + 0.5 * u(rng));
    for (int e = 0; e < 3 * n; ++e) t0.emplace_back(pick(rng), pick(rng), 0.6 * u(rng));
    SparseMatrixXd a0(n, n);
    a0.setFromTriplets(t0.begin(), t0.end());
    std::vector<SparseDelayTerm> terms;
    for (int k = 0; k < delays; ++k) {
        std::vector<Eigen::Triplet<double>> t;
        for (int e = 0; e < 2 * n; ++e) t.emplace_back(pick(rng), pick(rng), 0.8 * u(rng));
        SparseMatrixXd m(n, n);
        m.setFromTriplets(t.begin(), t.end());
        terms.push_back({m, 0.4 + 0.5 * k + 0.1 * u(rng)});
    }
    return LinearDDE(a0, terms);
}

/// Every listed root is a closed-form root (within `tol`), no two listed roots are the same
/// closed-form root, and every closed-form root right of the last listed one is listed.
void check_against_closed_form(const RootResult& r, const std::vector<cplx>& ref, double tol = test::tol::root_abs) {
    std::vector<std::size_t> matched;
    for (const auto& x : r.roots) {
        std::size_t best = 0;
        for (std::size_t i = 1; i < ref.size(); ++i)
            if (std::abs(ref[i] - x.value) < std::abs(ref[best] - x.value)) best = i;
        CAPTURE(x.value);
        CHECK(std::abs(ref[best] - x.value) <= tol);
        CHECK(std::find(matched.begin(), matched.end(), best) == matched.end());
        matched.push_back(best);
    }
    const double last = r.roots.back().value.real();
    const auto right = std::count_if(ref.begin(), ref.end(), [&](cplx z) { return z.real() > last + tol; });
    const auto listed = std::count_if(r.roots.begin(), r.roots.end(), [&](const Root& x) { return x.value.real() > last + tol; });
    CHECK(right == listed);
}

}  // namespace

TEST_CASE("compact Krylov path: reaction-diffusion roots equal the Lambert W closed form, none missed") {
    const int nx = 12, ny = 9;
    const double dx = 1.0, dy = 0.37, a = 0.5, b = 1.0, tau = 2.0;
    const LinearDDE dde = reaction_diffusion(nx, ny, dx, dy, a, b, tau);
    RootOptions o;
    o.method = "shift_invert";
    o.count = 6;
    const RootResult r = rightmost_roots(dde, o);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(r.roots.size() >= 6);
    check_against_closed_form(r, closed_form_roots(nx, ny, dx, dy, a, b, tau));  // and completeness
    CHECK(r.message.find("compact Arnoldi") != std::string::npos);
}

TEST_CASE("compact Krylov path equals the full-basis reference path on random sparse systems") {
    for (unsigned seed : {11u, 12u, 13u}) {
        const int delays = 1 + static_cast<int>(seed % 3);
        const LinearDDE dde = random_sparse(60, delays, seed);
        RootOptions o;
        o.method = "shift_invert";
        o.count = 6;
        const RootResult fast = rightmost_roots(dde, o);
        o.shift_invert.arnoldi = "spectra";
        const RootResult ref = rightmost_roots(dde, o);
        CAPTURE(seed);
        REQUIRE(fast.status == Status::Converged);
        REQUIRE(ref.status == Status::Converged);
        REQUIRE(fast.roots.size() == ref.roots.size());
        for (std::size_t i = 0; i < ref.roots.size(); ++i) {
            CAPTURE(i);
            CHECK(std::abs(fast.roots[i].value - ref.roots[i].value) <= test::tol::same_root * std::max(1.0, std::abs(ref.roots[i].value)));
        }
    }
}

TEST_CASE("restarted compact Krylov path: a cluster of nearly equal Laplacian modes, every closed-form root found") {
    // dy = 0.97 dx: the modes (i, j) and (j, i) are nearly equal, and the 12 rightmost roots come
    // from a cluster of pairs (0.002 to 0.02 apart); a basis of 60 vectors (nev 16) must restart
    const int nx = 16, ny = 16;
    const double dx = 1.0, dy = 0.97, a = 0.5, b = 1.0, tau = 2.0;
    const LinearDDE dde = reaction_diffusion(nx, ny, dx, dy, a, b, tau);
    RootOptions o;
    o.method = "shift_invert";
    o.count = 12;
    o.shift_invert.eigenvalues_per_shift = 16;
    o.shift_invert.compact_max_steps = 60;
    o.shift_invert.compact_restarts = 40;
    const RootResult r = rightmost_roots(dde, o);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(r.roots.size() >= 12);
    CHECK(r.arnoldi_restarts > 0);
    check_against_closed_form(r, closed_form_roots(nx, ny, dx, dy, a, b, tau));
}

TEST_CASE("restarted and unrestarted compact Krylov runs give the same roots") {
    auto same = [](const RootResult& x, const RootResult& y) {
        REQUIRE(x.status == Status::Converged);
        REQUIRE(y.status == Status::Converged);
        REQUIRE(x.roots.size() == y.roots.size());
        for (std::size_t i = 0; i < x.roots.size(); ++i) {
            CAPTURE(i);
            CHECK(std::abs(x.roots[i].value - y.roots[i].value) <= test::tol::same_root * std::max(1.0, std::abs(y.roots[i].value)));
        }
    };
    std::vector<LinearDDE> problems{reaction_diffusion(12, 9, 1.0, 0.37, 0.5, 1.0, 2.0)};
    for (unsigned seed : {21u, 22u}) problems.push_back(random_sparse(80, 1 + static_cast<int>(seed % 3), seed));
    for (std::size_t p = 0; p < problems.size(); ++p) {
        CAPTURE(p);
        RootOptions o;
        o.method = "shift_invert";
        o.count = 8;
        o.shift_invert.eigenvalues_per_shift = 12;
        o.shift_invert.compact_max_steps = 50;  // small: the restarted runs do restart
        o.shift_invert.compact_restarts = 40;
        const RootResult restarted = rightmost_roots(problems[p], o);
        o.shift_invert.compact_max_steps = 400;  // large enough to converge without restarts
        o.shift_invert.compact_restarts = 0;
        const RootResult plain = rightmost_roots(problems[p], o);
        CHECK(restarted.arnoldi_restarts > 0);
        CHECK(plain.arnoldi_restarts == 0);
        same(restarted, plain);
    }
}

TEST_CASE("root_free_radius: no root of a dense computation lies in the disc, and the radius is the formulas'" * doctest::test_suite("slow")) {
    // random sparse systems: every root right of the dense path's certified floor is known.
    // The radius must (1) hold no root, (2) be at most the larger of the two bounds with the
    // exact s = sigma_min(Delta(z)), ||Delta'(z)|| and a = ||Delta(z)^{-1} Delta'(z)||, and (3) at
    // least the larger of s / (1.25 L) and bound 2 with s / 1.25 and 1.25 a (a Lanczos estimate
    // of a squared norm never exceeds it). Bound 2 must be the larger at some points (else the
    // checks would not reach it).
    int second_larger = 0;
    for (unsigned seed : {31u, 32u, 33u}) {
        const LinearDDE dde = random_sparse(24, 1 + static_cast<int>(seed % 2), seed);
        RootOptions o;
        o.method = "dense";
        o.count = 20;
        const RootResult r = rightmost_roots(dde.to_dense(), o);
        REQUIRE(r.status == Status::Converged);
        const double floor = r.strip_floor;
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> ux(floor + 1.5, floor + 3.0), uy(0.0, 3.0);
        for (int k = 0; k < 25; ++k) {
            const cplx z(ux(rng), uy(rng));
            const double x0 = z.real() - 1.0;
            const double rad = root_free_radius(dde, z, x0);
            // the claim: no root in the disc right of x0 (the whole disc when rad < 1); x0 lies
            // right of the floor (Re z >= floor + 1.5), so every root there is known
            double nearest = 1e300;
            for (const auto& x : r.roots)
                if (x.value.real() >= x0) nearest = std::min(nearest, std::abs(x.value - z));
            const Eigen::MatrixXcd d = Eigen::MatrixXcd(dde.sparse_characteristic_matrix(z));
            const Eigen::MatrixXcd dp = Eigen::MatrixXcd(dde.sparse_characteristic_derivative(z));
            const double s = Eigen::JacobiSVD<Eigen::MatrixXcd>(d).singularValues().minCoeff();
            const double l1 = Eigen::JacobiSVD<Eigen::MatrixXcd>(dp).singularValues().maxCoeff();
            const double a = Eigen::JacobiSVD<Eigen::MatrixXcd>(Eigen::MatrixXcd(d.partialPivLu().solve(dp))).singularValues().maxCoeff();
            double lip = 1.0, m2 = 0.0;
            for (const auto& t : dde.bounds().terms) {
                lip += t.delay * t.norm * std::exp(-x0 * t.delay);
                m2 += t.delay * t.delay * t.norm * std::exp(-x0 * t.delay);
            }
            // bound 2: the root of r a + sum_k e^{-Re z tau_k} (e^{r tau_k} - 1 - r tau_k) ||A_k|| / s = 1
            auto second = [&](double aa, double ss) {
                double lo2 = 0.0, hi2 = 1.0 / aa;
                for (int it = 0; it < 200; ++it) {
                    const double mid = 0.5 * (lo2 + hi2);
                    double f = mid * aa;
                    for (const auto& t : dde.bounds().terms)
                        f += std::exp(-z.real() * t.delay) * (std::expm1(mid * t.delay) - mid * t.delay) * t.norm / ss;
                    (f <= 1.0 ? lo2 : hi2) = mid;
                }
                return lo2;
            };
            const double first_hi = std::max(s / lip, 2.0 * s / (l1 + std::sqrt(l1 * l1 + 2.0 * m2 * s)));
            const double second_lo = second(1.25 * a, s / 1.25);
            const double lo = std::max(s / (1.25 * lip), second_lo);
            const double hi = std::max(first_hi, second(a, s));
            second_larger += second_lo > first_hi;
            CAPTURE(seed);
            CAPTURE(z);
            CHECK(rad <= nearest);
            CHECK(rad >= lo * (1.0 - test::tol::radius_formula_rel));
            CHECK(rad <= hi * (1.0 + test::tol::radius_formula_rel));
        }
    }
    MESSAGE("bound 2 the larger at " << second_larger << " of 75 points");
    CHECK(second_larger >= 10);
}

TEST_CASE("shift_invert.arnoldi and compact_max_steps are validated") {
    RootOptions o;
    o.shift_invert.arnoldi = "lanczos";
    std::string why;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("shift_invert.arnoldi") != std::string::npos);
    o.shift_invert.arnoldi = "compact";
    o.shift_invert.compact_max_steps = 1;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("compact_max_steps") != std::string::npos);
    o.shift_invert.compact_max_steps = 200;
    o.shift_invert.compact_restarts = -1;
    CHECK_FALSE(o.is_valid(&why));
    CHECK(why.find("compact_restarts") != std::string::npos);
}

TEST_SUITE_END();

TEST_SUITE_BEGIN("slow");

TEST_CASE("a stiff system of 10^4 states (||A0|| = 2e7): the 6 rightmost roots, each once, in a strip of height e^{-2 Re}") {
    // u_t = 0.05 u_xx + 0.5 u - u(t - 2) on (0, 1), 10^4 points (bench/run_sparse_bench.sh's
    // rd10000): the lattice coefficient 0.05 (n + 1)^2 = 5e6. The disc bound R(a) = ||A0|| + ...
    // made the covering rectangle 2e7 high (not done in 100 s); A0 is symmetric, so no root right
    // of a has |Im| > e^{-2a} (RootBounds::height). The pair's two members from one complex shift
    // came out 2.9e-10 apart (stiff: Ritz values are accurate to about 1e-10 |lambda - sigma|)
    // and were listed as two pairs, dropping the third
    const int n = 10000;
    const double dx = 0.05 * (n + 1.0) * (n + 1.0), a = 0.5, b = 1.0, tau = 2.0;
    const LinearDDE dde = reaction_diffusion(n, 1, dx, 0.0, a, b, tau);
    CHECK(dde.bounds().height(0.0) == doctest::Approx(b).epsilon(1e-14));
    RootOptions o;
    o.method = "shift_invert";
    o.count = 6;
    const RootResult r = rightmost_roots(dde, o);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(r.roots.size() == 6);
    check_against_closed_form(r, closed_form_roots(n, 1, dx, 0.0, a, b, tau), test::tol::stiff_root_abs);
}

TEST_SUITE_END();
