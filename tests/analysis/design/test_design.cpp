#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <random>
#include <stdexcept>

#include "ddemap/analysis/design/design.hpp"
#include "ddemap/analysis/stability/attenuation_margin.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/roots.hpp"
#include "argument_count.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
using cd = std::complex<double>;

ParameterMap car_params(const std::string& name) {
    ParameterMap p = builtin_vehicle(name).parameters;
    p["speed"] = 20.0;
    return p;
}

/// Options for `objective` from `starts` starts (two: quick, and a second start checks the first).
DesignOptions options_for(DesignObjective objective, int starts = 2) {
    DesignOptions o;
    o.objective = objective;
    o.starts = starts;
    return o;
}

/// |Gamma(i w)| of OVRV written out here (independent of TransferFunction):
/// Gamma = (k1 + k2 s) e^{-s tau} / (s^2 + (k1 th + k2) s + k1 e^{-s tau}).
double ovrv_gain(const ParameterMap& p, double w) {
    const double k1 = p.at("k1"), k2 = p.at("k2"), th = p.at("th"), tau = p.at("tau");
    const cd s(0.0, w), e = std::exp(-s * tau);
    return std::abs((k1 + k2 * s) * e / (s * s + (k1 * th + k2) * s + k1 * e));
}

/// sup_w |Gamma(i w)| |1 + i m w| by brute force: 20000 log-spaced frequencies over 1e-4 to 1e3
/// rad/s, the best refined by golden sections.
double brute_weighted_sup(const ParameterMap& p, double m) {
    auto f = [&](double u) {
        const double w = std::exp(u);
        return ovrv_gain(p, w) * std::hypot(1.0, m * w);
    };
    const int n = 20000;
    const double a = std::log(1e-4), b = std::log(1e3);
    double best = 1.0;
    for (int i = 1; i + 1 < n; ++i) {
        const double u = a + (b - a) * i / (n - 1), h = (b - a) / (n - 1);
        const double v = f(u);
        if (v > f(u - h) && v >= f(u + h)) {
            double lo = u - h, hi = u + h;
            for (int it = 0; it < 100; ++it) {
                const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
                if (f(m1) < f(m2)) lo = m1;
                else hi = m2;
            }
            best = std::max(best, f(0.5 * (lo + hi)));
        }
        best = std::max(best, v);
    }
    return best;
}
}  // namespace

TEST_SUITE_BEGIN("fast");

TEST_CASE("attenuation margin of OVRV without delay against its closed form mu = min(c / k1^2, 1 / k2^2)") {
    // tau = 0: |D|^2 - |N|^2 = w^4 + c w^2 with c = k1^2 th^2 + 2 k1 k2 th - 2 k1, |N|^2 = k1^2 + k2^2 w^2,
    // so q / |N|^2 = (w^2 + c) / (k1^2 + k2^2 w^2), monotone in w^2 between c / k1^2 and 1 / k2^2.
    // The weighted norm: R(W) = (k1^2 + k2^2 W)(1 + m^2 W) / (W^2 + (b^2 - 2 k1) W + k1^2), W = w^2,
    // b = k1 th + k2, whose stationary points solve a quadratic (the cubic terms cancel).
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (int trial = 0; trial < 40; ++trial) {
        const double k1 = 0.05 + 0.95 * U(rng), k2 = 0.1 + 1.9 * U(rng), th = 0.5 + 2.5 * U(rng), m = 0.05 + 1.5 * U(rng);
        const Linearisation lin = test::ovrv(k1, k2, th, 0.0);
        const AttenuationScan s = attenuation_scan(lin, m);
        const double c = k1 * k1 * th * th + 2.0 * k1 * k2 * th - 2.0 * k1;
        const double mu = std::min(c / (k1 * k1), 1.0 / (k2 * k2));
        CAPTURE(k1);
        CAPTURE(k2);
        CAPTURE(th);
        CHECK(std::abs(s.mu - mu) <= tol::attenuation_mu_rel * std::max(1.0, std::abs(mu)));
        CHECK(s.margin == doctest::Approx(std::copysign(std::sqrt(std::abs(s.mu)), s.mu)));
        const double b = k1 * th + k2, al = k2 * k2 * m * m, be = k2 * k2 + k1 * k1 * m * m, ga = k1 * k1, de = b * b - 2.0 * k1;
        auto R = [&](double W) { return (al * W * W + be * W + ga) / (W * W + de * W + k1 * k1); };
        // (2 al W + be)(W^2 + de W + k1^2) - (al W^2 + be W + ga)(2 W + de) = A2 W^2 + A1 W + A0
        const double A2 = al * de - be, A1 = 2.0 * al * k1 * k1 - 2.0 * ga, A0 = be * k1 * k1 - ga * de;
        double sup = std::max(1.0, al);  // W = 0 and W -> infinity
        const double disc = A1 * A1 - 4.0 * A2 * A0;
        if (A2 != 0.0 && disc >= 0.0)
            for (double W : {(-A1 + std::sqrt(disc)) / (2.0 * A2), (-A1 - std::sqrt(disc)) / (2.0 * A2)})
                if (W > 0.0) sup = std::max(sup, R(W));
        CHECK(std::sqrt(sup) == doctest::Approx(s.weighted_sup).epsilon(tol::attenuation_sup_rel));
    }
}

TEST_CASE("attenuation margin: its sign is the certified L2 verdict, and |Gamma(iw)| |1 + i m* w| <= 1 over random delayed OVRV cars") {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    int stable = 0, unstable = 0;
    for (int trial = 0; trial < 60; ++trial) {
        const double k1 = 0.02 + 0.5 * U(rng), k2 = 0.1 + 1.5 * U(rng), th = 0.5 + 2.5 * U(rng), tau = 0.05 + 0.8 * U(rng);
        const Linearisation lin = test::ovrv(k1, k2, th, tau);
        if (!is_computable(lin)) continue;
        const StringResult v = analyse_string(lin);
        if (!v.plant_stable || (v.string_verdict != Verdict::Stable && v.string_verdict != Verdict::Unstable)) continue;
        const AttenuationScan s = attenuation_scan(lin);
        if (std::abs(s.mu) < 1e-9) continue;
        CAPTURE(k1);
        CAPTURE(k2);
        CAPTURE(th);
        CAPTURE(tau);
        CHECK((s.mu > 0.0) == (v.string_verdict == Verdict::Stable));
        if (s.mu <= 0.0) {
            ++unstable;
            continue;
        }
        ++stable;
        const ParameterMap p{{"k1", k1}, {"k2", k2}, {"th", th}, {"tau", tau}};
        // m* bounds the gain everywhere (independent dense evaluation) ...
        for (int i = 0; i <= 4000; ++i) {
            const double w = std::exp(std::log(1e-4) + (std::log(1e3) - std::log(1e-4)) * i / 4000.0);
            CHECK(ovrv_gain(p, w) * std::hypot(1.0, s.margin * w) <= 1.0 + tol::attenuation_bound_rel);
        }
        // ... and no larger time constant does: 1 % more fails where mu is reached
        const double w = s.omega_mu > 0.0 ? s.omega_mu : 1e-3 * std::sqrt(k1);
        CHECK(ovrv_gain(p, w) * std::hypot(1.0, 1.01 * s.margin * w) > 1.0);
    }
    CHECK(stable >= 10);
    CHECK(unstable >= 10);
}

TEST_CASE("design abscissa: OVRV without delay reaches the double root of the closed form (k1, k2) = (1, 1), abscissa -1") {
    // D = s^2 + (k1 th + k2) s + k1 with th = 1: a double root -a/2 when a^2 = 4 k1, a = k1 + k2;
    // within k1 <= 1 the least abscissa is -1 at k1 = 1, a = 2. The minimum is non-smooth (the
    // abscissa grows like a square root on the real side).
    DesignOptions o;
    o.objective = DesignObjective::Abscissa;
    o.bounds = {{"k1", 0.1, 1.0}, {"k2", 0.01, 2.0}};
    const DesignResult r = design_gains("ovrv", {{"k1", 0.5}, {"k2", 0.5}, {"th", 1.0}, {"tau", 0.0}, {"eta", 10.0}, {"speed", 20.0}}, o);
    CAPTURE(r.message);
    CHECK(r.status == Status::Converged);
    CHECK(std::abs(r.value + 1.0) < tol::design_abscissa_value);
    CHECK(std::abs(r.gains.at("k1") - 1.0) < tol::design_abscissa_gains);
    CHECK(std::abs(r.gains.at("k2") - 1.0) < tol::design_abscissa_gains);
    CHECK(r.string.plant_abscissa == doctest::Approx(r.value).epsilon(1e-9));
}

TEST_CASE("design abscissa with a delay: on the face k1 = 5 the minimum is the double real root of the closed form, and its verdict is decided") {
    // D = l^2 + a l + k1 e^{-l tau}, a = k1 th + k2, th = 1, tau = 0.5. Over a at fixed k1 the
    // least abscissa is where the two rightmost real roots meet: D = D' = 0 gives
    // l^2 = k1 e^{-l tau} (1 + tau l) and a = tau k1 e^{-l tau} - 2 l; it decreases with k1, so
    // the minimum lies on the face k1 = 5. There the plant's roots are nearly double (1.3e-6
    // apart), which left the certified verdict at the design undecided (max degree reached).
    DesignOptions o;
    o.objective = DesignObjective::Abscissa;
    o.bounds = {{"k1", 0.01, 5.0}, {"k2", 0.01, 5.0}};
    const DesignResult r = design_gains("ovrv", {{"k1", 0.5}, {"k2", 0.5}, {"th", 1.0}, {"tau", 0.5}, {"eta", 10.0}, {"speed", 20.0}}, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    const double k1 = 5.0, tau = 0.5;
    double l = -1.5;
    for (int i = 0; i < 50; ++i) {
        const double e = k1 * std::exp(-l * tau);
        l -= (-l * l + e * (1.0 + tau * l)) / (-2.0 * l + e * (tau - tau * (1.0 + tau * l)));
    }
    const double a = tau * k1 * std::exp(-l * tau) - 2.0 * l;
    CHECK(std::abs(r.gains.at("k1") - k1) < tol::design_abscissa_gains);
    CHECK(std::abs(r.gains.at("k2") - (a - k1)) < tol::design_abscissa_gains);
    CHECK(std::abs(r.value - l) < tol::design_abscissa_delay_value);
    CHECK(r.string.plant_verdict == Verdict::Stable);
}

TEST_CASE("design nearest: C_max reaches the closed-form nearest point of its low-frequency condition, and the margin flips across it") {
    // ovrv, th and tau held: mu_0 = c2 / k1^2 >= m^2 is 2 B - m^2 k1 >= 0, linear in (k1, k2):
    // a1 k1 + a2 k2 >= 2, a1 = 2 th (th/2 - tau) - m^2, a2 = 2 (th - tau). In relative changes
    // r_j = (x_j - x0_j)/x0_j the nearest point is r = beta v / |v|^2, v = (a1 k1_0, a2 k2_0),
    // beta = 2 - v1 - v2, distance beta / |v| (when the other pieces of mu are inactive there,
    // which the result's margin confirms).
    const ParameterMap car = car_params("C_max");
    DesignOptions o = options_for(DesignObjective::Nearest);
    const DesignResult r = design_gains("ovrv", car, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    const double th = car.at("th"), tau = car.at("tau"), m2 = o.margin * o.margin;
    const double a1 = 2.0 * th * (th / 2.0 - tau) - m2, a2 = 2.0 * (th - tau);
    const double v1 = a1 * car.at("k1"), v2 = a2 * car.at("k2"), beta = 2.0 - v1 - v2, vv = v1 * v1 + v2 * v2;
    CHECK(r.change == doctest::Approx(beta / std::sqrt(vv)).epsilon(tol::design_nearest_rel));
    CHECK(r.gains.at("k1") == doctest::Approx(car.at("k1") * (1.0 + beta * v1 / vv)).epsilon(tol::design_nearest_rel));
    CHECK(r.gains.at("k2") == doctest::Approx(car.at("k2") * (1.0 + beta * v2 / vv)).epsilon(tol::design_nearest_rel));
    // certified string stable there, with the margin; just before it on the segment, not
    CHECK(r.string.string_verdict == Verdict::Stable);
    CHECK(r.margin_met);
    CHECK(brute_weighted_sup(r.parameters, o.margin) <= 1.0 + tol::attenuation_bound_rel);
    ParameterMap before = r.parameters;
    for (const char* k : {"k1", "k2"}) before[k] = car.at(k) + (1.0 - 1e-4) * (r.gains.at(k) - car.at(k));
    CHECK(brute_weighted_sup(before, o.margin) > 1.0);
    CHECK(r.string_initial.string_verdict == Verdict::Unstable);
}

TEST_CASE("design sup-gamma: where the weighted norm reaches 1 the result is the nearest such gains, and bad options are refused") {
    const ParameterMap car = car_params("C_max");
    DesignOptions o = options_for(DesignObjective::SupGamma);
    const DesignResult s = design_gains("ovrv", car, o);
    o.objective = DesignObjective::Nearest;
    const DesignResult n = design_gains("ovrv", car, o);
    CAPTURE(s.message);
    CHECK(s.status == Status::Converged);
    CHECK(s.value == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(s.gains.at("k1") == doctest::Approx(n.gains.at("k1")).epsilon(1e-9));
    CHECK(s.gains.at("k2") == doctest::Approx(n.gains.at("k2")).epsilon(1e-9));

    DesignOptions bad;
    bad.free = {"k1", "gain"};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
    bad = DesignOptions{};
    bad.bounds = {{"th", 1.0, 2.0}};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);  // th is not free
    bad = DesignOptions{};
    bad.bounds = {{"k1", 0.5, 0.1}};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
    bad = DesignOptions{};
    bad.bounds = {{"k1", -0.5, 0.1}};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);  // outside the law's domain
    bad = DesignOptions{};
    bad.margin = 0.0;
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
    bad = DesignOptions{};
    bad.starts = 0;
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
    bad = DesignOptions{};
    bad.weights = {1.0};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
    bad = DesignOptions{};
    bad.free = {"k1", "k1"};
    CHECK_THROWS_AS(design_gains("ovrv", car, bad), std::invalid_argument);
}

TEST_CASE("design nearest from an unstable plant whose nearest gains lie on a bound: converged, no feasible run end nearer") {
    // k1 = 1 with a 1.5 s delay: the plant is unstable; the relative metric takes tau to its
    // lower bound tau0 / 10, where x0 + 1 (x_end - x0) != x_end in rounding (the crossing test
    // found the run's own end outside the box and fell back to a point three times as far)
    const ParameterMap car = {{"k1", 1.0}, {"k2", 0.1}, {"th", 0.5}, {"tau", 1.5}, {"eta", 10.0}, {"speed", 20.0}};
    DesignOptions o = options_for(DesignObjective::Nearest, 4);
    o.free = {"k1", "k2", "th", "tau"};
    o.margin = 0.001;
    const DesignResult r = design_gains("ovrv", car, o);
    INFO(r.message);
    CHECK(r.status == Status::Converged);
    CHECK(r.margin_met);
    CHECK(r.string.string_stable);
    CHECK(std::find(r.at_bound.begin(), r.at_bound.end(), "tau") != r.at_bound.end());
    // every run that ended meeting the margin (checked here with its own scan) is not nearer
    for (const DesignStart& s : r.starts) {
        ParameterMap p = car;
        double d2 = 0.0;
        for (const auto& [k, v] : s.end) {
            p[k] = v;
            d2 += std::pow((v - car.at(k)) / car.at(k), 2);
        }
        const Linearisation L = make_model("ovrv", p)->linearise();
        if (is_computable(L) && analyse_string(L).plant_stable && attenuation_scan(L).margin >= o.margin) CHECK(r.change <= std::sqrt(d2) * (1.0 + 1e-9));
    }
}

TEST_SUITE_END();
TEST_SUITE_BEGIN("slow");

TEST_CASE("design sup-gamma without string-stable gains (A_min, th < tau): never worse than a brute-force grid, and the proof holds on a grid of certified verdicts") {
    const ParameterMap car = car_params("A_min");
    DesignOptions o = options_for(DesignObjective::SupGamma);
    const DesignResult r = design_gains("ovrv", car, o);
    CAPTURE(r.message);
    CHECK(r.status == Status::Converged);
    CHECK_FALSE(r.infeasibility_proof.empty());
    CHECK_FALSE(r.string.string_stable);
    // the grid: 25 x 25 over the default box [k/10, 10 k], logarithmic, corners included
    double grid_min = 1e300;
    int stable = 0;
    for (int i = 0; i < 25; ++i)
        for (int j = 0; j < 25; ++j) {
            ParameterMap p = car;
            p["k1"] = car.at("k1") * std::pow(10.0, -1.0 + 2.0 * i / 24.0);
            p["k2"] = car.at("k2") * std::pow(10.0, -1.0 + 2.0 * j / 24.0);
            grid_min = std::min(grid_min, brute_weighted_sup(p, o.margin));
            if (i % 3 == 0 && j % 3 == 0) {
                const Linearisation lin = make_model("ovrv", p)->linearise();
                if (analyse_string(lin).string_verdict == Verdict::Stable) ++stable;
            }
        }
    CHECK(r.value <= grid_min + tol::design_grid_abs);
    CHECK(stable == 0);
    // nearest says the same, with the car's own gains unchanged
    o.objective = DesignObjective::Nearest;
    const DesignResult n = design_gains("ovrv", car, o);
    CHECK(n.status == Status::Converged);
    CHECK_FALSE(n.infeasibility_proof.empty());
    CHECK(n.gains.at("k1") == car.at("k1"));
    CHECK(n.gains.at("k2") == car.at("k2"));
}

TEST_CASE("design nearest in three parameters (G_min: k1, k2, th): no point of a smaller sphere about the car meets the margin") {
    const ParameterMap car = car_params("G_min");
    DesignOptions o;
    o.objective = DesignObjective::Nearest;
    o.free = {"k1", "k2", "th"};
    o.starts = 2;
    const DesignResult r = design_gains("ovrv", car, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    CHECK(r.margin_met);
    CHECK(r.string.string_verdict == Verdict::Stable);
    CHECK(brute_weighted_sup(r.parameters, o.margin) <= 1.0 + tol::attenuation_bound_rel);
    // 1500 directions of a Fibonacci sphere at 99.9 % of the distance (relative changes), inside the box
    const double rad = 0.999 * r.change;
    int checked = 0;
    for (int i = 0; i < 1500; ++i) {
        const double z = 1.0 - 2.0 * (i + 0.5) / 1500.0, phi = i * 2.399963229728653, rho = std::sqrt(1.0 - z * z);
        const double d[3] = {rho * std::cos(phi), rho * std::sin(phi), z};
        ParameterMap p = car;
        bool inside = true;
        const char* names[3] = {"k1", "k2", "th"};
        for (int j = 0; j < 3; ++j) {
            p[names[j]] = car.at(names[j]) * (1.0 + rad * d[j]);
            const BoundedParameter* b = find_bound(r.bounds, names[j]);
            if (p[names[j]] < b->lower || p[names[j]] > b->upper) inside = false;
        }
        if (!inside) continue;
        ++checked;
        const Linearisation lin = make_model("ovrv", p)->linearise();
        if (!is_computable(lin)) continue;
        CAPTURE(i);
        CHECK(brute_weighted_sup(p, o.margin) > 1.0);
    }
    CHECK(checked > 300);
}

namespace {
/// A converged peak design whose result is certified peak stable with ||h||_1 = 1 (to its error).
void check_non_overshooting(const DesignResult& r) {
    CAPTURE(r.message);
    CHECK(r.status == Status::Converged);
    REQUIRE(r.string.peak.has_value());
    CHECK(r.string.peak->verdict == Verdict::Stable);
    CHECK(r.value <= 1.0 + r.string.peak->error + 1e-7);
}
}  // namespace

TEST_CASE("design peak: C_max reaches a certified non-overshooting design (||h||_1 = 1)") {
    const DesignResult r = design_gains("ovrv", car_params("C_max"), options_for(DesignObjective::Peak));
    check_non_overshooting(r);
    CHECK(r.string.string_verdict == Verdict::Stable);
}

TEST_CASE("design peak: C_min's starts run in the order of their norm, and the result is the no-overshoot gains walked back toward the car") {
    // The car's own start needs the whole budget (40 gradients of 5 norms) without reaching 1,
    // a Halton start reaches it in a few: run first, it ends the search (83 evaluations before,
    // 47 s). The plateau point it reaches is then walked back along the segment to the car.
    const ParameterMap car = car_params("C_min");
    DesignOptions o = options_for(DesignObjective::Peak, 4);
    const DesignResult r = design_gains("ovrv", car, o);
    check_non_overshooting(r);
    CHECK(r.evaluations < 60);
    // the walk is the last stage: from the plateau point the search reached to the result
    REQUIRE(!r.starts.empty());
    const DesignStart& walk = r.starts.back();
    REQUIRE(walk.message.find("bisection") != std::string::npos);
    CHECK(walk.end == r.gains);
    // the result lies on the segment from the car to that point, nearer the car
    const double dx1 = walk.start.at("k1") - car.at("k1"), dx2 = walk.start.at("k2") - car.at("k2");
    const double t = (r.gains.at("k1") - car.at("k1")) / dx1;
    CHECK(t > 0.0);
    CHECK(t < 1.0);
    CHECK(std::abs(car.at("k2") + t * dx2 - r.gains.at("k2")) <= 1e-12 * std::abs(r.gains.at("k2")));
    // and on the edge of the no-overshoot set: a thousandth of the segment nearer the car, the
    // step response overshoots (an independent call of the string analysis)
    ParameterMap nearer = car;
    nearer["k1"] = car.at("k1") + (t - 1e-3) * dx1;
    nearer["k2"] = car.at("k2") + (t - 1e-3) * dx2;
    StringOptions so;
    so.peak = true;
    const StringResult s = analyse_string(make_model("ovrv", nearer)->linearise(), so);
    REQUIRE(s.peak.has_value());
    CAPTURE(s.peak->norm);
    CHECK(s.peak->verdict == Verdict::Unstable);
    // bounds that exclude the car's own k2: the walk stays inside the box (it stopped outside it)
    DesignOptions ob = o;
    ob.bounds = {{"k2", 1.95, 2.69}};
    const DesignResult rb = design_gains("ovrv", car, ob);
    check_non_overshooting(rb);
    CHECK(rb.gains.at("k2") >= 1.95);
    CHECK(rb.gains.at("k2") <= 2.69);
}

TEST_CASE("design under a fit's uncertainty of the held delay: the probability of string stability against an independent Monte Carlo") {
    // C_max with an uncertain delay (standard deviation 0.05 s, the other held parameters exact);
    // the design sits on the margin's boundary, so part of the delays make it string unstable
    const ParameterMap car = car_params("C_max");
    DesignOptions o = options_for(DesignObjective::Nearest, 1);
    o.has_covariance = true;
    o.covariance(3, 3) = 0.05 * 0.05;
    o.covariance(0, 0) = 1e-6;  // k1 is free: its variance must be ignored
    const DesignResult r = design_gains("ovrv", car, o);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(r.has_uncertainty);
    const double p = 1.0 - r.uncertainty.string_unstable.p;
    CHECK(r.uncertainty_initial.string_unstable.p == 1.0);  // the car itself: unstable for every delay drawn
    CHECK(p > 0.05);
    CHECK(p < 0.95);
    // independent: delays drawn here, the design's gains, the certified verdict of each
    std::mt19937_64 rng(99);
    std::normal_distribution<double> tau(car.at("tau"), 0.05);
    int stable = 0, n = 0;
    while (n < 2000) {
        const double t = tau(rng);
        if (t < 0.0 || t > 1.0) continue;  // calibrate's bounds on tau, as classify's domain
        ParameterMap q = r.parameters;
        q["tau"] = t;
        ++n;
        if (analyse_string(make_model("ovrv", q)->linearise()).string_verdict == Verdict::Stable) ++stable;
    }
    const double pm = static_cast<double>(stable) / n;
    const double se = std::sqrt(p * (1.0 - p) / r.uncertainty.samples + pm * (1.0 - pm) / n);
    CAPTURE(p);
    CAPTURE(pm);
    CHECK(std::abs(p - pm) <= 4.0 * se);
}

namespace {
/// m* of an OVRV car, by a second path: the scan itself (the plant checked stable by its roots)
double margin_of(const ParameterMap& p) {
    const Linearisation L = make_model("ovrv", p)->linearise();
    RootOptions ro;
    ro.count = 2;
    const RootResult rr = rightmost_roots(plant_dde(L), ro);
    REQUIRE(rr.status == Status::Converged);
    if (!(rr.roots.front().value.real() < 0.0)) return -std::numeric_limits<double>::infinity();
    return attenuation_scan(L).margin;
}
}  // namespace

TEST_CASE("worst attenuation margin over the ellipsoid: one held parameter, at an end of its interval") {
    // tau alone held: the interval tau0 -+ 1.96 sd, whose ends are the ellipsoid's boundary
    const ParameterMap p{{"k1", 0.05}, {"k2", 0.6}, {"th", 2.0}, {"tau", 0.2}, {"eta", 10.0}};
    Eigen::Matrix<double, 5, 5> C = Eigen::Matrix<double, 5, 5>::Zero();
    C(3, 3) = 0.03 * 0.03;
    const WorstMargin w = worst_attenuation_margin(p, C);
    REQUIRE(w.held == std::vector<std::string>{"tau"});
    ParameterMap hi = p, lo = p;
    hi["tau"] = 0.2 + std::sqrt(3.841458820694124) * 0.03;
    lo["tau"] = 0.2 - std::sqrt(3.841458820694124) * 0.03;
    const double m_hi = margin_of(hi), m_lo = margin_of(lo);
    CHECK(w.margin == doctest::Approx(std::min(m_hi, m_lo)).epsilon(1e-12));
    CHECK(w.at.at("tau") == doctest::Approx(m_hi < m_lo ? hi.at("tau") : lo.at("tau")).epsilon(1e-12));
    CHECK(w.nominal == doctest::Approx(margin_of(p)).epsilon(1e-12));
    CHECK(w.margin <= w.nominal);
}

TEST_CASE("worst attenuation margin over the ellipsoid: never above what sampling the ellipsoid finds") {
    // th and tau held with a correlated covariance; 600 points sampled on the boundary and in the
    // interior of the 95 % ellipse (an independent search) never find a smaller m* than the
    // reported one (to the scan's resolution), and the reported point is in the ellipse
    const ParameterMap p{{"k1", 0.05}, {"k2", 0.6}, {"th", 2.0}, {"tau", 0.2}, {"eta", 10.0}};
    Eigen::Matrix<double, 5, 5> C = Eigen::Matrix<double, 5, 5>::Zero();
    C(2, 2) = 0.15 * 0.15;
    C(3, 3) = 0.04 * 0.04;
    C(2, 3) = C(3, 2) = 0.6 * 0.15 * 0.04;
    const WorstMargin w = worst_attenuation_margin(p, C);
    REQUIRE(w.held.size() == 2);
    CHECK(std::isfinite(w.margin));
    CHECK(w.margin == doctest::Approx(margin_of([&] {
                                           ParameterMap q = p;
                                           q["th"] = w.at.at("th");
                                           q["tau"] = w.at.at("tau");
                                           return q;
                                       }()))
                          .epsilon(1e-12));
    Eigen::Matrix2d Ch;
    Ch << C(2, 2), C(2, 3), C(3, 2), C(3, 3);
    Eigen::Vector2d dp(w.at.at("th") - 2.0, w.at.at("tau") - 0.2);
    CHECK(dp.dot(Ch.inverse() * dp) <= 5.991464547107979 * (1 + 1e-9));
    const Eigen::Matrix2d Lc = Ch.llt().matrixL();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double sampled = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 600; ++k) {
        const double t = 2.0 * M_PI * u(rng), s = k < 300 ? 1.0 : std::sqrt(u(rng));  // boundary, then uniform in the ellipse
        const Eigen::Vector2d d = s * std::sqrt(5.991464547107979) * (Lc * Eigen::Vector2d(std::cos(t), std::sin(t)));
        ParameterMap q = p;
        q["th"] = 2.0 + d[0];
        q["tau"] = std::max(0.0, 0.2 + d[1]);
        sampled = std::min(sampled, margin_of(q));
    }
    MESSAGE("worst m* reported " << w.margin << " s (" << w.evaluations << " evaluations), sampled " << sampled << " s, nominal " << w.nominal << " s");
    CHECK(w.margin <= sampled + test::tol::worst_margin_vs_sampling);
}

namespace {
/// The robust cases' car: like the paper's, with a fit's uncertainty on th and tau (correlated).
ParameterMap robust_case_car() { return {{"k1", 0.05}, {"k2", 0.3}, {"th", 1.5}, {"tau", 0.4}, {"eta", 10.0}, {"speed", 20.0}}; }
/// Nearest gains with a margin of 0.1 s, the covariance of th and tau (sd 0.1 s and 0.05 s, correlation 0.5).
DesignOptions robust_case_options() {
    DesignOptions o;
    o.objective = DesignObjective::Nearest;
    o.margin = 0.1;
    o.starts = 2;
    o.has_covariance = true;
    o.covariance(2, 2) = 0.1 * 0.1;
    o.covariance(3, 3) = 0.05 * 0.05;
    o.covariance(2, 3) = o.covariance(3, 2) = 0.5 * 0.1 * 0.05;
    return o;
}
}  // namespace

TEST_CASE("robust design: the margin holds over the fit's ellipsoid (checked by sampling it) and the nominal design's does not") {
    // a car like the paper's with a fit's uncertainty on th and tau (correlated); nearest gains
    // with a margin of 0.1 s for the car's own th, tau, and robustly for every th, tau of the 95 %
    // ellipse. 600 sampled points of the ellipse (an independent search) never find a margin below
    // the asked one at the robust gains; at the nominal gains the worst point is below it.
    const ParameterMap p = robust_case_car();
    DesignOptions o = robust_case_options();
    o.uncertainty_samples = 200;
    const DesignResult nominal = design_gains("ovrv", p, o);
    REQUIRE(nominal.status == Status::Converged);
    CHECK(nominal.worst.margin < o.margin);  // the nominal design is not robust
    o.robust = true;
    const DesignResult r = design_gains("ovrv", p, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    CHECK(r.robust);
    CHECK(r.robust_met);
    CHECK(r.robust_steps.size() >= 2);
    CHECK(r.worst.margin >= o.margin * (1.0 - 1e-6));
    CHECK(r.change > nominal.change);  // robustness costs a larger change
    Eigen::Matrix2d Ch;
    Ch << o.covariance(2, 2), o.covariance(2, 3), o.covariance(3, 2), o.covariance(3, 3);
    const Eigen::Matrix2d Lc = Ch.llt().matrixL();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    double sampled = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 600; ++k) {
        const double t = 2.0 * M_PI * u(rng), s = k < 300 ? 1.0 : std::sqrt(u(rng));
        const Eigen::Vector2d d = s * std::sqrt(5.991464547107979) * (Lc * Eigen::Vector2d(std::cos(t), std::sin(t)));
        ParameterMap q = r.parameters;
        q["th"] = 1.5 + d[0];
        q["tau"] = std::max(0.0, 0.4 + d[1]);
        sampled = std::min(sampled, margin_of(q));
    }
    MESSAGE("robust design: change " << r.change << " (nominal " << nominal.change << "), worst margin reported " << r.worst.margin << " s, sampled " << sampled
                                     << " s, nominal design's worst " << nominal.worst.margin << " s, " << r.robust_steps.size() << " designs");
    CHECK(sampled >= o.margin - test::tol::worst_margin_vs_sampling);
    // robust without a covariance is refused
    DesignOptions bad = o;
    bad.has_covariance = false;
    CHECK_THROWS_AS(design_gains("ovrv", p, bad), std::invalid_argument);
}

namespace {
/// Robust design with two uncertain held parameters (indices i, j of k1, k2, th, tau, eta; standard
/// deviations si, sj; correlation rho) and 50 draws for the probabilities.
void set_robust(DesignOptions& o, int i, double si, int j, double sj, double rho) {
    o.has_covariance = true;
    o.covariance(i, i) = si * si;
    o.covariance(j, j) = sj * sj;
    o.covariance(i, j) = o.covariance(j, i) = rho * si * sj;
    o.uncertainty_samples = 50;
    o.robust = true;
}
}  // namespace

TEST_CASE("robust design designs for every worst point met so far at once: the result meets the margin at each, and over the ellipse by sampling") {
    // E_max with k2 and th designed and an uncertain k1 and tau held (sd 20 % and 10 %,
    // correlation -0.3): five designs. The exchange method asks each design for the margin at
    // the car's own held values and at every earlier worst point, so the result meets it at all
    // of them (checked here directly), and sampling the ellipse finds no point below it.
    const ParameterMap p = car_params("E_max");
    const double s1 = 0.2 * p.at("k1"), s4 = 0.1 * p.at("tau");
    DesignOptions o = options_for(DesignObjective::Nearest);
    o.free = {"k2", "th"};
    set_robust(o, 0, s1, 3, s4, -0.3);
    const DesignResult r = design_gains("ovrv", p, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    CHECK(r.robust_met);
    REQUIRE(r.robust_steps.size() >= 4);
    for (const DesignResult::RobustStep& st : r.robust_steps) {
        ParameterMap q = r.parameters;
        for (const auto& [k, v] : st.scenario) q[k] = v;
        CAPTURE(st.worst_margin);
        CHECK(margin_of(q) >= o.margin * (1.0 - 1e-6));
    }
    Eigen::Matrix2d C;
    C << s1 * s1, -0.3 * s1 * s4, -0.3 * s1 * s4, s4 * s4;
    const Eigen::Matrix2d Lc = C.llt().matrixL();
    double sampled = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 96; ++k) {
        const double t = 2.0 * M_PI * k / 96.0;
        const Eigen::Vector2d d = std::sqrt(5.991464547107979) * (Lc * Eigen::Vector2d(std::cos(t), std::sin(t)));
        ParameterMap q = r.parameters;
        q["k1"] = p.at("k1") + d[0];
        q["tau"] = p.at("tau") + d[1];
        sampled = std::min(sampled, margin_of(q));
    }
    MESSAGE("exchange method: " << r.robust_steps.size() << " designs, change " << r.change << ", least margin on 96 points of the ellipse " << sampled << " s");
    CHECK(sampled >= o.margin - test::tol::worst_margin_vs_sampling);
}

TEST_CASE("robust design where a point of the ellipse has no string-stable gains in the box: decided, with the proof at that point") {
    // F_max with 5 % on th and 10 % on tau (correlation 0.5): the nominal design's worst point
    // has th - tau too small for any (k1, k2) of the box. The iteration used to stop there
    // undecided (max_iterations, 'not a robust design'); the proof at that point decides it.
    const ParameterMap p = car_params("F_max");
    const double sth = 0.05 * p.at("th"), stau = 0.1 * p.at("tau");
    for (DesignObjective objective : {DesignObjective::Nearest, DesignObjective::SupGamma}) {
        DesignOptions o = options_for(objective);
        set_robust(o, 2, sth, 3, stau, 0.5);
        const DesignResult r = design_gains("ovrv", p, o);
        CAPTURE(r.message);
        CHECK(r.status == Status::Converged);
        CHECK_FALSE(r.robust_met);
        CHECK(!r.infeasibility_proof.empty());
        REQUIRE(r.robust_steps.size() >= 2);
        CHECK(r.message.find("no robust design within the bounds") == 0);
        // independently: the point lies in the ellipse, and B < 0 at every corner of the box there
        const ParameterMap& at = r.robust_steps.back().scenario;
        const double dth = at.at("th") - p.at("th"), dtau = at.at("tau") - p.at("tau");
        Eigen::Matrix2d C;
        C << sth * sth, 0.5 * sth * stau, 0.5 * sth * stau, stau * stau;
        const Eigen::Vector2d d(dth, dtau);
        CHECK(d.dot(C.inverse() * d) <= 5.991464547107979 * (1.0 + 1e-9));
        const double th = at.at("th"), tau = at.at("tau");
        for (double k1 : {0.1 * p.at("k1"), 10.0 * p.at("k1")})
            for (double k2 : {0.1 * p.at("k2"), 10.0 * p.at("k2")}) CHECK(k1 * th * (th / 2.0 - tau) + k2 * (th - tau) - 1.0 < 0.0);
    }
}

TEST_CASE("robust design is the least change: every gain pair nearer the car fails the margin somewhere in the ellipse") {
    // The relaxation argument: the last design is the nearest gains meeting the margin at a few
    // points of the ellipse (the car's own held values and the worst points met; a relaxation of
    // the robust problem, whose least change can only be smaller); when those gains meet it over
    // the whole ellipse they are the robust problem's nearest too. Checked directly: on a circle
    // of 0.98 times the robust change about the car (in the relative metric of k1, k2), each of
    // 72 gain pairs inside the design's box has a margin below 0.1 s at one of those points or at
    // one of 48 points of the ellipse's boundary.
    const ParameterMap p = robust_case_car();
    DesignOptions o = robust_case_options();
    o.uncertainty_samples = 50;
    o.robust = true;
    const DesignResult r = design_gains("ovrv", p, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(r.robust_met);
    Eigen::Matrix2d Ch;
    Ch << o.covariance(2, 2), o.covariance(2, 3), o.covariance(3, 2), o.covariance(3, 3);
    const Eigen::Matrix2d Lc = Ch.llt().matrixL();
    // the least margin of gains q over 48 points of the ellipse's boundary
    auto ellipse_worst = [&](const ParameterMap& q) {
        double worst = std::numeric_limits<double>::infinity();
        for (int j = 0; j < 48; ++j) {
            const double t = 2.0 * M_PI * j / 48;
            const Eigen::Vector2d d = std::sqrt(5.991464547107979) * (Lc * Eigen::Vector2d(std::cos(t), std::sin(t)));
            ParameterMap s = q;
            s["th"] = 1.5 + d[0];
            s["tau"] = std::max(0.0, 0.4 + d[1]);
            worst = std::min(worst, margin_of(s));
        }
        return worst;
    };
    int failing = 0, outside = 0;
    const int n = 72;
    for (int i = 0; i < n; ++i) {
        const double a = 2.0 * M_PI * i / n;
        ParameterMap q = p;
        q["k1"] = p.at("k1") * (1.0 + 0.98 * r.change * std::cos(a));
        q["k2"] = p.at("k2") * (1.0 + 0.98 * r.change * std::sin(a));
        // the design searched the box [x0 / 10, 10 x0]: pairs outside it are not candidates
        bool in_box = true;
        for (const char* k : {"k1", "k2"}) in_box = in_box && q.at(k) >= p.at(k) / 10.0 && q.at(k) <= 10.0 * p.at(k);
        if (!in_box) {
            ++outside;
            continue;
        }
        double worst = std::numeric_limits<double>::infinity();
        for (const DesignResult::RobustStep& st : r.robust_steps) {  // the points the last design was made for
            ParameterMap s = q;
            for (const auto& [k, v] : st.scenario) s[k] = v;
            worst = std::min(worst, margin_of(s));
        }
        if (worst >= o.margin) worst = std::min(worst, ellipse_worst(q));
        failing += worst < o.margin ? 1 : 0;
    }
    // and the check can tell: 5 % beyond the design, on the ray from the car through it, the
    // margin holds at p and at every point of the ellipse's boundary
    {
        ParameterMap q = p;
        for (const char* k : {"k1", "k2"}) q[k] = p.at(k) + 1.05 * (r.parameters.at(k) - p.at(k));
        CHECK(ellipse_worst(q) >= o.margin);
    }
    MESSAGE("robust change " << r.change << "; " << failing << " of " << n - outside << " gain pairs inside the box fail the margin");
    CHECK(n - outside >= 20);
    CHECK(failing == n - outside);
}

TEST_CASE("design abscissa with a delay: the value is the plant's rightmost root, a nearly double one at the optimum") {
    // D = l^2 + (k1 th + k2) l + k1 e^{-l tau}, th = 1, tau = 0.5: the minimiser drives the two
    // rightmost roots together; the value once skipped that pair (-10.73 reported, -0.859 true).
    DesignOptions o;
    o.objective = DesignObjective::Abscissa;
    o.starts = 2;
    const DesignResult r = design_gains("ovrv", {{"k1", 0.1}, {"k2", 0.3}, {"th", 1.0}, {"tau", 0.5}, {"eta", 5.0}, {"speed", 20.0}}, o);
    CAPTURE(r.message);
    REQUIRE(r.status == Status::Converged);
    const double a = r.gains.at("k1") * 1.0 + r.gains.at("k2"), b = r.gains.at("k1"), tau = 0.5;
    const auto D = [&](cplx l) { return l * l + a * l + b * std::exp(-l * tau); };
    // no root right of the value (|l| <= 10 bounds every root with Re >= -1), two within 1e-3 left of it
    CHECK(test::zeros_in_rectangle(D, r.value + 1e-3, 5.0, -10.0, 10.0, 100000) == 0);
    CHECK(test::zeros_in_rectangle(D, r.value - 1e-3, 5.0, -10.0, 10.0, 100000) == 2);
    CHECK(r.value < r.value_initial);
}

TEST_CASE("design: every run's path starts at its start and ends at its end, and the figure draws the winning run's") {
    DesignOptions o;
    o.objective = DesignObjective::Nearest;
    o.starts = 2;
    const ParameterMap car{{"k1", 0.018}, {"k2", 0.152}, {"th", 1.986}, {"tau", 0.324}, {"eta", 13.81}, {"speed", 20.0}};
    const DesignResult r = design_gains("ovrv", car, o);
    REQUIRE(r.status == Status::Converged);
    REQUIRE(!r.starts.empty());
    for (const DesignStart& st : r.starts) {
        REQUIRE(st.path.size() >= 2);
        CHECK(st.path.front() == st.start);
        CHECK(st.path.back() == st.end);
    }
    const std::string svg = design_chart_svg(r, "C_max", 22, nullptr, ExecutionPolicy{});
    CHECK(svg.find("-path\"") != std::string::npos);
    CHECK(svg.find("the minimiser") != std::string::npos);  // the legend entry
}
