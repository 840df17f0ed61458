#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <vector>

#include "tolerances.hpp"
#include "analysis/bifurcation/dde_simulation.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/ov_ring.hpp"
#include "numeric_helpers.hpp"
#include "analysis/bifurcation/ov_ring_branch.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;
using ddemap::test::crossings;
using ddemap::test::range;
using ddemap::test::simulate;

namespace {

using ddemap::test::pi;

/// The Hopf point of y' = -a y(t - 1) (g(y) y(t - 1) terms alike) at y = 0: a = omega = pi/2, q = 1.
HopfPoint scalar_hopf() {
    HopfPoint h;
    h.par = pi / 2;
    h.omega = pi / 2;
    h.x = Eigen::VectorXd::Zero(1);
    h.q = VectorXc::Constant(1, cplx(1.0, 0.0));
    h.status = Status::Converged;
    return h;
}

ExpressionSystem wright(double alpha = 1.6) { return ExpressionSystem({"y"}, {"alpha"}, {alpha}, {"-alpha*y(t - 1)*(1 + y)"}); }

PeriodicOrbitOptions options(const std::string& par, double from, double to, int points, int intervals = 40) {
    PeriodicOrbitOptions o;
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.max_points = points;
    o.intervals = intervals;
    return o;
}

/// The subcritical Hopf point of the ov ring (N = 5, alpha = tau = v0 = h_st = 1) at the upper end of
/// the unstable headways, mode k = 1 (Orosz, Wilson, Stepan 2004: the ring mode formula of
/// test_equilibrium_branch.cpp), corrected by Newton from a rough guess.
HopfPoint ov_hopf(OvRing& ring) {
    ring.set_parameter("headway", 2.6);
    const HopfPoint h = correct_hopf(ring, ring.parameter_index("headway"), ring.uniform_flow(), 2.6, 0.32);
    REQUIRE(h.status == Status::Converged);
    ring.set_parameter("headway", h.par);
    return h;
}

/// Mackey-Glass x' = beta x(t - tau) / (1 + x(t - tau)^n) - gamma x with beta = 2, gamma = 1,
/// n = 9.65 (tau = 0.3): equilibrium x = 1, a supercritical Hopf point in tau, then the period
/// doubling cascade of the stable orbit (Mackey and Glass 1977).
ExpressionSystem mackey_glass() {
    return ExpressionSystem({"x"}, {"beta", "gamma", "n", "tau"}, {2.0, 1.0, 9.65, 0.3}, {"beta*x(t - tau)/(1 + x(t - tau)^n) - gamma*x"});
}

/// Its branch of orbits from the Hopf point, tau in [0.3, 2] (200 orbits at most).
OrbitBranch mackey_glass_branch(const ExpressionSystem& mg) {
    EquilibriumBranchOptions eo;
    eo.parameter = "tau";
    eo.from = 0.3;
    eo.to = 2.0;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(mg, Eigen::VectorXd::Constant(1, 1.0), eo);
    REQUIRE(!eq.hopf.empty());
    return orbit_branch_from_hopf(mg, eq.hopf.front(), options("tau", 0.3, 2.0, 200));
}

/// The simulated orbit of Mackey-Glass at `tau` (from x = 0.5, transients over [0, 2500] left
/// out): the period (the shortest lag after which the sequence of local maxima of x repeats to
/// 1e-3, times the mean time per maximum) and the largest maximum. Period 0 when nothing repeats.
struct SimulatedOrbit {
    double period = 0.0, max = 0.0;
    std::size_t maxima_per_period = 0;
};

SimulatedOrbit mackey_glass_orbit(ExpressionSystem& mg, double tau) {
    mg.set_parameter("tau", tau);
    const DdeSolver s = simulate(mg, [](double, double* y) { y[0] = 0.5; }, 3000.0, 0.005);
    std::vector<double> m, when;
    double prev2 = s.value(0, 2500.0 - 0.01), prev = s.value(0, 2500.0);
    for (double t = 2500.0 + 0.01; t <= 3000.0; t += 0.01) {
        const double x = s.value(0, t);
        if (prev > prev2 && prev >= x) {
            m.push_back(prev);
            when.push_back(t - 0.01);
        }
        prev2 = prev;
        prev = x;
    }
    SimulatedOrbit r;
    for (std::size_t lag = 1; lag < 16 && 2 * lag < m.size() && r.period == 0.0; ++lag) {
        double spread = 0.0;
        for (std::size_t i = lag; i < m.size(); ++i) spread = std::max(spread, std::abs(m[i] - m[i - lag]));
        if (spread > 1e-3) continue;
        const std::size_t cycles = (m.size() - 1) / lag;
        r.period = (when[cycles * lag] - when[0]) / static_cast<double>(cycles);
        r.maxima_per_period = lag;
    }
    r.max = m.empty() ? 0.0 : *std::max_element(m.begin(), m.end());
    return r;
}

/// period and max of x of a branch's orbits linearly interpolated at p (the branch monotone in p there).
std::pair<double, double> branch_at(const OrbitBranch& b, double p) {
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
        const PeriodicOrbit &a = b.points[i], &z = b.points[i + 1];
        if ((a.par - p) * (z.par - p) > 0.0) continue;
        const double w = (p - a.par) / (z.par - a.par);
        return {a.period + w * (z.period - a.period), a.max[0] + w * (z.max[0] - a.max[0])};
    }
    return {0.0, 0.0};
}


}  // namespace

TEST_CASE("y' = -(pi/2) y(t - 1): the orbits at the Hopf point are sin(pi t / 2) with period 4 at every amplitude") {
    // the linear equation has the solutions A sin(pi t / 2) exactly at a = pi/2: the branch is vertical
    ExpressionSystem sys({"y"}, {"a"}, {pi / 2}, {"-a*y(t - 1)"});
    const OrbitBranch b = orbit_branch_from_hopf(sys, scalar_hopf(), options("a", 1.0, 2.0, 6));
    REQUIRE(b.points.size() == 6);
    for (const PeriodicOrbit& p : b.points) {
        CHECK(std::abs(p.period - 4.0) < tol::orbit_closed_form);
        CHECK(std::abs(p.par - pi / 2) < tol::orbit_closed_form);
        // the profile is a sine: max = -min
        CHECK(std::abs(p.max[0] + p.min[0]) < tol::orbit_closed_form);
        CHECK(p.trivial_distance < tol::orbit_closed_form);
    }
    CHECK(b.points.back().max[0] > 10.0 * b.points.front().max[0]);  // the amplitude did grow
}

TEST_CASE("Wright's equation near its Hopf point: amplitude law and period 4 (Chow and Mallet-Paret)") {
    // y' = -alpha y(t - 1)(1 + y): Hopf at alpha = pi/2, omega = pi/2 (period 4), supercritical, with
    // y(t) ~ K sqrt(alpha - pi/2) sin(pi t / 2), K^2 = 40 / (3 pi - 2) (the classical Hopf
    // expansion of Wright's equation, e.g. Hale and Verduyn Lunel, Introduction to FDEs, sec. 11.4)
    const ExpressionSystem sys = wright();
    const OrbitBranch b = orbit_branch_from_hopf(sys, scalar_hopf(), options("alpha", 1.5, 2.0, 5));
    REQUIRE(b.points.size() == 5);
    CHECK(b.status == Status::Converged);
    const double K = std::sqrt(40.0 / (3.0 * pi - 2.0));
    double previous_error = 1e300;
    for (int k = 2; k >= 0; --k) {  // towards the Hopf point the law holds ever better
        const PeriodicOrbit& p = b.points[static_cast<std::size_t>(k)];
        const double e = p.par - pi / 2;
        REQUIRE(e > 0.0);  // supercritical: the orbits exist for alpha > pi/2
        CHECK(p.stable);
        const double error = std::abs(0.5 * (p.max[0] - p.min[0]) / std::sqrt(e) / K - 1.0);
        CHECK(error < previous_error);
        previous_error = error;
    }
    CHECK(previous_error < tol::hopf_amplitude_law);
    // the period tends to 4 linearly in alpha - pi/2: (T - 4) / (alpha - pi/2) settles
    const double s0 = (b.points[0].period - 4.0) / (b.points[0].par - pi / 2), s1 = (b.points[1].period - 4.0) / (b.points[1].par - pi / 2);
    CHECK(std::abs(b.points[0].period - 4.0) < 1e-3);
    CHECK(std::abs(s0 - s1) < tol::hopf_period_slope * std::abs(s0));
}

TEST_CASE("Wright's equation at alpha = 2: the stable orbit's period and amplitude against a long simulation") {
    const OrbitBranch b = orbit_branch_from_hopf(wright(), scalar_hopf(), options("alpha", 1.5, 2.0, 60));
    REQUIRE(b.stop == "bound");
    const PeriodicOrbit& p = b.points.back();
    REQUIRE(std::abs(p.par - 2.0) < 1e-12);
    CHECK(p.stable);
    CHECK(p.trivial_distance < tol::orbit_trivial_multiplier);
    const ExpressionSystem sys = wright(2.0);
    const DdeSolver s = simulate(sys, [](double, double* y) { y[0] = 0.5; }, 400.0, 0.01);
    const std::vector<double> up = crossings(s, 0, 0.0, 300.0, 400.0, 0.05);
    REQUIRE(up.size() >= 3);
    const double period = (up.back() - up.front()) / static_cast<double>(up.size() - 1);
    CHECK(std::abs(period - p.period) < tol::orbit_vs_simulation * p.period);
    const double amp = range(s, 0, up.front(), up.back(), 0.001);
    CHECK(std::abs(amp - (p.max[0] - p.min[0])) < tol::orbit_vs_simulation * amp);
}

TEST_CASE("Wright's equation at alpha = 2: a branch started from an orbit sampled from a simulation") {
    const ExpressionSystem sys = wright(2.0);
    const DdeSolver s = simulate(sys, [](double, double* y) { y[0] = 0.5; }, 300.0, 0.01);
    const std::vector<double> up = crossings(s, 0, 0.0, 250.0, 300.0, 0.05);
    REQUIRE(up.size() >= 2);
    // one period of samples every 0.05 from an upward crossing, the period from two crossings
    std::vector<double> times;
    for (double t = up[0]; t <= up[1] + 1e-9; t += 0.05) times.push_back(t);
    times.push_back(up[1]);
    Eigen::MatrixXd states(static_cast<Eigen::Index>(times.size()), 1);
    for (std::size_t i = 0; i < times.size(); ++i) states(static_cast<Eigen::Index>(i), 0) = s.value(0, times[i]);
    const PeriodicMesh mesh(4, 40);
    const OrbitGuess g = orbit_guess_from_samples(mesh, times, states, up[1] - up[0], 2.0);
    const OrbitBranch b = orbit_branch_from_guess(sys, g, options("alpha", 2.0, 2.2, 4));
    REQUIRE(b.points.size() == 4);
    CHECK(b.status == Status::Converged);
    CHECK(std::abs(b.points[0].par - 2.0) < 1e-12);
    CHECK(b.points[1].par > 2.0);  // followed towards --to
    // the same orbit as the branch from the Hopf point reaches at alpha = 2
    const OrbitBranch h = orbit_branch_from_hopf(wright(), scalar_hopf(), options("alpha", 1.5, 2.0, 60));
    REQUIRE(h.stop == "bound");
    CHECK(std::abs(b.points[0].period - h.points.back().period) < tol::orbit_closed_form * h.points.back().period);
    CHECK(std::abs(b.points[0].max[0] - h.points.back().max[0]) < tol::orbit_extremes);
    CHECK(std::abs(b.points[0].min[0] - h.points.back().min[0]) < tol::orbit_extremes);
}

TEST_CASE("Wright's equation: the trivial multiplier tends to 1 and the period converges as the mesh is refined") {
    std::vector<double> trivial, period;
    for (int L : {8, 16, 32, 64}) {
        const OrbitBranch b = orbit_branch_from_hopf(wright(), scalar_hopf(), options("alpha", 1.5, 2.6, 80, L));
        REQUIRE(b.stop == "bound");
        REQUIRE(std::abs(b.points.back().par - 2.6) < 1e-12);
        trivial.push_back(b.points.back().trivial_distance);
        period.push_back(b.points.back().period);
    }
    for (std::size_t i = 1; i < trivial.size(); ++i) CHECK(trivial[i] < trivial[i - 1]);
    // the period error against the finest mesh falls (at least by 2^d / 2 per halving)
    const double e0 = std::abs(period[0] - period[3]), e1 = std::abs(period[1] - period[3]), e2 = std::abs(period[2] - period[3]);
    CHECK(e1 < e0 / 8.0);
    CHECK(e2 < e1 / 8.0);
}

TEST_CASE("ov ring (N = 5): subcritical Hopf, fold of orbits and bistability, checked by simulation" * doctest::test_suite("slow")) {
    OvRing ring(5, 1.0, 1.0, 1.0, 1.0, 2.6);
    const HopfPoint h = ov_hopf(ring);
    const OrbitBranch b = orbit_branch_from_hopf(ring, h, options("headway", 2.0, 3.5, 45, 40));
    REQUIRE(b.folds.size() == 1);
    CHECK(b.folds[0].located);
    const double fold = b.folds[0].par;
    CHECK(fold > h.par);  // subcritical: the orbits bend back past the Hopf point
    // the orbits before the fold are unstable, after it stable (the fold exchanges one multiplier)
    const auto after = static_cast<std::size_t>(b.folds[0].after);
    for (std::size_t i = 0; i <= after; ++i) CHECK(!b.points[i].stable);
    for (std::size_t i = after + 2; i < b.points.size(); ++i) CHECK(b.points[i].stable);
    // pick the unstable and the stable orbit at one headway inside the window: the branch crosses
    // h = hm once on each side of the fold
    const double hm = 0.5 * (h.par + fold);
    std::size_t iu = 0, is = 0;
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
        const double a = b.points[i].par - hm, c = b.points[i + 1].par - hm;
        if (a * c <= 0.0) (i < after ? iu : is) = i;
    }
    REQUIRE(iu > 0);
    REQUIRE(is > after);
    ring.set_parameter("headway", hm);
    // the stable large orbit, corrected at h = hm, against a long simulation
    OrbitGuess g{hm, b.points[is].period, Eigen::MatrixXd()};
    {
        const PeriodicMesh from(b.degree, b.points[is].breakpoints), to(4, 40);
        g.profile.resize(to.points(), ring.dimension());
        for (int i = 0; i < to.points(); ++i) g.profile.row(i) = orbit_value(from, b.points[is].profile, to.point(i)).transpose();
    }
    const OrbitBranch stable = orbit_branch_from_guess(ring, g, options("headway", hm, hm + 0.1, 2, 40));
    REQUIRE(!stable.points.empty());
    const PeriodicOrbit& ps = stable.points.front();
    CHECK(std::abs(ps.par - hm) < 1e-12);
    CHECK(ps.stable);
    // start the simulation on a profile that is the unstable orbit grown by 20 % around the uniform flow
    const PeriodicOrbit& pu = b.points[iu];
    const PeriodicMesh mesh(b.degree, pu.breakpoints);
    const Eigen::VectorXd xs = ring.uniform_flow();
    auto from_orbit = [&](double factor) {
        return [&, factor](double t, double* y) {
            const Eigen::VectorXd x = xs + factor * (orbit_value(mesh, pu.profile, t / pu.period) - xs);
            for (Eigen::Index i = 0; i < x.size(); ++i) y[i] = x(i);
        };
    };
    const DdeSolver big = simulate(ring, from_orbit(1.2), 1500.0, 0.02);
    const std::vector<double> up = crossings(big, 0, hm, 1200.0, 1500.0, 0.1);
    REQUIRE(up.size() >= 3);
    const double period = (up.back() - up.front()) / static_cast<double>(up.size() - 1);
    CHECK(std::abs(period - ps.period) < tol::orbit_vs_simulation * ps.period);
    const double amp = range(big, 0, up.front(), up.back(), 0.005);
    CHECK(std::abs(amp - (ps.max[0] - ps.min[0])) < tol::orbit_vs_simulation * amp);
    // the unstable orbit shrunk by 20 %: the disturbance dies out (the uniform flow is stable here),
    // so the unstable orbit is not reached by simulation, it separates the two attractors
    const DdeSolver small = simulate(ring, from_orbit(0.8), 1500.0, 0.02);
    CHECK(range(small, 0, 1200.0, 1500.0, 0.1) < 1e-3 * (pu.max[0] - pu.min[0]));
}

TEST_CASE("ov ring (N = 3): the branch from one Hopf point ends at the other, with exactly its two folds and two bistable windows" * doctest::test_suite("slow")) {
    // the equilibria and both Hopf points first (an independent computation: the equilibrium
    // branch's root counts), then the orbits from the lower Hopf point over the whole range, as
    // `orbits --model ov --ring 3 --par headway --from 1.2 --to 3 --points 400` (once: 2.5 loops,
    // 17 "folds", 3 of them at Hopf points)
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    const EquilibriumBranch eq = ddemap::test::ov3_headway_equilibria(ring);
    const double h1 = std::min(eq.hopf[0].par, eq.hopf[1].par), h2 = std::max(eq.hopf[0].par, eq.hopf[1].par);
    const HopfPoint& start = eq.hopf[0].par == h1 ? eq.hopf[0] : eq.hopf[1];
    const OrbitBranch b = orbit_branch_from_hopf(ring, start, options("headway", 1.2, 3.0, 400, 40));
    CHECK(b.status == Status::Converged);
    CHECK(b.stop == "hopf");
    REQUIRE(b.folds.size() == 2);
    CHECK(b.folds[0].located);
    CHECK(b.folds[1].located);
    const double f1 = std::min(b.folds[0].par, b.folds[1].par), f2 = std::max(b.folds[0].par, b.folds[1].par);
    CHECK(f1 < h1);  // both Hopf points subcritical: the orbits bend back past them
    CHECK(f2 > h2);
    // the branch ends next to the other Hopf point, at a small amplitude
    const PeriodicOrbit& last = b.points.back();
    double amp_max = 0.0;
    for (const PeriodicOrbit& p : b.points) amp_max = std::max(amp_max, (p.max - p.min).maxCoeff());
    CHECK(std::abs(last.par - h2) < 0.05 * (h2 - h1));
    CHECK((last.max - last.min).maxCoeff() < 0.25 * amp_max);
    // stability from the multipliers: unstable up to the first fold, stable between the folds,
    // unstable after the second (one multiplier crosses 1 at each fold)
    const auto a1 = static_cast<std::size_t>(std::min(b.folds[0].after, b.folds[1].after));
    const auto a2 = static_cast<std::size_t>(std::max(b.folds[0].after, b.folds[1].after));
    for (std::size_t i = 0; i < b.points.size(); ++i) {
        CAPTURE(i);
        REQUIRE(b.points[i].undecided.empty());
        if (i <= a1 || i > a2 + 1) CHECK(!b.points[i].stable);
        else if (i > a1 + 1 && i <= a2) CHECK(b.points[i].stable);
    }
    // the figure: two bistable windows [fold, Hopf] on either side of the unstable equilibria,
    // and stable orbits drawn solid, unstable dashed
    const std::string svg = bifurcation_svg(&eq, b, 0, "h0", "m", "m", "ov ring of 3 cars");
    auto g4 = [](double v) {  // 4 significant digits, as the figure's note
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.4g", v);
        return std::string(buf);
    };
    const std::string windows = "[" + g4(f1) + ", " + g4(h1) + "] and [" + g4(h2) + ", " + g4(f2) + "]";
    CAPTURE(windows);
    CHECK(svg.find("bistable (stable orbit and stable equilibrium) for headway in " + windows) != std::string::npos);
}

TEST_CASE("ov ring (N = 5): the fold of orbits converges as the mesh is refined" * doctest::test_suite("slow")) {
    std::vector<double> fold, period;
    // from 20 intervals: on 10 the orbits near the fold fail the accuracy check (|mu_trivial - 1| up
    // to 0.04 > orbit_accuracy_limit), so that branch is undecided and reports no special points
    for (int L : {20, 40, 80, 160}) {
        OvRing ring(5, 1.0, 1.0, 1.0, 1.0, 2.6);
        const HopfPoint h = ov_hopf(ring);
        const OrbitBranch b = orbit_branch_from_hopf(ring, h, options("headway", 2.0, 3.5, 30, L));
        REQUIRE(b.folds.size() == 1);
        REQUIRE(b.folds[0].located);
        fold.push_back(b.folds[0].par);
        period.push_back(b.folds[0].period);
    }
    const double e0 = std::abs(fold[0] - fold[3]), e1 = std::abs(fold[1] - fold[3]), e2 = std::abs(fold[2] - fold[3]);
    CHECK(e1 < e0);
    CHECK(e2 < e1);
    CHECK(std::abs(period[2] - period[3]) < std::abs(period[0] - period[3]));
}

TEST_CASE("orbit options and starts: bad input is std::invalid_argument, a failed start is a status") {
    const ExpressionSystem sys = wright();
    PeriodicOrbitOptions o = options("alpha", 1.5, 2.0, 5);
    o.degree = 0;
    CHECK_THROWS_AS(orbit_branch_from_hopf(sys, scalar_hopf(), o), std::invalid_argument);
    CHECK_THROWS_AS(orbit_branch_from_hopf(sys, scalar_hopf(), options("beta", 1.5, 2.0, 5)), std::invalid_argument);
    HopfPoint h = scalar_hopf();
    h.omega = 0.0;
    CHECK_THROWS_AS(orbit_branch_from_hopf(sys, h, options("alpha", 1.5, 2.0, 5)), std::invalid_argument);
    // a constant guess (an equilibrium solves the collocation equations with any period): a status
    OrbitGuess g{1.6, 4.0, Eigen::MatrixXd::Constant(160, 1, 0.01)};
    const OrbitBranch b = orbit_branch_from_guess(sys, g, options("alpha", 1.5, 2.0, 5));
    CHECK(b.status != Status::Converged);
    CHECK(b.stop == "first_orbit_failed");
    // a guess far from any orbit: no crash, a status (from 50 sin + 60 the condensed corrector
    // reaches the orbit of period 4.02 itself, so the guess is ten times further up)
    const PeriodicMesh mesh(4, 40);
    for (int i = 0; i < mesh.points(); ++i) g.profile(i, 0) = 50.0 * std::sin(2 * pi * mesh.point(i)) + 600.0;
    const OrbitBranch far = orbit_branch_from_guess(sys, g, options("alpha", 1.5, 2.0, 5));
    CHECK(far.status != Status::Converged);
    CHECK(far.stop == "first_orbit_failed");
}

TEST_CASE("Wright's equation at alpha = 2.9: the adapted mesh gives a more accurate period than the uniform one" * doctest::test_suite("slow")) {
    // the orbit has a fast pulse and a slow phase near y = -1; the reference is a uniform mesh of 200 intervals
    std::vector<double> period;
    for (int k = 0; k < 3; ++k) {
        PeriodicOrbitOptions o = options("alpha", 1.5, 2.9, 200, k == 2 ? 200 : 40);
        o.adapt = k == 1;
        const OrbitBranch b = orbit_branch_from_hopf(wright(), scalar_hopf(), o);
        REQUIRE(b.stop == "bound");
        period.push_back(b.points.back().period);
        if (k == 1) {  // the mesh moved: its intervals differ by more than a factor 2
            const std::vector<double>& t = b.points.back().breakpoints;
            double hmin = 1.0, hmax = 0.0;
            for (std::size_t i = 1; i < t.size(); ++i) hmin = std::min(hmin, t[i] - t[i - 1]), hmax = std::max(hmax, t[i] - t[i - 1]);
            CHECK(hmax > 2.0 * hmin);
        }
    }
    CHECK(std::abs(period[1] - period[2]) < 0.5 * std::abs(period[0] - period[2]));
}

TEST_CASE("Mackey-Glass (beta = 2, gamma = 1, n = 9.65): the first period doubling in tau, located, and period T / 2T by simulation on either side" * doctest::test_suite("slow")) {
    ExpressionSystem mg = mackey_glass();
    const OrbitBranch b = mackey_glass_branch(mg);
    REQUIRE(!b.period_doublings.empty());
    const OrbitCrossing& pd = b.period_doublings.front();
    REQUIRE(pd.located);
    CHECK(pd.accuracy <= 1e-9);
    CHECK(std::abs(pd.multiplier + 1.0) <= 1e-8);  // a real multiplier at -1
    CHECK(pd.par_bracket < 1e-6);
    CHECK(pd.orbit.trivial_distance < tol::orbit_trivial_multiplier);
    // the orbits before it are stable, the ones just after it not (the multiplier left through -1)
    const auto k = static_cast<std::size_t>(pd.after);
    CHECK(b.points[k].stable);
    CHECK(!b.points[k + 1].stable);
    // independent check by simulation, 0.02 below and above the located tau: one maximum of x
    // per period below (period T), two alternating maxima above (period 2T)
    const SimulatedOrbit below = mackey_glass_orbit(mg, pd.par - 0.02), above = mackey_glass_orbit(mg, pd.par + 0.02);
    CHECK(below.maxima_per_period == 1);
    CHECK(above.maxima_per_period == 2);
    // and the period of the simulated orbit below is the located orbit's (to the slope of T over 0.02 in tau)
    CHECK(std::abs(below.period - pd.period) < 0.05 * pd.period);
    CHECK(std::abs(above.period - 2.0 * pd.period) < 0.05 * pd.period);
}


TEST_CASE("Mackey-Glass (beta = 2, gamma = 1, n = 9.65): the branch switched onto at the period doubling, and the next doubling of the cascade, by simulation" * doctest::test_suite("slow")) {
    ExpressionSystem mg = mackey_glass();
    const OrbitBranch b = mackey_glass_branch(mg);
    REQUIRE(!b.period_doublings.empty());
    const OrbitCrossing& pd = b.period_doublings.front();
    REQUIRE(pd.located);
    PeriodicOrbitOptions o = options("tau", 0.3, 2.0, 200);
    o.max_step = 0.05;
    const OrbitBranch d = orbit_branch_from_period_doubling(mg, pd, o);
    REQUIRE(d.points.size() > 5);
    CHECK(d.status == Status::Converged);
    CHECK(d.intervals == 2 * b.intervals);
    // the new branch is born at the period doubling with twice its period: its period extrapolated
    // from its first two orbits to pd.par is 2 T there (T(p) is smooth through the point)
    const PeriodicOrbit &first = d.points[0], &second = d.points[1];
    const double T_at_pd = first.period + (pd.par - first.par) * (second.period - first.period) / (second.par - first.par);
    CHECK(std::abs(T_at_pd - 2.0 * pd.period) < 1e-3 * pd.period);
    // and its orbits are not the old orbit traversed twice: max_s |x(s) - x(s + 1/2)| > 0
    const PeriodicMesh m2(d.degree, first.breakpoints);
    double split = 0.0;
    for (int i = 0; i < m2.points(); ++i)
        split = std::max(split, std::abs(first.profile(i, 0) - orbit_value(m2, first.profile, m2.point(i) + 0.5)(0)));
    CHECK(split > 1e-3);
    // supercritical: the doubled orbits lie at larger tau and are stable (the old ones lost stability there)
    CHECK(first.par > pd.par);
    CHECK(second.stable);
    // the next period doubling of the cascade on the new branch, located
    REQUIRE(!d.period_doublings.empty());
    const OrbitCrossing& pd2 = d.period_doublings.front();
    REQUIRE(pd2.located);
    CHECK(pd2.par > pd.par);
    CHECK(std::abs(pd2.multiplier + 1.0) <= 1e-8);
    MESSAGE("period doublings at tau = ", pd.par, " (T = ", pd.period, ") and ", pd2.par, " (T = ", pd2.period, ")");
    // independent check by simulation: between the two doublings the simulated orbit has the
    // doubled branch's period and maximum (8.93491 against 8.93464 measured); 0.01 above the
    // second, twice that period again
    const double mid = 0.5 * (pd.par + pd2.par);
    const SimulatedOrbit between = mackey_glass_orbit(mg, mid), above = mackey_glass_orbit(mg, pd2.par + 0.01);
    const std::pair<double, double> at_mid = branch_at(d, mid);
    const double T_mid = at_mid.first, max_mid = at_mid.second;
    const double T_old = branch_at(b, mid).first;
    const double T_above = branch_at(d, pd2.par + 0.01).first;
    MESSAGE("tau = ", mid, ": simulated period ", between.period, " (", between.maxima_per_period, " maxima), doubled branch ", T_mid,
            ", old branch ", T_old, "; tau = ", pd2.par + 0.01, ": simulated ", above.period, ", doubled branch ", T_above);
    REQUIRE(between.period > 0.0);
    REQUIRE(above.period > 0.0);
    CHECK(std::abs(between.period - T_mid) < 2e-3 * T_mid);
    CHECK(std::abs(between.max - max_mid) < 2e-3);
    CHECK(between.period > 1.5 * T_old);  // not the old orbit (unstable there)
    // 0.01 beyond the second doubling the new orbits' period differs from twice the doubled ones'
    // by O(0.01) times the difference of their slopes: 1 % here (0.16 % measured)
    CHECK(std::abs(above.period - 2.0 * T_above) < 0.01 * 2.0 * T_above);
}

TEST_CASE("orbit_guess_from_simulation: the period read off a run is the collocated orbit's, a doubled orbit is seen as one, an equilibrium is a status") {
    // Wright's equation at alpha = 2: one crossing of the mean level per period, the period the
    // collocated orbit's to the integrator's accuracy (RK4, step 0.01)
    ExpressionSystem w = wright(2.0);
    const PeriodicMesh mesh(4, 40);
    const SimulatedOrbitGuess g = orbit_guess_from_simulation(w, "alpha", mesh, Eigen::VectorXd::Constant(1, 0.5), 300.0, 0.01);
    REQUIRE(g.status == Status::Converged);
    CHECK(g.crossings_per_period == 1);
    CHECK(g.guess.par == 2.0);
    const OrbitBranch b = orbit_branch_from_guess(w, g.guess, options("alpha", 2.0, 2.5, 2));
    REQUIRE(!b.points.empty());
    CHECK(std::abs(g.period - b.points.front().period) < 1e-6 * g.period);
    // Mackey-Glass at tau = 1.5, between its first two period doublings: the simulation settles on
    // the orbit of twice the period, corrected on the doubled branch's orbit there
    ExpressionSystem mg = mackey_glass();
    mg.set_parameter("tau", 1.5);
    const SimulatedOrbitGuess m = orbit_guess_from_simulation(mg, "tau", mesh, Eigen::VectorXd::Constant(1, 0.5), 3000.0, 0.005);
    REQUIRE(m.status == Status::Converged);
    const OrbitBranch mb = orbit_branch_from_guess(mg, m.guess, options("tau", 1.5, 1.6, 2));
    REQUIRE(!mb.points.empty());
    CHECK(std::abs(m.period - mb.points.front().period) < 1e-5 * m.period);
    CHECK(m.period > 8.0);  // twice the old orbit's period (4.3 there), not once
    CHECK(mb.points.front().stable);
    // a stable equilibrium (Wright at alpha = 1): a status saying so, no guess
    ExpressionSystem w1 = wright(1.0);
    const SimulatedOrbitGuess e = orbit_guess_from_simulation(w1, "alpha", mesh, Eigen::VectorXd::Constant(1, 0.5), 200.0, 0.01);
    CHECK(e.status == Status::NumericalIssue);
    CHECK(e.message.find("equilibrium") != std::string::npos);
    CHECK(e.guess.profile.size() == 0);
    CHECK_THROWS_AS(orbit_guess_from_simulation(w, "alpha", mesh, Eigen::VectorXd::Constant(2, 0.5), 300.0, 0.01), std::invalid_argument);
    CHECK_THROWS_AS(orbit_guess_from_simulation(w, "beta", mesh, Eigen::VectorXd::Constant(1, 0.5), 300.0, 0.01), std::invalid_argument);
}

TEST_CASE("Mackey-Glass: the curve of period doublings in (tau, n) ends on the faces n = 9 and 10.5 where the one-parameter branches there double" * doctest::test_suite("slow")) {
    ExpressionSystem mg = mackey_glass();
    const OrbitBranch b = mackey_glass_branch(mg);
    REQUIRE(!b.period_doublings.empty());
    OrbitFoldCurveOptions fo;
    fo.orbit = options("tau", 0.3, 2.0, 40);
    fo.parameter2 = "n";
    fo.from2 = 9.0;
    fo.to2 = 10.5;
    const OrbitFoldCurve c = orbit_period_doubling_curve(mg, b.period_doublings.front(), fo);
    REQUIRE(c.status == Status::Converged);
    CHECK(c.stop_backward == "bound");
    CHECK(c.stop_forward == "bound");
    // every point: the test function and, independently, a Floquet multiplier at -1
    for (const OrbitFoldCurvePoint& q : c.points) {
        CHECK(q.test < 1e-10);
        CHECK(q.second_distance < 1e-8);
    }
    // a second path: the first period doubling of the branch in tau alone at n = 9 and at n = 10.5
    for (const OrbitFoldCurvePoint* end : {&c.points.front(), &c.points.back()}) {
        CAPTURE(end->par2);
        REQUIRE((end->par2 == 9.0 || end->par2 == 10.5));
        ExpressionSystem at = mackey_glass();
        at.set_parameter("n", end->par2);
        const OrbitBranch bn = mackey_glass_branch(at);
        REQUIRE(!bn.period_doublings.empty());
        REQUIRE(bn.period_doublings.front().located);
        CHECK(std::abs(bn.period_doublings.front().par - end->par) < 1e-8);
        CHECK(std::abs(bn.period_doublings.front().period - end->orbit.period) < 1e-7);
    }
    // a period doubling that was not located is refused
    OrbitCrossing none;
    CHECK_THROWS_AS(orbit_period_doubling_curve(mg, none, fo), std::invalid_argument);
}
