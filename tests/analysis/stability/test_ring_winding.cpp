// The winding tables of a ring (every mode from one pass) against the per-mode argument
// principle (QuasiPolynomial::zeros_right_of on each mode's characteristic function) and the
// per-mode ring analysis, at random points and next to the boundaries of the continuation.
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <random>

#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/ring_winding.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/traffic/ring.hpp"
#include "chart_helpers.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

using test::ovrv;

/// Every mode's count from the table equals its own argument-principle count.
void check_counts(const Linearisation& lin, int cars, double sigma) {
    const RingWindingTable t = ring_winding_table(TransferFunction(lin), sigma);
    REQUIRE(t.ok);
    for (int m = 1; m < cars; ++m) {
        const int ref = ring_mode_characteristic(lin, ring_zeta(m, cars)).zeros_right_of(sigma);
        REQUIRE(ref >= 0);
        CAPTURE(m);
        CHECK(t.zeros(2.0 * M_PI * m / cars) == ref);
    }
}

/// Verdict, unstable count and abscissa against the per-mode ring analysis.
void check_against_modes(const Linearisation& lin, int cars) {
    const RingWindingResult w = analyse_ring_winding(lin, cars);
    const RingResult ref = analyse_ring(lin, cars);
    REQUIRE(ref.status == Status::Converged);
    REQUIRE(w.status == Status::Converged);
    CHECK(w.certified);
    CHECK(w.verdict == ref.verdict);
    if (cars > 0) {
        CHECK(w.unstable_roots == ref.unstable_roots);
        CHECK(std::abs(w.spectral_abscissa - ref.spectral_abscissa) < tol::sweep_vs_point);
    } else if (ref.verdict == Verdict::Unstable) {
        // the N = inf reference maximises over sampled wave numbers by golden section
        CHECK(std::abs(w.spectral_abscissa - ref.spectral_abscissa) < tol::sweep_vs_point);
    }
}

}  // namespace

TEST_CASE("winding tables count every mode's roots as the per-mode argument principle does") {
    std::mt19937 rng(20261123);
    std::uniform_real_distribution<double> k(0.01, 1.0), th(0.5, 2.0), tau(0.05, 1.0);
    for (int i = 0; i < 8; ++i) {
        const double k1 = k(rng), k2 = k(rng), h = th(rng), t = tau(rng);
        CAPTURE(k1);
        CAPTURE(k2);
        CAPTURE(h);
        CAPTURE(t);
        const Linearisation lin = ovrv(k1, k2, h, t);
        for (double sigma : {0.0, -0.03, 0.02}) {
            CAPTURE(sigma);
            for (int cars : {3, 22}) check_counts(lin, cars, sigma);
            if (i < 3) check_counts(lin, 200, sigma);
        }
    }
}

TEST_CASE("the winding verdict, unstable count and abscissa equal the per-mode ring analysis") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> k(0.01, 1.0);
    for (int i = 0; i < 6; ++i) {
        const double k1 = k(rng), k2 = k(rng);
        CAPTURE(k1);
        CAPTURE(k2);
        const Linearisation lin = ovrv(k1, k2, 1.5, 0.5);
        for (int cars : {3, 22}) {
            CAPTURE(cars);
            check_against_modes(lin, cars);
        }
        if (i < 3) check_against_modes(lin, 0);
    }
}

TEST_CASE("the winding path agrees with the per-mode path for the IDM law too") {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int i = 0; i < 4; ++i) {
        const ParameterMap p{{"a", 0.5 + 1.5 * u(rng)}, {"b", 1.0 + 2.0 * u(rng)}, {"v0", 30.0},
                             {"th", 0.8 + 1.5 * u(rng)}, {"tau", 0.05 + 0.6 * u(rng)}, {"speed", 5.0 + 20.0 * u(rng)}};
        const Linearisation lin = make_model("idm", p)->linearise();
        for (int cars : {5, 22}) {
            CAPTURE(i);
            CAPTURE(cars);
            check_counts(lin, cars, 0.0);
            check_against_modes(lin, cars);
        }
    }
}

TEST_CASE("next to the ring and low-frequency boundaries the winding counts and verdicts stay exact") {
    SweepSpec spec = test::ovrv_chart(11, 22, 1.5, 0.5);
    spec.ring_method = "modes";
    const BoundarySet set = trace_boundaries(run_sweep(spec));
    int checked = 0, inf_checked = 0;
    for (const auto& c : set.curves) {
        if (c.kind != BoundaryKind::RingHopf && c.kind != BoundaryKind::LowFrequency) continue;
        for (std::size_t i = c.points.size() / 3; i < c.points.size(); i += c.points.size() / 2 + 1) {
            for (double side : {-1e-6, 1e-6}) {
                const double k1 = c.points[i].x + side, k2 = c.points[i].y;
                if (k1 <= 0.0) continue;
                CAPTURE(k1);
                CAPTURE(k2);
                const Linearisation lin = ovrv(k1, k2, 1.5, 0.5);
                if (c.kind == BoundaryKind::RingHopf) {
                    check_counts(lin, 22, 0.0);
                    check_against_modes(lin, 22);
                    ++checked;
                } else if (inf_checked < 4) {
                    check_against_modes(lin, 0);
                    ++inf_checked;
                }
            }
        }
    }
    CHECK(checked >= 4);
    CHECK(inf_checked >= 2);
}

TEST_CASE("rings of a million and a billion cars: sampled modes against their own counts") {
    std::mt19937 rng(99);
    for (const auto& p : {std::array<double, 2>{0.3, 0.6}, std::array<double, 2>{0.8, 0.2}}) {
        const Linearisation lin = ovrv(p[0], p[1], 1.5, 0.5);
        const RingWindingTable t = ring_winding_table(TransferFunction(lin), 0.0);
        REQUIRE(t.ok);
        for (int cars : {1000000, 1000000000}) {
            std::uniform_int_distribution<int> mode(1, cars - 1);
            for (int j = 0; j < 6; ++j) {
                const int m = j == 0 ? 1 : mode(rng);
                CAPTURE(cars);
                CAPTURE(m);
                CHECK(t.zeros(2.0 * M_PI * m / cars) == ring_mode_characteristic(lin, ring_zeta(m, cars)).zeros_right_of(0.0));
            }
            // the abscissa of a long ring approaches the N = inf sup from below
            const RingWindingResult big = analyse_ring_winding(lin, cars), inf = analyse_ring_winding(lin, 0);
            REQUIRE(big.status == Status::Converged);
            REQUIRE(inf.status == Status::Converged);
            CHECK(big.spectral_abscissa <= inf.spectral_abscissa + tol::sweep_vs_point);
            if (inf.verdict == Verdict::Unstable) {
                CHECK(big.verdict == Verdict::Unstable);
                CHECK(big.spectral_abscissa > inf.spectral_abscissa - 1e-6);
            }
            // the rightmost root is a root of its mode
            const cplx zeta = ring_zeta(big.abscissa_mode, cars);
            const QuasiPolynomial f = big.abscissa_mode == 0 ? ring_mode0_characteristic(lin) : ring_mode_characteristic(lin, zeta);
            CHECK(std::abs(f(big.abscissa_root)) < 1e-10);
        }
    }
}

TEST_CASE("the winding sweep equals the per-mode sweep and does not depend on the thread count") {
    for (int cars : {22, 0}) {
        CAPTURE(cars);
        SweepSpec spec = test::ovrv_chart(13, cars, 1.5, 0.5);
        spec.ring_method = "winding";
        ExecutionPolicy one, two;
        one.threads = 1;
        two.threads = 2;
        const SweepResult a = run_sweep(spec, one), b = run_sweep(spec, two);
        CHECK(a.ring_method == "winding");
        REQUIRE(a.points.size() == b.points.size());
        auto same = [](double u, double v) { return std::memcmp(&u, &v, sizeof(double)) == 0; };
        for (std::size_t i = 0; i < a.points.size(); ++i) {
            const SweepPoint &p = a.points[i], &q = b.points[i];
            CHECK(same(p.spectral_abscissa, q.spectral_abscissa));
            CHECK(p.unstable_roots == q.unstable_roots);
            CHECK(p.abscissa_mode == q.abscissa_mode);
            CHECK(p.ring_stable == q.ring_stable);
            CHECK(p.certified == q.certified);
            CHECK(same(p.sup_gamma, q.sup_gamma));
            CHECK(same(p.plant_abscissa, q.plant_abscissa));
        }
        CHECK(a.winding_tables == b.winding_tables);
        spec.ring_method = "modes";
        const SweepResult c = run_sweep(spec, two);
        CHECK(c.ring_method == "modes");
        for (std::size_t i = 0; i < a.points.size(); ++i) {
            CAPTURE(a.points[i].x);
            CAPTURE(a.points[i].y);
            CHECK(a.points[i].ring_stable == c.points[i].ring_stable);
            CHECK(a.points[i].unstable_roots == c.points[i].unstable_roots);
            CHECK(std::abs(a.points[i].spectral_abscissa - c.points[i].spectral_abscissa) < tol::sweep_vs_point);
        }
    }
    SweepSpec unknown = test::ovrv_chart(3, 22, 1.5, 0.5);
    unknown.ring_method = "fast";
    CHECK_THROWS_AS(run_sweep(unknown), std::invalid_argument);
}

TEST_CASE("few modes: roots accounted for right of the axis (one table) give the per-mode abscissa, count and verdict" * doctest::test_suite("slow")) {
    // rows continued as a sweep continues them (each point from the previous point's result), at
    // random rows and across the ring's boundaries; every point against the per-mode ring analysis
    std::mt19937 rng(4242);
    std::uniform_real_distribution<double> u(0.01, 1.0);
    int accounted = 0, points = 0;
    for (int cars : {5, 22, 64}) {
        for (int row = 0; row < (cars == 64 ? 1 : 3); ++row) {
            const double k2 = u(rng);
            RingWindingGuess g;
            for (int i = 0; i < 12; ++i) {
                const double k1 = 0.01 + 0.09 * i;
                CAPTURE(cars);
                CAPTURE(k1);
                CAPTURE(k2);
                const Linearisation lin = ovrv(k1, k2, 1.5, 0.5);
                const RingWindingResult w = analyse_ring_winding(lin, cars, {}, g);
                g = w.next;
                const RingResult ref = analyse_ring(lin, cars);
                REQUIRE(w.status == Status::Converged);
                REQUIRE(ref.status == Status::Converged);
                CHECK(w.certified);
                CHECK(w.verdict == ref.verdict);
                CHECK(w.unstable_roots == ref.unstable_roots);
                CHECK(std::abs(w.spectral_abscissa - ref.spectral_abscissa) < tol::sweep_vs_point);
                if (w.accounted) {
                    ++accounted;
                    CHECK(w.tables == 1);
                    CHECK(w.verdict == Verdict::Unstable);
                    CHECK(w.abscissa_mode == std::min(ref.abscissa_mode, cars - ref.abscissa_mode));  // m and N - m: conjugate roots
                }
                ++points;
            }
        }
    }
    CHECK(accounted >= points / 4);  // the shortcut is taken at most unstable points
    // next to the ring's boundary, continued from a neighbour 0.01 to the left
    SweepSpec spec = test::ovrv_chart(11, 22, 1.5, 0.5);
    spec.ring_method = "modes";
    const BoundarySet set = trace_boundaries(run_sweep(spec));
    int checked = 0;
    for (const auto& c : set.curves) {
        if (c.kind != BoundaryKind::RingHopf) continue;
        for (std::size_t i = 0; i < c.points.size(); i += c.points.size() / 3 + 1)
            for (double side : {-1e-6, 1e-6, 1e-3}) {
                const double k1 = c.points[i].x + side, k2 = c.points[i].y;
                if (k1 <= 0.011) continue;
                CAPTURE(k1);
                CAPTURE(k2);
                const RingWindingResult before = analyse_ring_winding(ovrv(k1 - 0.01, k2, 1.5, 0.5), 22);
                const Linearisation lin = ovrv(k1, k2, 1.5, 0.5);
                const RingWindingResult w = analyse_ring_winding(lin, 22, {}, before.next);
                const RingResult ref = analyse_ring(lin, 22);
                REQUIRE(w.status == Status::Converged);
                CHECK(w.verdict == ref.verdict);
                CHECK(w.unstable_roots == ref.unstable_roots);
                CHECK(std::abs(w.spectral_abscissa - ref.spectral_abscissa) < tol::sweep_vs_point);
                ++checked;
            }
    }
    CHECK(checked >= 6);
}

TEST_SUITE_END();

namespace {

/// A verdict and its abscissa never contradict each other: unstable means a positive abscissa,
/// stable a negative one (anything else must be marginal or undecided).
void check_sign(const Linearisation& lin, int cars) {
    const RingWindingResult w = analyse_ring_winding(lin, cars);
    if (w.verdict == Verdict::Unstable) CHECK(w.spectral_abscissa > 0.0);
    if (w.verdict == Verdict::Stable) CHECK(w.spectral_abscissa < 0.0);
    const FastRing f = analyse_ring_fast(lin, cars, "winding", 6);
    if (f.ring.verdict == Verdict::Unstable) CHECK(f.ring.spectral_abscissa > 0.0);
    if (f.ring.verdict == Verdict::Stable) CHECK(f.ring.spectral_abscissa < 0.0);
}

}  // namespace

TEST_CASE("on huge rings the verdict and the abscissa agree in sign within rounding of the boundary" * doctest::test_suite("fast")) {
    // two points where they did not: a count of roots right of the axis with a located rightmost
    // root left of it (N = 10^6), and a listed root's real part of the wrong sign (N = 10^9)
    check_sign(ovrv(0.48136463760710274, 0.46374907192550308, 1.5, 0.2), 1000000);
    check_sign(ovrv(0.26871233702204367, 0.59870149670221018, 1.5, 0.2), 1000000000);
    // across the boundary along k1 at fixed k2: the crossing by bisection on the verdict, then
    // points 1e-15 to 1e-8 (relative) on either side of it
    for (const int cars : {1000000, 1000000000}) {
        for (const double k2 : {0.46374907192550308, 0.59870149670221018, 0.35}) {
            auto unstable = [&](double k1) { return analyse_ring_winding(ovrv(k1, k2, 1.5, 0.2), cars).verdict == Verdict::Unstable; };
            double lo = 0.05, hi = 1.5;
            const bool ulo = unstable(lo);
            REQUIRE(ulo != unstable(hi));
            for (int i = 0; i < 55; ++i) {
                const double mid = 0.5 * (lo + hi);
                (unstable(mid) == ulo ? lo : hi) = mid;
            }
            CAPTURE(cars);
            CAPTURE(k2);
            for (int e = 8; e <= 15; ++e)
                for (const double s : {-1.0, 1.0}) {
                    const double k1 = lo * (1.0 + s * std::pow(10.0, -e));
                    CAPTURE(k1);
                    check_sign(ovrv(k1, k2, 1.5, 0.2), cars);
                }
        }
    }
}
