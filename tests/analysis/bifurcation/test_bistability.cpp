// The bistability chart (bistability_chart) of the optimal-velocity ring of 3 cars in (headway,
// tau), checked by simulation: where it says bistable, a small disturbance of the uniform flow
// dies out and a large one ends on a sustained wave; where it says the uniform flow is the only
// attractor, the same large disturbance dies out.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

#include "analysis/bifurcation/dde_simulation.hpp"
#include "analysis/bifurcation/ov_ring_branch.hpp"
#include "ddemap/analysis/bifurcation/bistability.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/ov_ring.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::range;
using ddemap::test::simulate;
namespace tol = ddemap::test::tol;

namespace {

/// The box of the charts: headway 1.2 to 3, tau 0.3 to 2.
BistabilityOptions ov3_chart_options() {
    BistabilityOptions o;
    o.parameter = "headway";
    o.from = 1.2;
    o.to = 3.0;
    o.parameter2 = "tau";
    o.from2 = 0.3;
    o.to2 = 2.0;
    return o;
}

/// The cell whose interval on the line nearest p2 holds p1.
const BistabilityCell* cell_at(const BistabilityChart& c, double p1, double p2) {
    const BistabilityCell* best = nullptr;
    double dist = 1e300;
    for (const BistabilityCell& k : c.cells)
        for (const auto& iv : k.intervals)
            if (iv.lo <= p1 && p1 <= iv.hi && std::abs(iv.par2 - p2) < dist) {
                dist = std::abs(iv.par2 - p2);
                best = &k;
            }
    return best;
}

}  // namespace

TEST_CASE("bistability chart of the ov ring (N = 3) in (headway, tau): its verdicts against simulations from two initial states" *
          doctest::test_suite("slow")) {
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    BistabilityOptions o = ov3_chart_options();
    const BistabilityChart chart = bistability_chart(ring, ring.uniform_flow(), o);
    REQUIRE(chart.status == Status::Converged);
    CHECK(ring.parameter_values()[static_cast<std::size_t>(ring.parameter_index("tau"))] == 1.0);  // restored
    CHECK(chart.folds.size() == 3);
    std::size_t gh = 0;
    for (const HopfCurve& c : chart.hopf.curves) gh += c.generalised.size();
    CHECK(gh == 3);
    // at tau = 1 the branch in the headway has its Hopf points at 1.3629 and 2.4885 and its folds of
    // orbits at 1.2849 and 2.6846 (test_periodic_orbit.cpp): bistable between each pair
    const BistabilityCell* b = cell_at(chart, 2.6, 1.0);
    const BistabilityCell* n = cell_at(chart, 2.9, 1.0);
    const BistabilityCell* u = cell_at(chart, 2.0, 1.0);
    const BistabilityCell* l = cell_at(chart, 1.32, 1.0);
    REQUIRE(b);
    REQUIRE(n);
    REQUIRE(u);
    REQUIRE(l);
    CHECK(b->bistable);
    CHECK(l->bistable);
    CHECK(!n->bistable);
    CHECK(n->equilibrium_stable);
    CHECK(!n->stable_orbit);
    CHECK(!u->equilibrium_stable);
    CHECK(b != n);
    // the stable large wave at tau = 1 near headway 2.6, from the branch of orbits
    const OrbitBranch br = ddemap::test::ov3_headway_branch(1.0);
    const PeriodicOrbit* wave = nullptr;
    for (const PeriodicOrbit& p : br.points)
        if (p.stable && (!wave || std::abs(p.par - 2.6) < std::abs(wave->par - 2.6))) wave = &p;
    REQUIRE(wave);
    REQUIRE(std::abs(wave->par - 2.6) < 0.05);
    const PeriodicMesh mesh(br.degree, wave->breakpoints);
    const double amp = wave->max[0] - wave->min[0];
    for (const double headway : {2.6, 2.9}) {
        CAPTURE(headway);
        OvRing r(3, 1.0, 1.0, 1.0, 1.0, headway);
        const Eigen::VectorXd xs = r.uniform_flow();
        // the wave's profile shifted onto this headway's uniform flow (the gaps' mean moved)
        const Eigen::VectorXd shift = xs - OvRing(3, 1.0, 1.0, 1.0, 1.0, wave->par).uniform_flow();
        const DdeSolver large = simulate(r, [&](double t, double* y) {
            const Eigen::VectorXd x = orbit_value(mesh, wave->profile, t / wave->period) + shift;
            for (Eigen::Index i = 0; i < x.size(); ++i) y[i] = x(i);
        }, 1500.0, 0.02);
        const DdeSolver small = simulate(r, [&](double t, double* y) {
            const Eigen::VectorXd x = xs + 0.05 * (orbit_value(mesh, wave->profile, t / wave->period) - OvRing(3, 1.0, 1.0, 1.0, 1.0, wave->par).uniform_flow());
            for (Eigen::Index i = 0; i < x.size(); ++i) y[i] = x(i);
        }, 1500.0, 0.02);
        const double large_end = range(large, 0, 1200.0, 1500.0, 0.1), small_end = range(small, 0, 1200.0, 1500.0, 0.1);
        CAPTURE(large_end);
        CAPTURE(small_end);
        CHECK(small_end < 1e-3 * amp);  // the uniform flow is stable at both
        if (headway == 2.6) CHECK(large_end > 0.5 * amp);  // bistable: the large disturbance ends on a wave
        else CHECK(large_end < 1e-3 * amp);                 // beyond the fold: it dies out
    }
}

namespace {

/// z' = (p1 + i) z + b (z(t - tau) - z) + (p2 + i) z |z|^2 - z |z|^4 (z = x1 + i x2): it commutes
/// with z -> e^{i s} z, so its periodic orbits are rotating waves z = r e^{i Omega t}, exactly, with
/// (s = r^2)  Omega = 1 + s - b sin(Omega tau),  p1 = b - b cos(Omega tau) - p2 s + s^2.
/// The Hopf curve is the line p1 = p1(0) (s = 0); dp1/ds = b tau sin(Omega tau) / (1 + b tau
/// cos(Omega tau)) - p2 + 2 s, so the generalised Hopf point is at p2* = that ratio at s = 0, and for
/// p2 > p2* the waves turn at the fold dp1/ds = 0: stable large waves and the stable z = 0 coexist for
/// p1 between the fold and the Hopf line.
struct RotatingFold {
    double b = 0.5, tau = 1.0;
    ExpressionSystem system(double p2) const {
        return ExpressionSystem({"x1", "x2"}, {"p1", "p2", "b", "tau"}, {0.0, p2, b, tau},
                                {"p1*x1 - x2 + b*(x1(t - tau) - x1) + (x1^2 + x2^2)*(p2*x1 - x2) - (x1^2 + x2^2)^2*x1",
                                 "p1*x2 + x1 + b*(x2(t - tau) - x2) + (x1^2 + x2^2)*(p2*x2 + x1) - (x1^2 + x2^2)^2*x2"});
    }
    double omega(double s) const {
        double w = 1.0 + s;
        for (int it = 0; it < 100; ++it) w -= (w - 1.0 - s + b * std::sin(w * tau)) / (1.0 + b * tau * std::cos(w * tau));
        return w;
    }
    double p1(double s, double p2) const { return b - b * std::cos(omega(s) * tau) - p2 * s + s * s; }
    double slope(double s, double p2) const {
        const double w = omega(s);
        return b * tau * std::sin(w * tau) / (1.0 + b * tau * std::cos(w * tau)) - p2 + 2.0 * s;
    }
    double p2_star() const { return slope(0.0, 0.0); }
    /// s at the fold for p2 > p2* (bisection on the slope, negative at s = 0, positive at s = p2)
    double fold_s(double p2) const {
        double lo = 0.0, hi = std::max(1.0, p2);
        for (int it = 0; it < 200; ++it) {
            const double m = 0.5 * (lo + hi);
            (slope(m, p2) < 0.0 ? lo : hi) = m;
        }
        return 0.5 * (lo + hi);
    }
};

}  // namespace

TEST_CASE("bistability chart: the fold curve born at a generalised Hopf point that no slice meets, against exact rotating waves" *
          doctest::timeout(120)) {
    // The chart's first slices (at the held p2 = -0.3 and at the bottom row) lie below the
    // generalised Hopf point, where the Hopf bifurcation is supercritical and no orbit branch
    // folds: the bistable band above it is found only from the generalised Hopf point itself.
    const RotatingFold w;
    ExpressionSystem sys = w.system(-0.3);
    BistabilityOptions o;
    o.parameter = "p1";
    o.from = -0.2;
    o.to = 0.4;
    o.parameter2 = "p2";
    o.from2 = -0.5;
    o.to2 = 1.0;
    o.rows = 60;
    const BistabilityChart chart = bistability_chart(sys, Eigen::VectorXd::Zero(2), o);
    MESSAGE(chart.message);
    REQUIRE(chart.status == Status::Converged);
    const double p1h = w.p1(0.0, 0.0), p2s = w.p2_star();
    // the generalised Hopf point on the Hopf line
    int gh = 0;
    for (const HopfCurve& c : chart.hopf.curves)
        for (const GeneralisedHopfPoint& g : c.generalised) {
            ++gh;
            CHECK(std::abs(g.par - p1h) < 1e-9);
            CHECK(std::abs(g.par2 - p2s) < 1e-9);
            CHECK(g.normal_form.l2 < 0.0);  // the large waves are stable: a fold curve on the side p2 > p2*
        }
    CHECK(gh == 1);
    // one fold curve, from the generalised Hopf point to the top face, on the exact folds
    REQUIRE(chart.folds.size() == 1);
    const OrbitFoldCurve& f = chart.folds[0];
    CHECK(((f.stop_backward == "hopf" && f.stop_forward == "bound") || (f.stop_backward == "bound" && f.stop_forward == "hopf")));
    double worst = 0.0, worst_period = 0.0, top = -1.0, bottom = 2.0;
    for (const OrbitFoldCurvePoint& q : f.points) {
        const double s = w.fold_s(q.par2);
        worst = std::max(worst, std::abs(q.par - w.p1(s, q.par2)));
        worst_period = std::max(worst_period, std::abs(q.orbit.period - 2.0 * M_PI / w.omega(s)) / q.orbit.period);
        top = std::max(top, q.par2);
        bottom = std::min(bottom, q.par2);
    }
    MESSAGE("fold curve: " << f.points.size() << " points, p2 in [" << bottom << ", " << top << "], max |p1 - exact| = " << worst
                           << ", period " << worst_period);
    CHECK(worst < tol::fold_curve_exact_waves);
    CHECK(worst_period < tol::fold_curve_exact_waves_period);
    CHECK(std::abs(top - o.to2) < 1e-12);
    // its end at the generalised Hopf point: p2 - p2* is O(a^2) at the last orbit's amplitude a
    // (the curve ends below 2 % of its largest, 1.2: a < 0.024)
    CHECK(bottom >= p2s - 1e-9);
    CHECK(bottom - p2s < 1e-3);
    // the cells: bistable between the fold and the Hopf line above p2*, nowhere else
    for (double p2 : {0.5, 0.8}) {
        const double pf = w.p1(w.fold_s(p2), p2);
        const BistabilityCell* band = cell_at(chart, 0.5 * (pf + p1h), p2);
        const BistabilityCell* left = cell_at(chart, 0.5 * (pf + o.from), p2);
        const BistabilityCell* right = cell_at(chart, 0.5 * (p1h + o.to), p2);
        REQUIRE(band);
        REQUIRE(left);
        REQUIRE(right);
        CHECK(band->bistable);
        CHECK(left->equilibrium_stable);
        CHECK(!left->stable_orbit);
        CHECK(!right->equilibrium_stable);
        CHECK(right->stable_orbit);
    }
    for (const BistabilityCell& c : chart.cells)
        if (c.bistable)
            for (const auto& iv : c.intervals) {
                CHECK(iv.par2 > p2s);
                CHECK(iv.hi <= p1h + 1e-9);
            }
}

TEST_CASE("bistability figure: a bistable cell too thin to shade is marked B, a wide one is not") {
    BistabilityChart chart;
    chart.parameter = "k2";
    chart.parameter2 = "tau";
    chart.from = 0.2, chart.to = 1.2, chart.from2 = 0.3, chart.to2 = 1.0;
    BistabilityCell thin;
    thin.intervals = {{0.55, 0.4650, 0.4656}, {0.56, 0.4690, 0.4697}};  // 7e-4 wide: below 0.5 % of the box
    thin.par = 0.4653, thin.par2 = 0.55;
    thin.equilibrium_stable = thin.stable_orbit = thin.bistable = true;
    BistabilityCell wide = thin;
    wide.intervals = {{0.8, 0.6, 0.9}};
    wide.par = 0.75, wide.par2 = 0.8;
    chart.cells = {wide};
    const std::string without = bistability_svg(chart, "1/s", "s", "wide only");
    CHECK(without.find(">B<") == std::string::npos);
    CHECK(without.find("too thin") == std::string::npos);
    chart.cells.push_back(thin);
    const std::string with = bistability_svg(chart, "1/s", "s", "wide and thin");
    CHECK(with.find(">B<") != std::string::npos);
    CHECK(with.find("too thin to see") != std::string::npos);
}

TEST_CASE("bistability options: bad input is std::invalid_argument, and the system's parameter is left as it was") {
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    BistabilityOptions o = ov3_chart_options();
    o.parameter2 = "headway";
    CHECK_THROWS_AS(bistability_chart(ring, ring.uniform_flow(), o), std::invalid_argument);
    o.parameter2 = "tau";
    o.rows = 2;
    CHECK_THROWS_AS(bistability_chart(ring, ring.uniform_flow(), o), std::invalid_argument);
    o.rows = 200;
    o.from2 = 1.5;  // tau = 1 outside [1.5, 2]
    CHECK_THROWS_AS(bistability_chart(ring, ring.uniform_flow(), o), std::invalid_argument);
    o.from2 = 0.3;
    o.parameter2 = "no_such";
    CHECK_THROWS_AS(bistability_chart(ring, ring.uniform_flow(), o), std::invalid_argument);
    CHECK(ring.parameter_values()[static_cast<std::size_t>(ring.parameter_index("tau"))] == 1.0);
}

TEST_SUITE_END();
