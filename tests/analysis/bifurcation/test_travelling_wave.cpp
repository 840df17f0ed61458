#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

TravellingWaveOptions wave_options(int cars, int wave, int intervals, int points, bool floquet) {
    TravellingWaveOptions o;
    o.model = "ov";
    o.cars = cars;
    o.wave = wave;
    o.orbit.parameter = "headway";
    o.orbit.from = 3.5;
    o.orbit.to = 2.0;
    o.orbit.intervals = intervals;
    o.orbit.max_points = points;
    o.orbit.floquet = floquet;
    return o;
}

/// The full ring (one headway eliminated) from its first Hopf point from headway 3.5 down to 2.
struct FullRing {
    NonlinearRing ring;
    HopfPoint hopf;
    OrbitBranch branch;
};

FullRing full_ring(int cars, int points) {
    FullRing f{make_nonlinear_ring("ov", cars, {{"headway", 3.5}}), {}, {}};
    EquilibriumBranchOptions eo;
    eo.parameter = "headway";
    eo.from = 3.5;
    eo.to = 2.0;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(*f.ring.system, f.ring.uniform_flow, eo);
    REQUIRE(!eq.hopf.empty());
    f.hopf = eq.hopf.front();
    REQUIRE(f.hopf.status == Status::Converged);
    PeriodicOrbitOptions o = wave_options(cars, 1, 40, points, false).orbit;
    f.branch = orbit_branch_from_hopf(*f.ring.system, f.hopf, o);
    return f;
}

/// |a - b| <= the mesh change |a - a20| + floor (see tol::wave_vs_full_ring_floor)
void check_agrees(double reduced, double reduced20, double full, double floor, const char* what) {
    INFO(std::string(what) << ": reduced " << reduced << " (20 intervals: " << reduced20 << "), full ring " << full);
    CHECK(std::abs(reduced - full) <= std::abs(reduced - reduced20) + floor);
}

}  // namespace

TEST_CASE("travelling waves: the reduced form against the full ring (N = 3, 5): Hopf point, fold, end orbit" * doctest::test_suite("slow")) {
    for (int cars : {3, 5}) {
        CAPTURE(cars);
        const FullRing full = full_ring(cars, 80);
        REQUIRE(full.branch.status == Status::Converged);
        REQUIRE(full.branch.folds.size() == 1);
        REQUIRE(full.branch.stop == "bound");
        // the first Hopf point from headway 3.5 is of ring modes 1 and N - 1; as a wave with
        // omega > 0 it has wave number 1 (the leader ahead in phase), wave number N - 1 has none
        const TravellingWaveBranch w = travelling_wave_branch({}, wave_options(cars, 1, 40, 80, false));
        const TravellingWaveBranch w20 = travelling_wave_branch({}, wave_options(cars, 1, 20, 80, false));
        const TravellingWaveBranch other = travelling_wave_branch({}, wave_options(cars, cars - 1, 40, 3, false));
        CHECK(other.hopf.status != Status::Converged);
        CHECK(other.branch.points.empty());
        REQUIRE(w.hopf.status == Status::Converged);
        CHECK(std::abs(w.hopf.par - full.hopf.par) <= tol::wave_vs_full_ring_floor);
        CHECK(std::abs(w.hopf.omega - full.hopf.omega) <= tol::wave_vs_full_ring_floor);
        for (const TravellingWaveBranch* b : {&w, &w20}) {
            REQUIRE(b->branch.status == Status::Converged);
            REQUIRE(b->branch.folds.size() == 1);
            REQUIRE(b->branch.folds[0].located);
            REQUIRE(b->branch.stop == "bound");
            CHECK(b->max_drift < tol::wave_drift);  // the unfolding term vanishes
            for (const PeriodicOrbit& p : b->branch.points) CHECK(p.residual <= 1e-8);  // the options' residual tolerance
        }
        // the fold of waves (a subcritical Hopf point: the unstable waves fold back into stable ones)
        const PeriodicOrbit& fr = w.branch.folds[0].orbit;
        const PeriodicOrbit& fr20 = w20.branch.folds[0].orbit;
        const PeriodicOrbit& ff = full.branch.folds[0].orbit;
        check_agrees(fr.par, fr20.par, ff.par, tol::wave_vs_full_ring_floor, "fold headway");
        check_agrees(fr.period, fr20.period, ff.period, tol::wave_vs_full_ring_floor, "fold period");
        // the last orbit, on headway = 2 (the face of the range), and the fold orbit: extremes of
        // car 0's headway and speed (the full ring's h_0 and v_0; sampled, so phase-dependent by
        // tol::orbit_extremes)
        const PeriodicOrbit& er = w.branch.points.back();
        const PeriodicOrbit& er20 = w20.branch.points.back();
        const PeriodicOrbit& ef = full.branch.points.back();
        REQUIRE(er.par == 2.0);
        REQUIRE(ef.par == 2.0);
        check_agrees(er.period, er20.period, ef.period, tol::wave_vs_full_ring_floor, "period at headway 2");
        for (int q = 0; q < 2; ++q) {
            const int col = q == 0 ? 0 : cars - 1;  // h_0, v_0 of the full ring's state
            check_agrees(er.min(q), er20.min(q), ef.min(col), tol::orbit_extremes, "min at headway 2");
            check_agrees(er.max(q), er20.max(q), ef.max(col), tol::orbit_extremes, "max at headway 2");
            check_agrees(fr.min(q), fr20.min(q), ff.min(col), tol::orbit_extremes, "min at the fold");
            check_agrees(fr.max(q), fr20.max(q), ff.max(col), tol::orbit_extremes, "max at the fold");
        }
    }
}

TEST_CASE("travelling waves: the full ring's multipliers along the reduced wave equal those of the full ring's orbit (N = 3)" * doctest::test_suite("slow")) {
    const int cars = 3;
    const FullRing full = full_ring(cars, 40);
    REQUIRE(full.branch.stop == "bound");
    TravellingWaveOptions o = wave_options(cars, 1, 40, 40, true);
    const TravellingWaveBranch w = travelling_wave_branch({}, o);
    REQUIRE(w.full_ring_stability);
    REQUIRE(w.branch.stop == "bound");
    const PeriodicOrbit& er = w.branch.points.back();
    const PeriodicOrbit& ef = full.branch.points.back();
    const PeriodicMesh mesh(4, 40);
    const std::vector<cplx> mf = orbit_multipliers(*full.ring.system, "headway", mesh, ef.profile, ef.period, ef.par);
    REQUIRE(!mf.empty());
    REQUIRE(!er.multipliers.empty());
    // by decreasing modulus: the trivial one first, then the largest nontrivial (stable: < 1)
    CHECK(std::abs(mf[0] - 1.0) < tol::orbit_trivial_multiplier);
    CHECK(er.stable);
    CHECK(std::abs(std::abs(mf[1]) - er.max_nontrivial) <= tol::wave_full_ring_multipliers);
    CHECK(er.trivial_distance <= tol::wave_full_ring_multipliers);
    // near the Hopf point the waves are unstable in the full ring (subcritical), after the fold stable
    CHECK(!w.branch.points.front().stable);
    CHECK(w.branch.points.front().max_nontrivial > 1.0);
}

TEST_CASE("travelling waves: 1000 cars, 100 per wave, the ring length held by every wave, no stability claimed") {
    TravellingWaveOptions o = wave_options(1000, 10, 40, 12, true);
    o.orbit.initial_step = 1e-3;  // long waves: the harmonics are nearly resonant at the Hopf point
    const TravellingWaveBranch w = travelling_wave_branch({}, o);
    REQUIRE(w.branch.status == Status::Converged);
    REQUIRE(w.branch.points.size() == 12);
    CHECK(!w.full_ring_stability);
    CHECK(w.max_drift < tol::wave_drift);
    const PeriodicMesh mesh(4, 40);
    for (const PeriodicOrbit& p : w.branch.points) {
        CHECK(p.residual <= 1e-8);
        CHECK(p.multipliers.empty());
        CHECK(!p.stable);
    }
    // the ring of 1000 cars at four instants: sum of the headways = N headway
    const PeriodicOrbit& last = w.branch.points.back();
    CHECK(last.max(0) - last.min(0) > 0.05);  // a wave, not the uniform flow
    for (double s : {0.0, 0.13, 0.5, 0.77}) {
        double sum = 0.0;
        for (long car = 0; car < 1000; ++car) sum += wave_car_state(mesh, last, 1000, 10, car, s)(0);
        CHECK(std::abs(sum / (1000 * last.par) - 1.0) <= tol::wave_ring_length);
    }
}

TEST_CASE("travelling waves: the 6-car IDM ring, reduced against full (supercritical Hopf point, the end orbit and its stability)" * doctest::test_suite("slow")) {
    // th = 1.2 s, tau = 0.6 s: the uniform flow loses stability below gap ~10.917 m (ring modes
    // 1 and 5); the waves born there are stable and exist for smaller gaps
    const int cars = 6;
    const ParameterMap parameters{{"th", 1.2}, {"tau", 0.6}};
    auto options = [&](int intervals, bool floquet) {
        TravellingWaveOptions o;
        o.model = "idm";
        o.cars = cars;
        o.wave = 1;
        o.orbit.parameter = "gap";
        o.orbit.from = 10.92;
        o.orbit.to = 10.85;
        o.orbit.intervals = intervals;
        o.orbit.max_points = 60;
        o.orbit.floquet = floquet;
        return o;
    };
    ParameterMap start = parameters;
    start["gap"] = 10.92;
    NonlinearRing ring = make_nonlinear_ring("idm", cars, start);
    EquilibriumBranchOptions eo;
    eo.parameter = "gap";
    eo.from = 10.92;
    eo.to = 10.85;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(*ring.system, ring.uniform_flow, eo);
    REQUIRE(eq.hopf.size() == 1);
    const OrbitBranch full = orbit_branch_from_hopf(*ring.system, eq.hopf[0], options(40, false).orbit);
    REQUIRE(full.stop == "bound");
    const TravellingWaveBranch w = travelling_wave_branch(parameters, options(40, true));
    const TravellingWaveBranch w20 = travelling_wave_branch(parameters, options(20, false));
    REQUIRE(w.hopf.status == Status::Converged);
    CHECK(std::abs(w.hopf.par - eq.hopf[0].par) <= tol::wave_vs_full_ring_floor);
    CHECK(std::abs(w.hopf.omega - eq.hopf[0].omega) <= tol::wave_vs_full_ring_floor);
    REQUIRE(w.branch.stop == "bound");
    REQUIRE(w20.branch.stop == "bound");
    const PeriodicOrbit& er = w.branch.points.back();
    const PeriodicOrbit& er20 = w20.branch.points.back();
    const PeriodicOrbit& ef = full.points.back();
    REQUIRE(er.par == 10.85);
    REQUIRE(ef.par == 10.85);
    check_agrees(er.period, er20.period, ef.period, tol::wave_vs_full_ring_floor, "period at gap 10.85");
    for (int q = 0; q < 2; ++q) {
        const int col = q == 0 ? 0 : cars - 1;  // s_0, v_0 of the full ring's state
        check_agrees(er.min(q), er20.min(q), ef.min(col), tol::orbit_extremes, "min at gap 10.85");
        check_agrees(er.max(q), er20.max(q), ef.max(col), tol::orbit_extremes, "max at gap 10.85");
    }
    // supercritical: stable waves in the full ring (its multipliers along the reduced wave)
    REQUIRE(w.full_ring_stability);
    REQUIRE(!er.multipliers.empty());
    CHECK(er.stable);
    CHECK(er.trivial_distance <= tol::wave_full_ring_multipliers);
}

TEST_CASE("travelling waves: bad input") {
    CHECK_THROWS_AS(travelling_wave_branch({}, wave_options(5, 0, 40, 5, false)), std::invalid_argument);
    CHECK_THROWS_AS(travelling_wave_branch({}, wave_options(5, 5, 40, 5, false)), std::invalid_argument);
    CHECK_THROWS_AS(travelling_wave_branch({}, wave_options(1, 1, 40, 5, false)), std::invalid_argument);
    TravellingWaveOptions o = wave_options(5, 1, 40, 5, false);
    o.model = "mackey-glass";  // not a ring model
    CHECK_THROWS_AS(travelling_wave_branch({}, o), std::invalid_argument);
    o = wave_options(5, 1, 40, 5, false);
    CHECK_THROWS_AS(travelling_wave_branch({{"gap", 20.0}}, o), std::invalid_argument);  // idm's parameter, not ov's
    o.orbit.parameter = "kappa";
    CHECK_THROWS_AS(travelling_wave_branch({}, o), std::invalid_argument);
    try {
        travelling_wave_branch({}, wave_options(5, 7, 40, 5, false));
        FAIL("expected std::invalid_argument");
    } catch (const std::invalid_argument& e) {
        CHECK(std::string(e.what()).find("wave = 7") != std::string::npos);
    }
}

TEST_CASE("travelling waves: the long wave of a 1000-car ring (K = 1) by the homotopy in K / N, converged under mesh refinement" * doctest::test_suite("slow")) {
    double period[2] = {0.0, 0.0};
    const int intervals[2] = {100, 200};
    for (int k = 0; k < 2; ++k) {
        TravellingWaveOptions o = wave_options(1000, 1, intervals[k], 6, false);
        const TravellingWaveBranch w = travelling_wave_branch({}, o);
        INFO(w.branch.message);
        REQUIRE(w.branch.status == Status::Converged);
        REQUIRE(w.branch.points.size() >= 2);
        CHECK(std::isfinite(w.homotopy_par));
        CHECK(w.homotopy_steps > 0);
        CHECK(w.branch.max_residual <= 1e-8);
        CHECK(w.max_drift <= tol::wave_drift);
        // the wave at the homotopy's parameter: the point where both sides join
        double best = 1e300;
        for (const PeriodicOrbit& p : w.branch.points)
            if (std::abs(p.par - w.homotopy_par) < best) {
                best = std::abs(p.par - w.homotopy_par);
                period[k] = p.period;
            }
        CHECK(best <= 1e-12);
    }
    CHECK(std::abs(period[0] - period[1]) <= tol::long_wave_period * period[1]);
}
