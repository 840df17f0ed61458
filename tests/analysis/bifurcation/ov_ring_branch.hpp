#pragma once
// The branch of periodic orbits in the headway (1.2 to 3) of the optimal-velocity ring of 3 cars
// (alpha = v0 = h_st = 1) at a given tau, from its lower Hopf point: shared by the fold-curve and
// bistability tests.
#include <doctest/doctest.h>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/traffic/ov_ring.hpp"

namespace ddemap::test {

inline PeriodicOrbitOptions ov3_headway_options() {
    PeriodicOrbitOptions o;
    o.parameter = "headway";
    o.from = 1.2;
    o.to = 3.0;
    o.max_points = 400;
    return o;
}

/// The equilibrium branch of the ring in the headway over [1.2, 3] (its two Hopf points required).
inline EquilibriumBranch ov3_headway_equilibria(const OvRing& ring) {
    EquilibriumBranchOptions eo;
    eo.parameter = "headway";
    eo.from = 1.2;
    eo.to = 3.0;
    EquilibriumBranch eq = equilibrium_branch(ring, ring.uniform_flow(), eo);
    REQUIRE(eq.hopf.size() == 2);
    return eq;
}

inline OrbitBranch ov3_headway_branch(double tau) {
    OvRing ring(3, 1.0, tau, 1.0, 1.0, 1.2);
    const EquilibriumBranch eq = ov3_headway_equilibria(ring);
    const HopfPoint& start = eq.hopf[0].par < eq.hopf[1].par ? eq.hopf[0] : eq.hopf[1];
    return orbit_branch_from_hopf(ring, start, ov3_headway_options());
}

}  // namespace ddemap::test
