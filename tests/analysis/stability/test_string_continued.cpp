// The continued string analysis of sweep rows (analyse_string_continued): Newton from a
// neighbour's maximiser and a certified exclusion bound, against the scan of analyse_string.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/transfer_function.hpp"
#include "tolerances.hpp"

using namespace ddemap;

namespace {

Linearisation ovrv_car(double k1, double k2, double th, double tau) {
    return make_model("ovrv", {{"k1", k1}, {"k2", k2}, {"th", th}, {"tau", tau}})->linearise();
}

RootResult plant_of(const Linearisation& lin) {
    RootOptions ro;
    ro.count = 2;
    return rightmost_roots(plant_dde(lin), ro);
}

/// The highest local maximum of the scan.
GainPeak highest(const StringResult& r) {
    GainPeak best;
    for (const auto& p : r.peaks)
        if (p.gain > best.gain) best = p;
    return best;
}

void check_same(const StringResult& c, const StringResult& full) {
    CHECK(c.string_stable == full.string_stable);
    CHECK(c.string_verdict == full.string_verdict);
    CHECK(c.plant_verdict == full.plant_verdict);
    CHECK(std::abs(c.sup_gamma - full.sup_gamma) <= test::tol::string_continued_rel * full.sup_gamma);
    REQUIRE(c.peaks.size() == 1);
    CHECK(std::abs(c.peaks.front().gain - highest(full).gain) <= test::tol::string_continued_rel * highest(full).gain);
}

}  // namespace

TEST_CASE("continued string analysis: the same sup |Gamma| and verdicts as the scan at random points seeded by a neighbour" * doctest::test_suite("fast")) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<double> u(0.02, 1.0);
    int used = 0;
    for (int i = 0; i < 60; ++i) {
        const double k1 = u(rng), k2 = u(rng);
        const Linearisation lin = ovrv_car(k1, k2, 1.5, 0.5);
        const Linearisation next = ovrv_car(k1 + 0.005, k2, 1.5, 0.5);  // the next point of a 200-point row
        const StringResult here = analyse_string(lin, plant_of(lin), StringOptions{});
        const GainPeak seed = highest(here);
        if (seed.gain < 1.0) continue;
        const RootResult plant = plant_of(next);
        const StringResult full = analyse_string(next, plant, StringOptions{});
        const auto c = analyse_string_continued(next, plant, {true, seed.omega});
        const double gain1 = k1, gain2 = k2;  // plain variables: CAPTURE takes them in a lambda
        CAPTURE(gain1);
        CAPTURE(gain2);
        if (!c) continue;  // the caller scans: nothing to compare
        ++used;
        check_same(*c, full);
        CHECK(c->omega_search_max == full.omega_search_max);
    }
    CHECK(used >= 30);  // the shortcut applies to most points of this window
}

TEST_CASE("continued string analysis: a neighbour's maximiser on the lower of two peaks never yields the lower peak" * doctest::test_suite("fast")) {
    // tau 1.2, th 1.5: peaks near w = 0.030 (|Gamma| 1.0017) and w = 0.507 (1.285)
    const Linearisation lin = ovrv_car(0.65, 0.8, 1.5, 1.2);
    const RootResult plant = plant_of(lin);
    const StringResult full = analyse_string(lin, plant, StringOptions{});
    REQUIRE(full.peaks.size() == 2);
    const GainPeak low = full.peaks.front(), high = full.peaks.back();
    REQUIRE(low.gain > 1.0);
    REQUIRE(high.gain > low.gain);
    // seeded exactly on the lower peak: Newton stays there and the exclusion bound fails on the
    // higher one; the restart from that sample may certify the higher peak or decline (the caller
    // then scans), but the lower peak is never returned
    const auto c = analyse_string_continued(lin, plant, {true, low.omega});
    if (c) {
        check_same(*c, full);
        CHECK(std::abs(c->omega_peak - high.omega) < 1e-6 * high.omega);
    }
    // seeded near the higher peak it is certified
    const auto d = analyse_string_continued(lin, plant, {true, high.omega * 0.97});
    REQUIRE(d.has_value());
    check_same(*d, full);
}

TEST_CASE("continued string analysis: the verdict next to the string-stability boundary" * doctest::test_suite("fast")) {
    // along k2 at k1 = 0.5 the sup of |Gamma| falls to 1 (th 1.5, tau 0.5): bisect the scan's verdict
    const double k1 = 0.5;
    double lo = 0.05, hi = 1.0;  // string unstable at lo, stable at hi
    REQUIRE(!analyse_string(ovrv_car(k1, lo, 1.5, 0.5)).string_stable);
    REQUIRE(analyse_string(ovrv_car(k1, hi, 1.5, 0.5)).string_stable);
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (analyse_string(ovrv_car(k1, mid, 1.5, 0.5)).string_stable ? hi : lo) = mid;
    }
    const double seed_k2 = lo - 1e-3;
    const StringResult seeded = analyse_string(ovrv_car(k1, seed_k2, 1.5, 0.5));
    const GainPeak seed = highest(seeded);
    REQUIRE(seed.gain > 1.0);
    for (double k2 : {lo - 1e-4, lo - 1e-6, lo, hi, hi + 1e-6, hi + 1e-4}) {
        const Linearisation lin = ovrv_car(k1, k2, 1.5, 0.5);
        const RootResult plant = plant_of(lin);
        const StringResult full = analyse_string(lin, plant, StringOptions{});
        const auto c = analyse_string_continued(lin, plant, {true, seed.omega});
        CAPTURE(k2);
        if (!c) continue;  // declined (the sup is not a peak above 1, or too close to it): the scan decides
        check_same(*c, full);
    }
    // a little further from the boundary, on the unstable side, the shortcut decides (and agrees)
    const Linearisation lin = ovrv_car(k1, seed_k2, 1.5, 0.5);
    const auto c = analyse_string_continued(lin, plant_of(lin), {true, seed.omega});
    REQUIRE(c.has_value());
    check_same(*c, seeded);
}

TEST_CASE("continued string analysis: the exclusion bound against a dense scan of the axis" * doctest::test_suite("fast")) {
    for (const auto& [k1, k2, th, tau] : {std::array<double, 4>{0.3, 0.2, 1.5, 0.5}, std::array<double, 4>{0.9, 0.4, 1.5, 0.5},
                                          std::array<double, 4>{0.65, 0.8, 1.5, 1.2}, std::array<double, 4>{0.5, 0.2, 2.5, 0.8}}) {
        const Linearisation lin = ovrv_car(k1, k2, th, tau);
        const RootResult plant = plant_of(lin);
        const StringResult full = analyse_string(lin, plant, StringOptions{});
        const GainPeak seed = highest(full);
        const double gain1 = k1, gain2 = k2;  // plain variables: CAPTURE takes them in a lambda
        CAPTURE(gain1);
        CAPTURE(gain2);
        REQUIRE(seed.gain > 1.0);
        const auto c = analyse_string_continued(lin, plant, {true, seed.omega * 1.05});
        REQUIRE(c.has_value());
        // 200,000 samples of |Gamma(i w)|^2 on (0, 2 omega_search_max]: none above the certified bound,
        // and the largest sample next to the certified maximiser
        const TransferFunction tf(lin);
        const double g = c->sup_gamma * c->sup_gamma;
        double best = 0.0, best_w = 0.0;
        const int n = 200000;
        for (int i = 1; i <= n; ++i) {
            const double w = 2.0 * c->omega_search_max * i / n;
            const double v = tf.gain2(w);
            if (v > best) {
                best = v;
                best_w = w;
            }
        }
        CHECK(best <= g * (1.0 + kStringExclusionSlack) * (1.0 + 1e-15));
        CHECK(std::abs(best_w - c->omega_peak) <= 2.0 * c->omega_search_max / n);
        CHECK(best >= g * (1.0 - 1e-6));  // the grid is fine enough to come close to the peak
    }
}
