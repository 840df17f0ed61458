// Rings of one-leader cars through D = prod P_i - prod Q_i: the determinant against a dense
// determinant of the 2N system, the argument-principle counts against dense roots, and the
// product path against the sparse path, the Fourier modes and the dense path.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "ddemap/study/penetration.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/traffic/ring_determinant.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"
#include "numeric_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::nearest;
namespace tol = ddemap::test::tol;
using ddemap::test::linearised;
using ddemap::test::ovrv;
using ddemap::test::random_car;

namespace {

/// N random OVRV cars (some repeated, so that grouping into types is exercised), linearised at 20 m/s.
std::vector<Linearisation> random_ring(std::mt19937& rng, int n) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Linearisation> out;
    for (int i = 0; i < n; ++i) {
        if (i > 0 && u(rng) < 0.3) {
            out.push_back(out[static_cast<std::size_t>(u(rng) * i)]);
            continue;
        }
        out.push_back(linearised(random_car(rng, false)));
    }
    return out;
}

Eigen::MatrixXcd dense_delta(const LinearDDE& dde, cplx z) { return Eigen::MatrixXcd(dde.characteristic_matrix(z)); }

}  // namespace

TEST_CASE("ring determinant: D = prod P_i - prod Q_i is det Delta of the 2N system, and D'/D = trace(Delta^-1 Delta')") {
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> re(-1.5, 1.0), im(-3.0, 3.0);
    int left = 0, right = 0;
    for (int n : {2, 3, 5, 9}) {
        const std::vector<Linearisation> cars = random_ring(rng, n);
        const RingDeterminant det(cars);
        const LinearDDE dde = mixed_ring_dde(cars);
        for (int k = 0; k < 40; ++k) {
            const cplx z(re(rng), im(rng));
            CAPTURE(n);
            CAPTURE(z);
            const Eigen::MatrixXcd d = dense_delta(dde, z);
            Eigen::PartialPivLU<Eigen::MatrixXcd> lu(d);
            const cplx dense_det = lu.determinant();
            // both regimes of the factored form are used (|e^Phi| below and above 1)
            (det.phi(z).real() <= 0.0 ? left : right) += 1;
            CHECK(std::abs(std::exp(det.log_value(z)) / dense_det - 1.0) < 1e-11);
            const Eigen::MatrixXcd dd = Eigen::MatrixXcd(dde.characteristic_derivative(z));
            const cplx trace = lu.solve(dd).trace();
            CHECK(std::abs(det.log_derivative(z) - trace) < 1e-10 * std::max(1.0, std::abs(trace)));
        }
    }
    CHECK(left >= 10);
    CHECK(right >= 5);
}

TEST_CASE("ring determinant: argument-principle counts equal the dense roots inside random rectangles") {
    std::mt19937 rng(5);
    int nonzero = 0, rectangles = 0;
    for (int n : {3, 6}) {
        const std::vector<Linearisation> cars = random_ring(rng, n);
        const RingDeterminant det(cars);
        // every root with Re >= floor from the dense collocation path (an independent algorithm)
        RootOptions ro;
        ro.count = 14;
        const RootResult dense = rightmost_roots(mixed_ring_dde(cars).to_dense(), ro);
        REQUIRE(dense.status == Status::Converged);
        const double floor = dense.strip_floor;
        std::uniform_real_distribution<double> x(floor, 0.5), y(-2.0, 2.0);
        for (int k = 0; k < 40; ++k) {
            double x0 = x(rng), x1 = x(rng), y0 = y(rng), y1 = y(rng);
            if (x0 > x1) std::swap(x0, x1);
            if (y0 > y1) std::swap(y0, y1);
            int expected = 0;
            double closest = 1e300;
            for (const auto& r : dense.roots) {
                const cplx z = r.value;
                if (z.real() > x0 && z.real() < x1 && z.imag() > y0 && z.imag() < y1) ++expected;
                closest = std::min({closest, std::abs(z.real() - x0), std::abs(z.real() - x1), std::abs(z.imag() - y0),
                                    std::abs(z.imag() - y1)});
            }
            if (closest < 1e-6) continue;  // a root on the boundary: the count is not defined
            const auto c = det.count(x0, x1, y0, y1);
            CAPTURE(n);
            CAPTURE(x0);
            CAPTURE(x1);
            CAPTURE(y0);
            CAPTURE(y1);
            REQUIRE(c.ok);
            CHECK(c.zeros == expected);
            nonzero += expected > 0 ? 1 : 0;
            ++rectangles;
            if (y1 > 0.0) {  // the symmetric rectangle of the same width
                int sym = 0;
                for (const auto& r : dense.roots)
                    if (r.value.real() > x0 && r.value.real() < x1 && std::abs(r.value.imag()) < y1) ++sym;
                const auto s = det.count_symmetric(x0, x1, y1);
                REQUIRE(s.ok);
                CHECK(s.zeros == sym);
            }
        }
    }
    CHECK(rectangles >= 60);
    CHECK(nonzero >= 10);
}

TEST_CASE("product path: the same rightmost roots as the sparse path for random one-leader fleets (N up to 60)") {
    std::mt19937 rng(20261121);
    for (int n : {4, 7, 12, 30, 60}) {
        const std::vector<Linearisation> cars = random_ring(rng, n);
        RootOptions po;
        po.method = "contour";
        po.count = 9;
        const RootResult p = rightmost_roots(ring_root_problem(cars), po);
        RootOptions so;
        so.method = "shift_invert";
        so.count = 9;
        const RootResult s = rightmost_roots(mixed_ring_dde(cars), so);
        CAPTURE(n);
        REQUIRE(p.status == Status::Converged);
        REQUIRE(s.status == Status::Converged);
        REQUIRE(p.roots.size() == s.roots.size());
        for (std::size_t i = 0; i < p.roots.size(); ++i) {
            CAPTURE(p.roots[i].value);
            CHECK(nearest(s.roots, p.roots[i].value) < tol::same_root);
            CHECK(p.roots[i].residual < 1e-12);
        }
        // and the other way: every sparse root right of the product path's certified floor is listed
        for (const auto& r : s.roots)
            if (r.value.real() >= p.strip_floor) CHECK(nearest(p.roots, r.value) < tol::same_root);
    }
}

TEST_CASE("product path: a homogeneous ring equals the Fourier-mode roots (N up to 2000), and the dense path for N = 3") {
    const Linearisation lin = make_model("ovrv", fleet_from_pattern("E_min", 1)[0].parameters)->linearise();
    for (int n : {3, 40, 2000}) {
        CAPTURE(n);
        RootOptions po;
        po.method = "contour";
        po.count = 8;
        const RootResult p = rightmost_roots(ring_root_problem(std::vector<Linearisation>(n, lin)), po);
        REQUIRE(p.status == Status::Converged);
        RingOptions ro;
        ro.roots.count = 8;
        const RingResult modes = analyse_ring(lin, n, ro);
        REQUIRE(modes.status == Status::Converged);
        // the mode solver leaves the trivial root out, the product path lists it: every mode root
        // right of the product path's certified floor is a product root
        int matched = 0;
        for (const auto& r : modes.roots) {
            if (r.root.value.real() < p.strip_floor) continue;
            CAPTURE(r.root.value);
            CHECK(nearest(p.roots, r.root.value) < tol::same_root);
            ++matched;
        }
        CHECK(matched >= 6);
        if (n == 3) {
            RootOptions dro;
            dro.count = 8;
            const RootResult d = rightmost_roots(mixed_ring_dde(std::vector<Linearisation>(n, lin)).to_dense(), dro);
            for (const auto& r : p.roots) CHECK(nearest(d.roots, r.value) < tol::same_root);
        }
    }
}

TEST_CASE("product path: long mixed rings stay certified, and a multi-leader car is refused") {
    const Fleet fleet = fleet_from_pattern("A_min,C_max,E_min,G_max", 20000);
    MixedRingOptions o;
    o.speed = 20.0;
    o.roots.count = 10;
    const MixedRingResult r = analyse_mixed_ring(fleet, o);  // automatic: the product path
    REQUIRE(r.roots.status == Status::Converged);
    CHECK(r.roots.roots.size() >= 10);
    CHECK(r.roots.max_residual < 1e-11);
    CHECK(r.product_residual < 1e-8);  // sum of 20000 logarithms: ~N eps |Phi'| lost
    // the same fleet as four groups of 5000 identical cars: the order does not matter
    Fleet grouped;
    for (const char* name : {"A_min", "C_max", "E_min", "G_max"})
        for (int i = 0; i < 5000; ++i) grouped.push_back(fleet_from_pattern(name, 1)[0]);
    const MixedRingResult g = analyse_mixed_ring(grouped, o);
    REQUIRE(g.roots.status == Status::Converged);
    REQUIRE(g.roots.roots.size() == r.roots.roots.size());
    for (std::size_t i = 0; i < g.roots.roots.size(); ++i) CHECK(std::abs(g.roots.roots[i].value - r.roots.roots[i].value) < 1e-12);

    Fleet ccc = fleet_from_pattern("A_min", 6);
    ccc[2] = parse_fleet_car("ccc:k1=0.1,k2=0.3,k3=0.2,th=1.2,tau=0.3,tau2=0.2");
    o.roots.method = "contour";
    // the scalar product form refuses the CCC car; the ring takes the transfer-matrix determinant
    CHECK_THROWS_AS(RingDeterminant(linearise_fleet(ccc, 20.0)), std::invalid_argument);
    const MixedRingResult c = analyse_mixed_ring(ccc, o);
    CHECK(c.roots.method_used == "contour");
    CHECK(c.roots.status == Status::Converged);
    CHECK(std::isnan(c.product_residual));  // no scalar product check with two leaders
}

namespace {

/// Change of arg D along a -> b by n uniform steps of the principal log (a reference that
/// shares nothing with the adaptive tracking but the evaluation of D).
double brute_arg(const RingDeterminant& d, cplx a, cplx b, int n) {
    double total = 0.0;
    cplx prev = d.log_value(a);
    for (int i = 1; i <= n; ++i) {
        const cplx v = d.log_value(a + (b - a) * (static_cast<double>(i) / n));
        total += std::remainder(v.imag() - prev.imag(), 2.0 * M_PI);
        prev = v;
    }
    return total;
}

}  // namespace

TEST_CASE("argument principle: counts far into the left half-plane equal a uniform fine sampling of arg D" * doctest::test_suite("slow")) {
    // a 2-car ring with tau = 1: arg Gamma turns about once per 2 pi along vertical edges, so a
    // first step of an eighth of a long edge can skip a whole turn unless the step is capped
    // by the local rates (the first cell is such a case: it has no roots)
    const RingDeterminant det({ovrv(0.4, 0.5, 1.0, 1.0), ovrv(0.5, 0.3, 1.2, 1.0)});
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int nonzero = 0;
    for (int k = 0; k < 16; ++k) {
        double x0 = -8.44701, w = 1.93213, y0 = 21.2957, h = 47.9416;
        if (k > 0) {
            x0 = -12.0 + 8.0 * u(rng);
            w = 0.2 + 3.0 * u(rng);
            y0 = 60.0 * u(rng);
            h = 1.0 + 60.0 * u(rng);
        }
        const cplx a(x0, y0), b(x0 + w, y0), c(x0 + w, y0 + h), d(x0, y0 + h);
        const int nw = 2000 + static_cast<int>(2000 * w), nh = 2000 + static_cast<int>(2000 * h);
        const double total = brute_arg(det, a, b, nw) + brute_arg(det, b, c, nh) + brute_arg(det, c, d, nw) + brute_arg(det, d, a, nh);
        const long reference = std::lround(total / (2.0 * M_PI));
        CAPTURE(k);
        CAPTURE(x0);
        CAPTURE(y0);
        const auto count = det.count(x0, x0 + w, y0, y0 + h);
        REQUIRE(count.ok);
        CHECK(count.zeros == reference);
        nonzero += reference > 0 ? 1 : 0;
    }
    CHECK(nonzero >= 4);
}

TEST_CASE("product path: a delay-free ring (2N roots in all) and a double root at 0 (th = 0)") {
    // tau = 0: D is a polynomial of degree 2N; the product path lists the whole spectrum,
    // which must equal the eigenvalues of the ODE matrix
    std::vector<Linearisation> cars{ovrv(0.2, 0.5, 1.2, 0.0), ovrv(0.2, 0.5, 1.2, 0.0), ovrv(0.3, 0.4, 1.0, 0.0)};
    RootOptions po;
    po.method = "contour";
    po.count = 20;  // more than the 6 roots there are
    const RootResult p = rightmost_roots(ring_root_problem(cars), po);
    REQUIRE(p.status == Status::Converged);
    const LinearDDE dde = mixed_ring_dde(cars);
    REQUIRE(dde.is_ode());
    Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(dde.sparse_a0()), false);
    REQUIRE(p.roots.size() == 6);
    for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) CHECK(nearest(p.roots, es.eigenvalues()(i)) < 1e-9);
    // the dense path's ODE branch lists the same six, lambda = 0 included (a real eigenvalue
    // from a complex eigen-solver came with Im = -1e-18 and was skipped as a conjugate)
    RootOptions dro;
    dro.count = 6;
    const RootResult dd = rightmost_roots(dde.to_dense(), dro);
    REQUIRE(dd.roots.size() == 6);
    for (const auto& r : dd.roots) CHECK(nearest(p.roots, r.value) < 1e-9);

    // th = 0 for every car: lambda = 0 is a double root (the ring's and the equilibrium's);
    // the cluster is reported as such and the other roots are still found
    std::vector<Linearisation> flat(4, ovrv(0.2, 0.5, 0.0, 0.5));
    po.count = 8;
    const RootResult f = rightmost_roots(ring_root_problem(flat), po);
    CHECK(f.status == Status::MaxDegreeReached);
    CHECK(f.message.find("cluster") != std::string::npos);
    RootOptions ro;
    ro.count = 8;
    const RootResult d = rightmost_roots(mixed_ring_dde(flat).to_dense(), ro);
    int matched = 0;
    for (const auto& r : d.roots) {
        if (std::abs(r.value) < 1e-6 || r.value.real() < f.strip_floor) continue;
        CHECK(nearest(f.roots, r.value) < tol::same_root);
        ++matched;
    }
    CHECK(matched >= 4);
}

TEST_SUITE_END();
