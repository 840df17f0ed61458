// Sweeps against the plain per-point computation (collocation for every mode, no continuation).
#include <doctest/doctest.h>

#include "tolerances.hpp"

#include <cmath>
#include <random>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/traffic/transfer_function.hpp"
#include "chart_helpers.hpp"

namespace tol = ddemap::test::tol;

TEST_SUITE_BEGIN("fast");

using namespace ddemap;


TEST_CASE("sweep points equal the per-point computation (random points, boundaries, mode switches)" * doctest::test_suite("slow")) {
    const SweepResult r = run_sweep(ddemap::test::ovrv_chart(41, 22, 1.5, 0.5));
    CHECK(r.uncertified == 0);
    std::mt19937 rng(23);
    std::uniform_int_distribution<int> pick(0, 40);
    std::vector<std::pair<int, int>> where;
    for (int i = 0; i < 40; ++i) where.emplace_back(pick(rng), pick(rng));
    // points next to a ring-stability boundary and where the abscissa mode changes along x
    int near_boundary = 0, switches = 0;
    for (int iy = 0; iy < 41; ++iy)
        for (int ix = 0; ix + 1 < 41; ++ix) {
            const auto& a = r.at(ix, iy);
            const auto& b = r.at(ix + 1, iy);
            if (a.ring_stable != b.ring_stable && near_boundary < 25) {
                where.emplace_back(ix, iy);
                where.emplace_back(ix + 1, iy);
                ++near_boundary;
            }
            if (a.abscissa_mode != b.abscissa_mode && switches < 25) {
                where.emplace_back(ix, iy);
                where.emplace_back(ix + 1, iy);
                ++switches;
            }
        }
    CHECK(near_boundary >= 5);
    CHECK(switches >= 5);
    for (const auto& [ix, iy] : where) {
        const SweepPoint& p = r.at(ix, iy);
        const Linearisation lin = model_at(r.spec, p.x, p.y)->linearise();
        const RingResult ring = analyse_ring(lin, 22);
        const StringResult s = analyse_string(lin);
        CAPTURE(p.x);
        CAPTURE(p.y);
        CHECK(std::abs(p.spectral_abscissa - ring.spectral_abscissa) < tol::sweep_vs_point);
        CHECK(p.unstable_roots == ring.unstable_roots);
        CHECK(p.ring_stable == ring.stable);
        CHECK(p.plant_stable == s.plant_stable);
        CHECK(p.string_stable == s.string_stable);
        CHECK(std::abs(p.sup_gamma - s.sup_gamma) < 1e-10 * s.sup_gamma);
        CHECK(std::abs(p.plant_abscissa - s.plant_abscissa) < tol::sweep_vs_point);
    }
}

TEST_CASE("N = infinity sweeps agree with the per-point verdicts" * doctest::test_suite("slow")) {
    const SweepResult r = run_sweep(ddemap::test::ovrv_chart(7, 0, 1.2, 0.3));
    for (const auto& p : r.points) {
        const Linearisation lin = model_at(r.spec, p.x, p.y)->linearise();
        const RingResult ring = analyse_ring(lin, 0);
        CAPTURE(p.x);
        CAPTURE(p.y);
        CHECK(p.ring_stable == ring.stable);
        CHECK(std::abs(p.spectral_abscissa - ring.spectral_abscissa) < 1e-7);
    }
}

TEST_CASE("axes and sweep specs are validated") {
    CHECK_THROWS_WITH_AS(parse_axis("k1", "1:0:5"), "k1 = '1:0:5': expected LO:HI:COUNT with finite LO < HI and an integer COUNT from 2 to 100000", std::invalid_argument);
    CHECK_THROWS_AS(parse_axis("k1", "0:1"), std::invalid_argument);
    CHECK_THROWS_AS(parse_axis("k1", "0:1:1"), std::invalid_argument);
    CHECK_THROWS_AS(parse_axis("k1", "0:x:4"), std::invalid_argument);
    SweepSpec s = ddemap::test::ovrv_chart(3, 22, 1.5, 0.5);
    s.x = parse_axis("k1", "-1:1:3");
    CHECK_THROWS_WITH_AS(s.validate(), "k1 = -1: expected a value >= 0 [1/s^2]", std::invalid_argument);
    // a law of more than the car ahead is refused up front, for the reason that holds whatever the
    // ring method or curves (the string verdict of every point needs the car ahead only)
    SweepSpec ccc = ddemap::test::ovrv_chart(3, 22, 1.5, 0.5);
    ccc.model = "ccc";
    ccc.fixed["k3"] = 0.2;
    ccc.fixed["tau2"] = 0.5;
    CHECK_THROWS_WITH_AS(ccc.validate(),
                         "a sweep's string verdict (the low-frequency string condition) needs a law that uses only the car ahead; this one uses 2 cars ahead (analyse it as a ring or a fleet)",
                         std::invalid_argument);
    ccc.ring_method = "modes";
    CHECK_THROWS_AS(ccc.validate(), std::invalid_argument);
}

// the sweep's plant root, abscissa and verdict at each of `where` against the collocation roots
// of the plant alone (refined and certified on their own)
static void check_plant_against_collocation(const SweepResult& r, const std::vector<std::pair<int, int>>& where) {
    for (const auto& [ix, iy] : where) {
        const SweepPoint& p = r.at(ix, iy);
        const Linearisation lin = model_at(r.spec, p.x, p.y)->linearise();
        RootOptions o;
        o.count = 2;
        const RootResult ref = rightmost_roots(plant_dde(lin), o);  // collocation, refined and certified on its own
        REQUIRE(ref.status == Status::Converged);
        CAPTURE(p.x);
        CAPTURE(p.y);
        CHECK(std::abs(p.plant_abscissa - ref.spectral_abscissa()) < tol::sweep_vs_point);
        const cplx z = ref.roots.front().value;
        CHECK(std::abs(p.plant_root - (z.imag() < 0.0 ? std::conj(z) : z)) < tol::sweep_vs_point * std::max(1.0, std::abs(z)));
        CHECK(p.plant_stable == (ref.spectral_abscissa() < -marginal_band(z)));
    }
}

TEST_CASE("the sweep's plant roots (certified on a wide line first, adapted along the row) equal the per-point collocation roots") {
    // th = 0.5, tau = 0.8: the plant P = s^2 + (k1 th + k2) s + k1 e^{-s tau} is unstable for large
    // k1 and small k2 inside the window, so the rows cross the plant's boundary
    const SweepResult r = run_sweep(ddemap::test::ovrv_chart(21, 22, 0.5, 0.8));
    std::vector<std::pair<int, int>> where;
    std::mt19937 rng(31);
    std::uniform_int_distribution<int> pick(0, 20);
    for (int i = 0; i < 30; ++i) where.emplace_back(pick(rng), pick(rng));
    int near_boundary = 0;
    for (int iy = 0; iy < 21; ++iy)
        for (int ix = 0; ix + 1 < 21; ++ix)
            if (r.at(ix, iy).plant_stable != r.at(ix + 1, iy).plant_stable) {
                where.emplace_back(ix, iy);
                where.emplace_back(ix + 1, iy);
                ++near_boundary;
            }
    CHECK(near_boundary >= 5);
    check_plant_against_collocation(r, where);
}

TEST_SUITE_END();

TEST_SUITE_BEGIN("fast");

TEST_CASE("sweep with the peak notion: per-point verdicts equal analyse_string's, peak stable points are L2 stable, the chart and CSV show them" * doctest::test_suite("slow")) {
    // th = 1.5, tau = 0.3: above the L2 boundary a band where the step response still overshoots
    SweepSpec spec;
    spec.fixed = {{"th", 1.5}, {"tau", 0.3}};
    spec.x = parse_axis("k1", "0.005:0.2:7");
    spec.y = parse_axis("k2", "0.6:1.2:9");
    spec.cars = 22;
    spec.peak = true;
    const SweepResult r = run_sweep(spec);
    int peak_stable = 0, l2_only = 0;
    for (const SweepPoint& p : r.points) {
        CAPTURE(p.x);
        CAPTURE(p.y);
        CHECK(p.has_peak);
        CHECK(!(p.peak_stable && !p.string_stable));  // ||h||_1 >= sup |Gamma|
        StringOptions so;
        so.peak = true;
        const StringResult sr = analyse_string(model_at(spec, p.x, p.y)->linearise(), so);
        REQUIRE(sr.peak);
        CHECK(p.peak_stable == (sr.peak->verdict == Verdict::Stable));
        if (sr.string_stable && sr.peak->finite) CHECK(p.peak_norm == doctest::Approx(sr.peak->norm).epsilon(1e-12));
        peak_stable += p.peak_stable;
        l2_only += p.string_stable && !p.peak_stable;
    }
    CHECK(peak_stable > 0);
    CHECK(l2_only > 0);
    const std::string svg = sweep_chart_svg(spec, r, nullptr, {});
    CHECK(svg.find("string stable (L2 and peak)") != std::string::npos);
    CHECK(svg.find("string stable (L2), peak unstable (overshoot)") != std::string::npos);
    CHECK(svg.find("class=\"level4\"") != std::string::npos);
    const std::string csv = sweep_csv(r);
    CHECK(csv.substr(0, csv.find('\n')).find(",peak_norm,peak_stable") != std::string::npos);
    // without the peak notion: four classes, no peak columns
    spec.peak = false;
    const SweepResult plain = run_sweep(spec);
    CHECK(sweep_chart_svg(spec, plain, nullptr, {}).find("level4") == std::string::npos);
    CHECK(sweep_csv(plain).find("peak_norm") == std::string::npos);
}

TEST_CASE("the sweep's plant roots where two real roots meet and leave the real axis: Newton started off the axis, equal to the collocation roots") {
    // th = 1.5, tau = 0.5: along the rows the plant's rightmost root switches between a real root
    // and a complex pair; Newton from a real guess stays real, so the pair is reached from starts
    // off the axis (certified_rightmost) instead of a collocation solve
    const SweepResult r = run_sweep(ddemap::test::ovrv_chart(30, 22, 1.5, 0.5));
    std::vector<std::pair<int, int>> where;
    int to_pair = 0;
    for (int iy = 0; iy < 30; ++iy)
        for (int ix = 0; ix + 1 < 30; ++ix) {
            const bool real0 = r.at(ix, iy).plant_root.imag() == 0.0, real1 = r.at(ix + 1, iy).plant_root.imag() == 0.0;
            if (real0 != real1) {
                where.emplace_back(ix, iy);
                where.emplace_back(ix + 1, iy);
                to_pair += real0 && !real1;
            }
        }
    CAPTURE(to_pair);
    CAPTURE(r.fallbacks);
    CHECK(to_pair >= 5);
    // each of those switches needed a collocation solve before; now at most a few points do
    CHECK(r.fallbacks < to_pair);
    check_plant_against_collocation(r, where);
}

TEST_SUITE_END();
