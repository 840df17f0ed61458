// Rings with connected cruise control (cars that react to the car two ahead) through
// D = prod P_i det(I - T_{N-1} ... T_0): the determinant against a dense determinant of the 2N
// system (random cars, random order, random complex lambda), the overflow-free evaluation of
// long rings against the closed form of a homogeneous ring, argument-principle counts against
// dense roots, and the rightmost roots and their certificate against the sparse path.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Dense>

#include "ddemap/analysis/stability/mixed_ring.hpp"
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
using ddemap::test::random_car;

namespace {

/// N cars in random order: a fraction `ccc` of connected cruise control cars; `kinds` random
/// cars of each law are drawn first and the ring repeats them (so types are grouped).
std::vector<Linearisation> random_ccc_ring(std::mt19937& rng, int n, double ccc, int kinds = 2) {
    std::vector<Linearisation> c, o;
    for (int k = 0; k < kinds; ++k) {
        c.push_back(linearised(random_car(rng, true)));
        o.push_back(linearised(random_car(rng, false)));
    }
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_int_distribution<int> pick(0, kinds - 1);
    std::vector<Linearisation> out;
    for (int i = 0; i < n; ++i) out.push_back(u(rng) < ccc ? c[pick(rng)] : o[pick(rng)]);
    if (std::none_of(out.begin(), out.end(), [](const Linearisation& l) { return l.leaders() == 2; })) out[0] = c[0];
    return out;
}

}  // namespace

TEST_CASE("transfer ring determinant: prod P_i det(I - prod T_i) is det Delta of the 2N system, and D'/D its trace formula") {
    std::mt19937 rng(1313);
    std::uniform_real_distribution<double> re(-1.5, 1.0), im(-3.0, 3.0);
    int reordered_differs = 0, checked = 0;
    for (int n : {2, 3, 4, 7, 12}) {
        for (double share : {0.5, 1.0}) {
            std::vector<Linearisation> cars = random_ccc_ring(rng, n, share, 3);
            std::vector<Linearisation> shuffled = cars;
            std::shuffle(shuffled.begin(), shuffled.end(), rng);
            const TransferRingDeterminant det(cars), det2(shuffled);
            const LinearDDE dde = mixed_ring_dde(cars), dde2 = mixed_ring_dde(shuffled);
            for (int k = 0; k < 20; ++k) {
                const cplx z(re(rng), im(rng));
                CAPTURE(n);
                CAPTURE(share);
                CAPTURE(z);
                const Eigen::MatrixXcd d = Eigen::MatrixXcd(dde.characteristic_matrix(z));
                Eigen::PartialPivLU<Eigen::MatrixXcd> lu(d);
                const cplx dense_det = lu.determinant();
                CHECK(std::abs(std::exp(det.log_value(z)) / dense_det - 1.0) < 1e-11);
                const cplx trace = lu.solve(Eigen::MatrixXcd(dde.characteristic_derivative(z))).trace();
                CHECK(std::abs(det.log_derivative(z) - trace) < 1e-10 * std::max(1.0, std::abs(trace)));
                // the other order: its own dense determinant, and (for N >= 4) a different value
                const cplx dense2 = Eigen::MatrixXcd(dde2.characteristic_matrix(z)).determinant();
                CHECK(std::abs(std::exp(det2.log_value(z)) / dense2 - 1.0) < 1e-11);
                if (std::abs(dense2 / dense_det - 1.0) > 1e-6) ++reordered_differs;
                ++checked;
            }
        }
    }
    CHECK(checked == 200);
    CHECK(reordered_differs >= 60);
    // lambda = 0 is a root of every ring: M(0) has the eigenvalue 1
    const TransferRingDeterminant det(random_ccc_ring(rng, 9, 0.5));
    CHECK(std::exp(det.log_value(cplx(0.0, 0.0))) == 0.0);
}

TEST_CASE("transfer ring determinant: long rings without overflow, against the closed form of a homogeneous ring") {
    // N identical cars: det(I - T^N) = (1 - mu_1^N)(1 - mu_2^N) with mu the eigenvalues of T
    std::mt19937 rng(77);
    const Linearisation car = linearised(random_car(rng, true));
    std::uniform_real_distribution<double> re(-1.0, 0.5), im(-2.0, 2.0);
    int huge = 0;
    for (int n : {5, 1000, 100000}) {
        const TransferRingDeterminant det(std::vector<Linearisation>(static_cast<std::size_t>(n), car));
        CHECK(det.products() <= 60);  // repeated squaring, not N products
        for (int k = 0; k < 10; ++k) {
            const cplx z(re(rng), im(rng));
            const cplx p = z * z - z * car.own(z) + car.gap(z), q = car.gap(z) + z * car.lead(z), r = z * car.further[0](z);
            // T = [[q/p, r/p], [1, 0]]: mu^2 - (q/p) mu - r/p = 0
            const cplx a = q / p, b = r / p, root = std::sqrt(a * a + 4.0 * b);
            const cplx mu1 = 0.5 * (a + root), mu2 = 0.5 * (a - root);
            auto log1m = [n](cplx mu) {  // log(1 - mu^N) without overflow
                const cplx l = static_cast<double>(n) * std::log(mu);
                return l.real() <= 0.0 ? std::log(1.0 - std::exp(l)) : l + std::log(std::exp(-l) - 1.0);
            };
            const cplx expected = log1m(mu1) + log1m(mu2);
            const cplx got = det.log_closure(z);
            CAPTURE(n);
            CAPTURE(z);
            CHECK(std::abs(got.real() - expected.real()) < 1e-9 * std::max(1.0, std::abs(expected.real())));
            CHECK(std::abs(std::remainder(got.imag() - expected.imag(), 2.0 * M_PI)) < 1e-6);
            // mu^N beyond the range of a double
            if (static_cast<double>(n) * std::max(std::abs(std::log(std::abs(mu1))), std::abs(std::log(std::abs(mu2)))) > 800.0) ++huge;
        }
    }
    CHECK(huge >= 5);
}

TEST_CASE("transfer ring determinant: argument-principle counts equal the dense roots inside random rectangles") {
    std::mt19937 rng(2026);
    int nonzero = 0, rectangles = 0;
    for (int n : {3, 5}) {
        const std::vector<Linearisation> cars = random_ccc_ring(rng, n, 0.6, 3);
        const TransferRingDeterminant det(cars);
        RootOptions ro;
        ro.count = 14;
        const RootResult dense = rightmost_roots(mixed_ring_dde(cars).to_dense(), ro);
        REQUIRE(dense.status == Status::Converged);
        std::uniform_real_distribution<double> x(dense.strip_floor, 0.5), y(-2.0, 2.0);
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
        }
    }
    CHECK(rectangles >= 60);
    CHECK(nonzero >= 10);
}

namespace {

/// The transfer-matrix path against the sparse path on one ring: the same rightmost roots
/// (both ways) and the same number of roots right of the certified floor.
void check_against_sparse(const std::vector<Linearisation>& cars, int count) {
    RootOptions po;
    po.method = "contour";
    po.count = count;
    const RootProblem problem = ring_root_problem(cars);
    REQUIRE(dynamic_cast<const TransferRingDeterminant*>(problem.characteristic.get()) != nullptr);
    const RootResult p = rightmost_roots(problem, po);
    RootOptions so;
    so.method = "shift_invert";
    so.count = count + 6;  // reaches left of the contour path's floor
    const RootResult s = rightmost_roots(problem.dde, so);
    CAPTURE(p.message);
    CAPTURE(s.message);
    REQUIRE(p.status == Status::Converged);
    REQUIRE(s.status == Status::Converged);
    REQUIRE(p.roots.size() >= static_cast<std::size_t>(count));
    for (const auto& r : p.roots) {
        CAPTURE(r.value);
        CHECK(nearest(s.roots, r.value) < tol::same_root * std::max(1.0, std::abs(r.value)));
        CHECK(r.residual < 1e-12);
    }
    // the certificate: the contour count right of the floor is the sparse path's number there
    REQUIRE(s.strip_floor < p.strip_floor);
    int right = 0;
    for (const auto& r : s.roots)
        if (r.value.real() >= p.strip_floor) {
            ++right;
            CHECK(nearest(p.roots, r.value) < tol::same_root * std::max(1.0, std::abs(r.value)));
        }
    CHECK(right == static_cast<int>(p.roots.size()));
    CHECK(p.eigenvalues_found >= right);
}

}  // namespace

TEST_CASE("transfer ring path: the same rightmost roots and certified count as the sparse path (N = 10, 50, random orders)") {
    std::mt19937 rng(4242);
    for (int n : {6, 10, 50}) {
        for (double share : {0.3, 0.7}) {
            CAPTURE(n);
            CAPTURE(share);
            check_against_sparse(random_ccc_ring(rng, n, share), 10);
        }
    }
}

TEST_CASE("transfer ring path: a string-stable CCC ring, rightmost roots next to the imaginary axis, against the sparse path") {
    // two kinds of CCC car in a random order: every non-trivial root has Re < 0, the first pair
    // (the lowest mode) at Re ~ -0.024, the trivial root 0 listed as well
    const FleetCar a{"a", "ccc", {{"k1", 0.2}, {"k2", 0.6}, {"k3", 0.4}, {"th", 2.0}, {"tau", 0.2}, {"tau2", 0.1}}};
    const FleetCar b{"b", "ccc", {{"k1", 0.3}, {"k2", 0.5}, {"k3", 0.3}, {"th", 1.8}, {"tau", 0.3}, {"tau2", 0.2}}};
    const Fleet fleet = mixed_fleet(a, b, 40, 20, 1, 7);
    const std::vector<Linearisation> cars = linearise_fleet(fleet, 20.0);
    check_against_sparse(cars, 10);
    RootOptions po;
    po.count = 10;
    const RootResult p = rightmost_roots(ring_root_problem(cars), po);
    REQUIRE(p.method_used == "contour");
    int near_axis = 0;
    for (const auto& r : p.roots) {
        CHECK(r.value.real() <= 1e-12);
        if (r.value.real() > -3e-2 && std::abs(r.value) > 1e-8) ++near_axis;
    }
    CHECK(near_axis == 2);
    CHECK(std::abs(p.roots.front().value) < 1e-12);
}

TEST_CASE("transfer ring path: N = 200 against the sparse path" * doctest::test_suite("slow")) {
    std::mt19937 rng(200);
    check_against_sparse(random_ccc_ring(rng, 200, 0.5), 10);
}

TEST_CASE("transfer ring path: a homogeneous CCC ring equals the Fourier-mode roots (N up to 2000)") {
    // identical cars: the roots of mode m solve P zeta^2 - Q zeta - R = 0, zeta = e^{2 pi i m / N}
    // (analyse_ring, one mode at a time); long rings put N roots next to the floor's edge
    const Linearisation lin = linearised({"ccc", "ccc", {{"k1", 0.1}, {"k2", 0.3}, {"k3", 0.2}, {"th", 1.2}, {"tau", 0.4}, {"tau2", 0.1}}});
    for (int n : {3, 40, 2000}) {
        CAPTURE(n);
        RootOptions po;
        po.method = "contour";
        po.count = 8;
        const RootResult p = rightmost_roots(ring_root_problem(std::vector<Linearisation>(static_cast<std::size_t>(n), lin)), po);
        CAPTURE(p.message);
        REQUIRE(p.status == Status::Converged);
        RingOptions ro;
        ro.roots.count = 8;
        const RingResult modes = analyse_ring(lin, n, ro);
        REQUIRE(modes.status == Status::Converged);
        // every mode root right of the certified floor is listed (the trivial root only by the product path)
        int matched = 0;
        for (const auto& r : modes.roots) {
            if (r.root.value.real() < p.strip_floor) continue;
            CAPTURE(r.root.value);
            CHECK(nearest(p.roots, r.root.value) < tol::same_root);
            ++matched;
        }
        CHECK(matched >= 6);
        for (const auto& r : p.roots) CHECK(r.residual < 1e-12);
    }
}

namespace {

/// Change of arg D along a -> b by uniform steps of the principal log, the number of steps
/// doubled until no step turns by more than 0.5 rad (a reference that shares nothing with the
/// adaptive tracking but the evaluation of D).
double brute_arg(const TransferRingDeterminant& d, cplx a, cplx b) {
    for (int n = 4096;; n *= 2) {
        double total = 0.0, worst = 0.0;
        cplx prev = d.log_value(a);
        for (int i = 1; i <= n; ++i) {
            const cplx v = d.log_value(a + (b - a) * (static_cast<double>(i) / n));
            const double step = std::remainder(v.imag() - prev.imag(), 2.0 * M_PI);
            worst = std::max(worst, std::abs(step));
            total += step;
            prev = v;
        }
        if (worst <= 0.5 || n >= (1 << 22)) return total;
    }
}

}  // namespace

TEST_CASE("transfer ring determinant: counts on a long ring next to its band of roots equal a fine uniform sampling of arg D" * doctest::test_suite("slow")) {
    // 300 cars in a random order: the unstable band holds many roots close together; rectangles
    // whose left edge runs just below the top of the band, where a step could jump over it
    std::mt19937 rng(300);
    const std::vector<Linearisation> cars = linearise_fleet(
        mixed_fleet(parse_fleet_car("ccc:k1=0.1,k2=0.3,k3=0.2,th=1.2,tau=0.4,tau2=0.1"), fleet_from_pattern("A_min", 1)[0], 300, 150, 1, 3),
        20.0);
    const TransferRingDeterminant det(cars);
    // (its roots with Re > 0.02 lie at Im 0.07 to 0.22, about 0.007 apart)
    std::uniform_real_distribution<double> x(0.02, 0.034), y(0.0, 0.15), h(0.02, 0.12);
    int nonzero = 0;
    for (int k = 0; k < 8; ++k) {
        double x0 = x(rng), x1 = 0.06, y0 = y(rng), y1 = y0 + h(rng);
        if (k == 0) {  // a long strip as the floor search uses: long edges, large first steps
            x0 = 0.0328;
            x1 = 1.4;
            y0 = -2.85;
            y1 = 2.85;
        }
        const cplx a(x0, y0), b(x1, y0), c(x1, y1), d(x0, y1);
        const double total = brute_arg(det, a, b) + brute_arg(det, b, c) + brute_arg(det, c, d) + brute_arg(det, d, a);
        const long reference = std::lround(total / (2.0 * M_PI));
        CAPTURE(x0);
        CAPTURE(y0);
        CAPTURE(y1);
        CHECK(std::abs(total - 2.0 * M_PI * static_cast<double>(reference)) < 1e-6);
        const auto count = det.count(x0, x1, y0, y1);
        REQUIRE(count.ok);
        CHECK(count.zeros == reference);
        nonzero += reference > 0 ? 1 : 0;
    }
    CHECK(nonzero >= 5);
}

TEST_CASE("transfer ring determinant: the floor search's strip on a 2,000-car ring counts what a fine uniform sampling counts" *
          doctest::test_suite("slow")) {
    // the benchmark's ring: 92 roots in the strip, all within 0.0015 of its left edge; a step
    // control that looked only at the rates of arg D at its end points jumped over them (count 0)
    const std::vector<Linearisation> cars = linearise_fleet(
        mixed_fleet(parse_fleet_car("ccc:k1=0.1,k2=0.3,k3=0.2,th=1.2,tau=0.4,tau2=0.1"), fleet_from_pattern("A_min", 1)[0], 2000, 1000, 1, 1),
        20.0);
    const TransferRingDeterminant det(cars);
    const double x0 = 0.0328, x1 = 1.38, y = 2.85;
    const cplx a(x0, -y), b(x1, -y), c(x1, y), d(x0, y);
    const double total = brute_arg(det, a, b) + brute_arg(det, b, c) + brute_arg(det, c, d) + brute_arg(det, d, a);
    const long reference = std::lround(total / (2.0 * M_PI));
    CHECK(std::abs(total - 2.0 * M_PI * static_cast<double>(reference)) < 1e-6);
    CHECK(reference > 20);
    const auto count = det.count(x0, x1, -y, y);
    REQUIRE(count.ok);
    CHECK(count.zeros == reference);
    const auto sym = det.count_symmetric(x0, x1, y);
    REQUIRE(sym.ok);
    CHECK(sym.zeros == reference);
}
