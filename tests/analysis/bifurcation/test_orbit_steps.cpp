#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"

// The step control of a branch of periodic orbits (PeriodicOrbitOptions::max_step): a branch
// computed with long steps is the same branch as with short ones (period and largest nontrivial
// |mu| of every long-step orbit against the short-step branch interpolated at its parameter), and
// finds the same period doublings and tori, located with small brackets.

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

/// Cubic Lagrange interpolation of y(p) through the 4 orbits of `b` nearest to p in the
/// parameter (the branch's parameter must be monotone there: checked by the caller).
double interpolate(const OrbitBranch& b, double p, double (*y)(const PeriodicOrbit&)) {
    std::vector<std::size_t> idx(b.points.size());
    for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::partial_sort(idx.begin(), idx.begin() + 4, idx.end(),
                      [&](std::size_t i, std::size_t j) { return std::abs(b.points[i].par - p) < std::abs(b.points[j].par - p); });
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        double w = 1.0;
        for (int j = 0; j < 4; ++j)
            if (j != i) w *= (p - b.points[idx[j]].par) / (b.points[idx[i]].par - b.points[idx[j]].par);
        sum += w * y(b.points[idx[i]]);
    }
    return sum;
}

double period_of(const PeriodicOrbit& o) { return o.period; }
double max_mu_of(const PeriodicOrbit& o) { return o.max_nontrivial; }

bool monotone_in_par(const OrbitBranch& b) {
    for (std::size_t i = 2; i < b.points.size(); ++i)
        if ((b.points[i].par - b.points[i - 1].par) * (b.points[i - 1].par - b.points[i - 2].par) <= 0.0) return false;
    return true;
}

/// Every orbit of `coarse` strictly inside the parameter range of `fine` (the first and the last
/// two excluded, where the interpolation would extrapolate) against `fine` interpolated there:
/// the largest relative differences of the period and of the largest nontrivial |mu| (relative
/// to max(1, |mu|)).
std::pair<double, double> branch_difference(const OrbitBranch& fine, const OrbitBranch& coarse) {
    double dT = 0.0, dmu = 0.0;
    const double lo = fine.points[1].par, hi = fine.points[fine.points.size() - 2].par;
    int compared = 0;
    for (const PeriodicOrbit& o : coarse.points) {
        if (!(o.par > std::min(lo, hi) && o.par < std::max(lo, hi))) continue;
        dT = std::max(dT, std::abs(o.period - interpolate(fine, o.par, period_of)) / o.period);
        dmu = std::max(dmu, std::abs(o.max_nontrivial - interpolate(fine, o.par, max_mu_of)) / std::max(1.0, o.max_nontrivial));
        ++compared;
    }
    REQUIRE(compared >= 3);
    return {dT, dmu};
}

}  // namespace

TEST_CASE("Wright's equation: a branch with max_step 0.5 is the branch with max_step 0.02 (period and max |mu| interpolated)") {
    const ExpressionSystem sys({"y"}, {"alpha"}, {1.6}, {"-alpha*y(t - 1)*(1 + y)"});
    HopfPoint h;  // y' = -alpha y(t - 1) at y = 0: alpha = omega = pi / 2, q = 1
    h.par = h.omega = 3.14159265358979323846 / 2;
    h.x = Eigen::VectorXd::Zero(1);
    h.q = VectorXc::Constant(1, cplx(1.0, 0.0));
    h.status = Status::Converged;
    PeriodicOrbitOptions o;
    o.parameter = "alpha";
    o.from = 1.0;
    o.to = 2.5;
    o.max_points = 1000;
    o.max_step = 0.02;  // every step the first one's
    const OrbitBranch fine = orbit_branch_from_hopf(sys, h, o);
    o.max_step = 0.5;
    const OrbitBranch coarse = orbit_branch_from_hopf(sys, h, o);
    REQUIRE(fine.status == Status::Converged);
    REQUIRE(coarse.status == Status::Converged);
    CHECK(fine.stop == "bound");
    CHECK(coarse.stop == "bound");
    MESSAGE("orbits to alpha = 2.5: " << fine.points.size() << " with max_step 0.02, " << coarse.points.size() << " with max_step 0.5");
    CHECK(coarse.points.size() * 3 < fine.points.size());  // the longer steps are taken
    REQUIRE(monotone_in_par(fine));
    const auto d = branch_difference(fine, coarse);
    MESSAGE("largest relative differences: period " << d.first << ", max |mu| " << d.second);
    CHECK(d.first <= tol::orbit_step_interpolation);
    CHECK(d.second <= tol::orbit_step_interpolation);
    // both branches end on the same orbit (the face alpha = 2.5, located exactly)
    CHECK(std::abs(fine.points.back().period - coarse.points.back().period) <= tol::orbit_step_interpolation * fine.points.back().period);
}

TEST_CASE("IDM ring of 5 cars: long steps find the same period doubling and torus as short ones, each with a small verified bracket" *
          doctest::test_suite("slow")) {
    // the branch of `bench_orbits --model idm 5` (th = 1.2 s, tau = 0.6 s) from its first Hopf
    // point in the gap to gap 22: a torus bifurcation near gap 20.46 and a period doubling near
    // 21.04. Before the crossings were paired by continuity, the short-step branch located the
    // period doubling with |mu| - 1 = 5e-10 but reported a bracket of 0.04 in the gap (the regula
    // falsi's far end), and long steps could miss a crossing whose multiplier was not the one
    // nearest the circle (on the 10-car ring with max_step 1 and 2: BENCHMARKS.md).
    NonlinearRing ring = make_nonlinear_ring("idm", 5, ParameterMap{{"th", 1.2}, {"tau", 0.6}}, "gap", 6.0);
    EquilibriumBranchOptions eo;
    eo.parameter = "gap";
    eo.from = 6.0;
    eo.to = 22.0;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(*ring.system, ring.uniform_flow, eo);
    REQUIRE(!eq.hopf.empty());
    PeriodicOrbitOptions o;
    o.parameter = "gap";
    o.from = 6.0;
    o.to = 22.0;
    o.max_points = 3000;
    const OrbitBranch fine = orbit_branch_from_hopf(*ring.system, eq.hopf.front(), o);
    REQUIRE(fine.status == Status::Converged);
    REQUIRE(fine.stop == "bound");
    REQUIRE(monotone_in_par(fine));
    REQUIRE(fine.period_doublings.size() == 1);
    REQUIRE(fine.tori.size() == 1);
    for (double step : {1.0, 2.0}) {
        o.max_step = step;
        const OrbitBranch coarse = orbit_branch_from_hopf(*ring.system, eq.hopf.front(), o);
        REQUIRE(coarse.status == Status::Converged);
        CHECK(coarse.stop == "bound");
        MESSAGE("max_step " << step << ": " << coarse.points.size() << " orbits against " << fine.points.size());
        CHECK(coarse.points.size() * 3 < fine.points.size());
        const auto d = branch_difference(fine, coarse);
        MESSAGE("largest relative differences: period " << d.first << ", max |mu| " << d.second);
        CHECK(d.first <= tol::orbit_step_interpolation);
        CHECK(d.second <= tol::orbit_step_interpolation);
        REQUIRE(coarse.period_doublings.size() == 1);
        REQUIRE(coarse.tori.size() == 1);
        const OrbitCrossing* pairs[2][2] = {{&fine.period_doublings[0], &coarse.period_doublings[0]}, {&fine.tori[0], &coarse.tori[0]}};
        for (const auto& pr : pairs) {
            REQUIRE(pr[0]->located);
            REQUIRE(pr[1]->located);
            CHECK(std::abs(pr[0]->par - pr[1]->par) <= tol::orbit_crossing_between_steps);
            CHECK(std::abs(pr[0]->multiplier - pr[1]->multiplier) <= tol::orbit_crossing_between_steps);
        }
    }
    // the located crossings: on the circle, and a verified small bracket (both sides computed)
    for (const OrbitCrossing* x : {&fine.period_doublings[0], &fine.tori[0]}) {
        MESSAGE("crossing at gap " << x->par << ", mu = " << x->multiplier << ", | |mu| - 1 | = " << x->accuracy << ", bracket " << x->par_bracket);
        CHECK(x->accuracy <= 1e-9);
        CHECK(x->par_bracket <= tol::orbit_crossing_bracket);
        CHECK((x->par - fine.points[static_cast<std::size_t>(x->after)].par) * (x->par - fine.points[static_cast<std::size_t>(x->after) + 1].par) < 0.0);
    }
    CHECK(std::abs(fine.period_doublings[0].multiplier + 1.0) <= 1e-8);
    CHECK(fine.tori[0].multiplier.imag() > 0.1);
}

// ---- travelling waves (analysis/travelling_wave.hpp): the same step control and special points
// (analysis/bifurcation/internal/orbit_continuation.hpp), so the same guarantees with long steps

namespace {

/// The wave branch of wave number 1 on a 5-car ring; the full ring's multipliers with `floquet`.
TravellingWaveBranch wave_branch(const std::string& model, const ParameterMap& parameters, const std::string& par, double from, double to,
                                 double max_step, int intervals, bool floquet) {
    TravellingWaveOptions o;
    o.model = model;
    o.cars = 5;
    o.wave = 1;
    o.orbit.parameter = par;
    o.orbit.from = from;
    o.orbit.to = to;
    o.orbit.max_points = 3000;
    o.orbit.max_step = max_step;
    o.orbit.intervals = intervals;
    o.orbit.floquet = floquet;
    return travelling_wave_branch(parameters, o);
}

/// The full ring's orbits (one headway eliminated) from its first Hopf point in [from, to].
OrbitBranch full_ring_branch(const std::string& model, const ParameterMap& parameters, const std::string& par, double from, double to,
                             double max_step, bool floquet) {
    const NonlinearRing ring = make_nonlinear_ring(model, 5, parameters, par, from);
    EquilibriumBranchOptions eo;
    eo.parameter = par;
    eo.from = from;
    eo.to = to;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(*ring.system, ring.uniform_flow, eo);
    REQUIRE(!eq.hopf.empty());
    PeriodicOrbitOptions o;
    o.parameter = par;
    o.from = from;
    o.to = to;
    o.max_points = 3000;
    o.max_step = max_step;
    o.floquet = floquet;
    return orbit_branch_from_hopf(*ring.system, eq.hopf.front(), o);
}

}  // namespace

TEST_CASE("travelling waves (ov, 5 cars): long steps find the same fold of the wave branch, at the full ring's fold and above every wave" * doctest::test_suite("slow")) {
    // the subcritical wave branch from the Hopf point at headway 2.62 folds at headway 3.1078
    // (README) and comes back to headway 2: the fold is the largest headway of the branch
    const OrbitBranch full = full_ring_branch("ov", {}, "headway", 3.5, 2.0, 0.1, false);
    REQUIRE(full.status == Status::Converged);
    REQUIRE(full.folds.size() == 1);
    REQUIRE(full.folds[0].located);
    const TravellingWaveBranch fine = wave_branch("ov", {}, "headway", 3.5, 2.0, 0.1, 40, false);
    const TravellingWaveBranch fine20 = wave_branch("ov", {}, "headway", 3.5, 2.0, 0.1, 20, false);
    for (const TravellingWaveBranch* w : {&fine, &fine20}) {
        REQUIRE(w->branch.status == Status::Converged);
        REQUIRE(w->branch.folds.size() == 1);
        REQUIRE(w->branch.folds[0].located);
    }
    const double fold = fine.branch.folds[0].par;
    // the fine branch's own scan: no wave beyond the fold, and the fold between its neighbours
    double largest = -1.0;
    for (const PeriodicOrbit& p : fine.branch.points) largest = std::max(largest, p.par);
    MESSAGE("fold of waves at headway " << fold << ", the fine branch's largest headway " << largest << ", the full ring's fold "
                                        << full.folds[0].par << " (20 intervals: " << fine20.branch.folds[0].par << ")");
    CHECK(largest <= fold + tol::wave_fold_between_steps);
    const auto after = static_cast<std::size_t>(fine.branch.folds[0].after);
    REQUIRE(after + 1 < fine.branch.points.size());
    CHECK(fine.branch.points[after].par < fold);
    CHECK(fine.branch.points[after + 1].par < fold);
    // the full ring's fold (its own equations, 9 of them): within the mesh change of the reduced form
    CHECK(std::abs(fold - full.folds[0].par) <= std::abs(fold - fine20.branch.folds[0].par) + tol::wave_vs_full_ring_floor);
    for (double step : {1.0, 2.0}) {
        CAPTURE(step);
        const TravellingWaveBranch coarse = wave_branch("ov", {}, "headway", 3.5, 2.0, step, 40, false);
        REQUIRE(coarse.branch.status == Status::Converged);
        CHECK(coarse.branch.stop == "bound");
        MESSAGE("max_step " << step << ": " << coarse.branch.points.size() << " waves against " << fine.branch.points.size());
        CHECK(coarse.branch.points.size() < fine.branch.points.size());
        REQUIRE(coarse.branch.folds.size() == 1);  // not missed
        REQUIRE(coarse.branch.folds[0].located);
        CHECK(std::abs(coarse.branch.folds[0].par - fold) <= tol::wave_fold_between_steps);  // nor misplaced
        CHECK(std::abs(coarse.branch.folds[0].period - fine.branch.folds[0].period) <= tol::wave_fold_between_steps * fine.branch.folds[0].period);
        // the same branch: both end on headway 2 (located exactly) with the same wave
        REQUIRE(coarse.branch.points.back().par == 2.0);
        CHECK(std::abs(coarse.branch.points.back().period - fine.branch.points.back().period) <=
              tol::orbit_step_interpolation * fine.branch.points.back().period);
    }
}

TEST_CASE("travelling waves (IDM, 5 cars): long steps give the same branch, period doubling and torus, both at the full ring's" * doctest::test_suite("slow")) {
    // the wave branch of `orbits --model idm --ring 5 --th 1.2 --tau 0.6 --wave 1` from its Hopf
    // point at gap 8.048 to gap 22, with the full ring's multipliers along the wave: a torus
    // bifurcation near gap 20.4575 and a period doubling near 21.0402, as on the full ring's own
    // branch (test above: the same Hopf point, the same orbits)
    const ParameterMap idm{{"th", 1.2}, {"tau", 0.6}};
    const TravellingWaveBranch fine = wave_branch("idm", idm, "gap", 6.0, 22.0, 0.1, 40, true);
    const TravellingWaveBranch fine20 = wave_branch("idm", idm, "gap", 6.0, 22.0, 1.0, 20, true);
    for (const TravellingWaveBranch* w : {&fine, &fine20}) {
        REQUIRE(w->full_ring_stability);
        REQUIRE(w->branch.status == Status::Converged);
        REQUIRE(w->branch.stop == "bound");
        REQUIRE(w->branch.period_doublings.size() == 1);
        REQUIRE(w->branch.tori.size() == 1);
    }
    REQUIRE(monotone_in_par(fine.branch));
    CHECK(fine.branch.folds.empty());
    for (double step : {1.0, 2.0}) {
        CAPTURE(step);
        const TravellingWaveBranch coarse = wave_branch("idm", idm, "gap", 6.0, 22.0, step, 40, true);
        REQUIRE(coarse.branch.status == Status::Converged);
        CHECK(coarse.branch.stop == "bound");
        MESSAGE("max_step " << step << ": " << coarse.branch.points.size() << " waves against " << fine.branch.points.size());
        CHECK(coarse.branch.points.size() * 3 < fine.branch.points.size());
        const auto d = branch_difference(fine.branch, coarse.branch);
        MESSAGE("largest relative differences: period " << d.first << ", max |mu| " << d.second);
        CHECK(d.first <= tol::orbit_step_interpolation);
        CHECK(d.second <= tol::orbit_step_interpolation);
        REQUIRE(coarse.branch.period_doublings.size() == 1);
        REQUIRE(coarse.branch.tori.size() == 1);
        const OrbitCrossing* pairs[2][2] = {{&fine.branch.period_doublings[0], &coarse.branch.period_doublings[0]},
                                            {&fine.branch.tori[0], &coarse.branch.tori[0]}};
        for (const auto& pr : pairs) {
            REQUIRE(pr[0]->located);
            REQUIRE(pr[1]->located);
            CHECK(std::abs(pr[0]->par - pr[1]->par) <= tol::orbit_crossing_between_steps);
            CHECK(std::abs(pr[0]->multiplier - pr[1]->multiplier) <= tol::orbit_crossing_between_steps);
            CHECK(pr[1]->par_bracket <= tol::orbit_crossing_bracket);
        }
    }
    // the located crossings: on the circle, a verified small bracket between their neighbours
    for (const OrbitCrossing* x : {&fine.branch.period_doublings[0], &fine.branch.tori[0]}) {
        CHECK(x->accuracy <= 1e-9);
        CHECK(x->par_bracket <= tol::orbit_crossing_bracket);
        const auto after = static_cast<std::size_t>(x->after);
        CHECK((x->par - fine.branch.points[after].par) * (x->par - fine.branch.points[after + 1].par) < 0.0);
    }
    CHECK(std::abs(fine.branch.period_doublings[0].multiplier + 1.0) <= 1e-8);
    CHECK(fine.branch.tori[0].multiplier.imag() > 0.1);
    // the full ring's own branch (9 equations; long steps, which locate the same points: test
    // above): the same period doubling and torus, within the mesh change of the reduced form
    const OrbitBranch full = full_ring_branch("idm", idm, "gap", 6.0, 22.0, 1.0, true);
    REQUIRE(full.status == Status::Converged);
    REQUIRE(full.period_doublings.size() == 1);
    REQUIRE(full.tori.size() == 1);
    const double wpd = fine.branch.period_doublings[0].par, wt = fine.branch.tori[0].par;
    MESSAGE("period doubling: wave " << wpd << " (20 intervals " << fine20.branch.period_doublings[0].par << "), full ring " << full.period_doublings[0].par
                                     << "; torus: wave " << wt << " (20 intervals " << fine20.branch.tori[0].par << "), full ring " << full.tori[0].par);
    CHECK(std::abs(wpd - full.period_doublings[0].par) <= std::abs(wpd - fine20.branch.period_doublings[0].par) + tol::wave_vs_full_ring_floor);
    CHECK(std::abs(wt - full.tori[0].par) <= std::abs(wt - fine20.branch.tori[0].par) + tol::wave_vs_full_ring_floor);
    CHECK(std::abs(fine.branch.tori[0].multiplier - full.tori[0].multiplier) <= tol::wave_full_ring_multipliers);
}

TEST_CASE("Mackey-Glass (DDE-BIFTOOL demo): the period doubling with max_step 0.5 is the one found with short steps") {
    // x' = 2 x(t - tau) / (1 + x(t - tau)^10) - x, the branch in tau from the Hopf point. With
    // max_step 0.5 the real multiplier jumps from -0.99 to -1.63 in one step (farther than the
    // pairing allows): the parity of the number of multipliers < -1 changes, the step is halved
    // until the pairing sees the crossing. The reference is the branch with max_step 0.02.
    const ExpressionSystem sys({"x"}, {"beta", "n", "tau", "gamma"}, {2.0, 10.0, 0.0, 1.0}, {"beta*x(t - tau)/(1 + x(t - tau)^n) - gamma*x"});
    EquilibriumBranchOptions eo;
    eo.parameter = "tau";
    eo.from = 0.0;
    eo.to = 2.0;
    const EquilibriumBranch eq = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 1.0), eo);
    REQUIRE(eq.hopf.size() == 1);
    PeriodicOrbitOptions o;
    o.parameter = "tau";
    o.from = 0.0;
    o.to = 2.0;
    o.intervals = 40;
    o.max_points = 1000;
    o.max_step = 0.02;
    const OrbitBranch fine = orbit_branch_from_hopf(sys, eq.hopf[0], o);
    o.max_step = 0.5;
    const OrbitBranch coarse = orbit_branch_from_hopf(sys, eq.hopf[0], o);
    REQUIRE(fine.status == Status::Converged);
    REQUIRE(coarse.status == Status::Converged);
    CHECK(coarse.points.size() * 3 < fine.points.size());
    REQUIRE(fine.period_doublings.size() == 1);
    REQUIRE(coarse.period_doublings.size() == 1);
    CHECK(coarse.period_doublings[0].located);
    MESSAGE("period doubling: tau " << fine.period_doublings[0].par << " (max_step 0.02), " << coarse.period_doublings[0].par << " (0.5)");
    CHECK(std::abs(coarse.period_doublings[0].par - fine.period_doublings[0].par) <= tol::special_point);
}
