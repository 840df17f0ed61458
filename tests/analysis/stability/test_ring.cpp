#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "tolerances.hpp"
#include "fleet_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
using test::ovrv;
}  // namespace

TEST_CASE("the full 2N-dimensional ring has the roots of the Fourier modes plus the trivial zero") {
    const double params[][4] = {{0.2, 0.2, 1.5, 0.1}, {0.052, 0.338, 0.819, 0.948}, {0.6, 0.1, 0.8, 0.4}};
    for (const auto& p : params) {
        for (int n : {2, 3, 4, 5}) {
            CAPTURE(n);
            CAPTURE(p[0]);
            const Linearisation lin = ovrv(p[0], p[1], p[2], p[3]);
            RingOptions ro;
            ro.roots.count = 8;
            const RingResult modes = analyse_ring(lin, n, ro);
            RootOptions fo;
            fo.count = 9;  // one more: the trivial zero is a root of the full system
            const RootResult full = rightmost_roots(full_ring_dde(lin, n), fo);
            REQUIRE(full.status == Status::Converged);
            // every full-system root is a mode root or the trivial zero
            int trivial = 0;
            std::size_t matched = 0;
            for (const auto& fr : full.roots) {
                if (std::abs(fr.value) < 1e-10) {
                    ++trivial;
                    continue;
                }
                if (fr.value.real() < modes.roots.back().root.value.real() - 1e-9) continue;  // beyond the listed modes
                const auto it = std::find_if(modes.roots.begin(), modes.roots.end(), [&](const RingRoot& m) {
                    return std::abs(m.root.value - fr.value) < tol::same_root;
                });
                CAPTURE(fr.value);
                CHECK(it != modes.roots.end());
                ++matched;
            }
            CHECK(trivial == 1);
            CHECK(matched >= 6);
        }
    }
}

TEST_CASE("D-subdivision: closed-form boundary points have a root on the imaginary axis") {
    // OVRV, mode m: k1 [i w th + e^{-i w tau}(1 - zeta)] + k2 [i w (1 - zeta e^{-i w tau})] = w^2
    const double th = 1.5, tau = 0.4;
    const int n = 7;
    int checked = 0;
    for (int m = 1; m < n; ++m) {  // crossings at w > 0 lie in modes m > N/2 (their conjugates at -w)
        const cplx zeta = std::polar(1.0, -2.0 * M_PI * m / n);
        for (double w : {0.1, 0.2, 0.3, 0.5}) {
            const cplx e = std::exp(cplx(0.0, -w * tau));
            const cplx a = cplx(0.0, w * th) + e * (1.0 - zeta);
            const cplx b = cplx(0.0, w) * (1.0 - zeta * e);
            // [Re a, Re b; Im a, Im b] (k1, k2) = (w^2, 0)
            const double det = a.real() * b.imag() - b.real() * a.imag();
            const double k1 = w * w * b.imag() / det;
            const double k2 = -w * w * a.imag() / det;
            if (k1 <= 0.0 || k2 <= 0.0) continue;
            CAPTURE(m);
            CAPTURE(w);
            const Linearisation lin = ovrv(k1, k2, th, tau);
            RootOptions o;
            o.count = 2;  // the crossing pair is the rightmost (the boundary is the first crossing)
            const RootResult r = rightmost_roots(ring_mode_dde(lin, zeta), o);
            const auto it = std::find_if(r.roots.begin(), r.roots.end(), [&](const Root& x) {
                return std::abs(x.value - cplx(0.0, w)) < tol::same_root;
            });
            CHECK(it != r.roots.end());
            ++checked;
        }
    }
    CHECK(checked >= 10);
}

TEST_CASE("k1 = 0: every mode has a zero root, the ring is marginal, not stable") {
    const RingResult r = analyse_ring(ovrv(0.0, 0.3, 1.2, 0.2), 6);
    CHECK_FALSE(r.stable);
    CHECK(r.unstable_roots == 0);
    CHECK(r.marginal_roots == 6);  // one per mode, mode 0 after removing the trivial factor
    CHECK(std::abs(r.spectral_abscissa) < 1e-13);
}

TEST_CASE("rings become unstable as N grows when sup |Gamma| > 1, and N = infinity bounds them") {
    const Linearisation lin = ovrv(0.2, 0.2, 1.5, 0.1);  // the paper's example
    const StringResult s = analyse_string(lin);
    REQUIRE_FALSE(s.string_stable);
    const RingResult small = analyse_ring(lin, 2);
    const RingResult large = analyse_ring(lin, 50);
    const RingResult inf = analyse_ring(lin, 0);
    CHECK(small.stable);  // a ring of 2 can be stable while string unstable
    CHECK_FALSE(large.stable);
    CHECK_FALSE(inf.stable);
    CHECK(inf.spectral_abscissa >= large.spectral_abscissa - 1e-12);
}

TEST_CASE("N = infinity ring stability agrees with string stability for plant-stable cases" * doctest::test_suite("slow")) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int stable = 0, unstable = 0;
    for (int i = 0; i < 30; ++i) {
        const double k1 = 0.05 + u(rng), k2 = 0.05 + u(rng), th = 0.3 + 2.7 * u(rng), tau = 0.05 + 0.6 * u(rng);
        const Linearisation lin = ovrv(k1, k2, th, tau);
        const StringResult s = analyse_string(lin);
        if (!s.plant_stable) continue;
        // skip cases within 1e-3 of the string boundary, where a finite grid in theta could be fooled
        if (std::abs(s.sup_gamma - 1.0) < 1e-3 && s.omega_peak > 0) continue;
        const RingResult r = analyse_ring(lin, 0);
        CAPTURE(k1);
        CAPTURE(k2);
        CAPTURE(th);
        CAPTURE(tau);
        CHECK(r.stable == s.string_stable);
        (s.string_stable ? stable : unstable)++;
    }
    CHECK(stable >= 3);
    CHECK(unstable >= 3);
}

TEST_CASE("large N works and the mode-0 trivial root is never reported") {
    const RingResult r = analyse_ring(ovrv(0.2, 0.2, 1.5, 0.1), 400);
    CHECK(r.modes_solved == 201);
    for (const auto& x : r.roots) CHECK(std::abs(x.root.value) > 1e-8);
    CHECK_THROWS_AS(analyse_ring(ovrv(0.2, 0.2, 1.5, 0.1), 1), std::invalid_argument);
}

TEST_SUITE_END();
