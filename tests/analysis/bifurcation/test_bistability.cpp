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
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/ov_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::range;
using ddemap::test::simulate;

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
