#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "fleet_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
using test::ovrv;
}  // namespace

TEST_CASE("quasi-polynomials equal det Delta of the mode DDEs") {
    const Linearisation lin = ovrv(0.3, 0.2, 1.1, 0.6);
    const cplx zeta = std::polar(1.0, -0.7);
    const QuasiPolynomial f = ring_mode_characteristic(lin, zeta);
    const LinearDDE dde = ring_mode_dde(lin, zeta);
    for (cplx z : {cplx(0.3, 0.1), cplx(-1.0, 2.0), cplx(0.0, 0.5)}) {
        CHECK(std::abs(f(z) - dde.characteristic_matrix(z).determinant()) < 1e-13);
        cplx v, d;
        f.evaluate(z, v, d);
        const double h = 1e-6;
        CHECK(std::abs(d - (f(z + h) - f(z - h)) / (2 * h)) < 1e-7);
    }
    const QuasiPolynomial p = plant_characteristic(lin);
    for (cplx z : {cplx(0.3, 0.1), cplx(-1.0, 2.0)}) CHECK(std::abs(p(z) - TransferFunction(lin).denominator(z)) < 1e-13);
}

TEST_CASE("argument-principle counts equal the number of collocation roots right of the line" * doctest::test_suite("slow")) {
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int checked = 0;
    for (int i = 0; i < 150; ++i) {
        const Linearisation lin = ovrv(0.01 + u(rng), 0.01 + u(rng), 0.2 + 2.8 * u(rng), 0.05 + 0.95 * u(rng));
        const double theta = 2 * M_PI * u(rng);
        const QuasiPolynomial f = ring_mode_characteristic(lin, std::polar(1.0, -theta));
        RootOptions o;
        o.count = 8;
        const RootResult r = rightmost_roots(ring_mode_dde(lin, std::polar(1.0, -theta)), o);
        for (double sigma : {-0.5, -0.1, 0.0, 0.05}) {
            int expected = 0;
            for (const auto& x : r.roots) expected += x.value.real() > sigma;
            if (expected >= static_cast<int>(r.roots.size())) continue;  // count not certain from the list
            CHECK(f.zeros_right_of(sigma) == expected);
            ++checked;
        }
        // just right of the rightmost root there is none; just left of it, at least one
        const double a = r.roots.front().value.real();
        CHECK(f.zeros_right_of(a + 1e-9 * std::max(1.0, std::abs(a))) == 0);
        CHECK(f.zeros_right_of(a - 1e-6) >= 1);
    }
    CHECK(checked > 400);
}

TEST_CASE("real quasi-polynomials (counted along the upper half line) equal the collocation roots right of the line" * doctest::test_suite("slow")) {
    // the plant D and ring mode N/2 (zeta = -1) have real coefficients: zeros_right_of samples
    // only Im >= 0 and doubles the change of arg (conjugate symmetry); the collocation roots are
    // the independent count
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int checked = 0, converged = 0;
    for (int i = 0; i < 30; ++i) {
        const Linearisation lin = ovrv(0.01 + u(rng), 0.01 + u(rng), 0.2 + 2.8 * u(rng), 0.05 + 0.95 * u(rng));
        const bool plant = i % 2 == 0;
        const QuasiPolynomial f = plant ? plant_characteristic(lin) : ring_mode_characteristic(lin, cplx(-1.0, 0.0));
        REQUIRE(f.is_real());
        RootOptions o;
        o.count = 8;
        const RootResult r = rightmost_roots(plant ? plant_dde(lin) : ring_mode_dde(lin, cplx(-1.0, 0.0)), o);
        if (r.status != Status::Converged || r.roots.empty()) continue;  // the list does not decide the counts
        ++converged;
        for (double sigma : {-0.7, -0.2, 0.0, 0.1}) {
            int expected = 0;
            for (const auto& x : r.roots) expected += x.value.real() > sigma;
            if (expected >= static_cast<int>(r.roots.size())) continue;  // count not certain from the list
            CAPTURE(i);
            CAPTURE(sigma);
            CHECK(f.zeros_right_of(sigma) == expected);
            ++checked;
        }
        const double a = r.roots.front().value.real();
        CHECK(f.zeros_right_of(a + 1e-9 * std::max(1.0, std::abs(a))) == 0);
        CHECK(f.zeros_right_of(a - 1e-6) >= 1);
    }
    CHECK(converged >= 20);
    CHECK(checked > 60);
}

TEST_SUITE_END();
