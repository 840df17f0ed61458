#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <vector>

#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/problem/expression_system.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

/// DDE-BIFTOOL's minimal demo (demos/minimal_demo/minimal_demo.m; Yanchuk and Perlikowski,
/// PRE 79, 046221, 2009), the same system as examples/duffing.json:
///     x1' = x2,  x2' = -d x2 - a x1 - x1^3 - b (x1 - x1(t - tau)),  a = 0.5, b = 0.6, d = 0.05.
ExpressionSystem duffing() {
    return ExpressionSystem({"x1", "x2"}, {"a", "b", "d", "tau"}, {0.5, 0.6, 0.05, 2.0},
                            {"x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"});
}

/// The orbits from the Hopf point at tau = 7.3195 (the second on the trivial equilibrium's
/// branch in tau, omega = 1.30248), continued in tau, degree 4 on `intervals` uniform intervals.
OrbitBranch duffing_orbits(const ExpressionSystem& sys, int intervals) {
    const HopfPoint h = correct_hopf(sys, sys.parameter_index("tau"), Eigen::VectorXd::Zero(2), 7.32, 1.30);
    REQUIRE(h.status == Status::Converged);
    PeriodicOrbitOptions o;
    o.parameter = "tau";
    o.from = 0.0;
    o.to = 20.0;
    o.degree = 4;
    o.intervals = intervals;
    o.max_points = 12;  // the torus is crossed between the 8th and 9th orbits
    return orbit_branch_from_hopf(sys, h, o);
}

int outside_unit_circle(const std::vector<cplx>& mu) {
    int count = 0;
    for (const cplx& m : mu)
        if (std::abs(m) > 1.0 + 1e-6) ++count;  // the trivial multiplier (1 to 1e-10 here) is not counted
    return count;
}

// DDE-BIFTOOL under Octave (its GitHub repository, current snapshot), run by
// bench/ddebiftool/duffing_torus.m: the same branch (degree 4, uniform mesh, no mesh
// adaptation), the crossing complex pair's |mu| - 1 brought to zero (below 1e-11) by regula falsi
// in tau on orbits corrected by DDE-BIFTOOL's p_correc, multipliers by its p_stabil. Its torus
// points on 20 / 30 / 40 intervals: tau = 7.051523359224 / 7.051523362412 / 7.051523363438 (ddemap:
// 7.051523379416 / 7.051523361893 / 7.051523363684): the two discretisations are not identical
// (on 20 intervals they differ by 2e-8, each by its own mesh error), from 30 intervals on they
// agree to 5e-10 (on 80 intervals: DDE-BIFTOOL 7.051523363295, ddemap 7.051523363322). The demo's
// published output shows the torus curves in (tau, b) but no torus value on this one-parameter
// branch, so these are from our own DDE-BIFTOOL runs.
struct DdeBiftoolTorus {
    int intervals;
    double tau, period;
};
const DdeBiftoolTorus ddebiftool_l30{30, 7.051523362412, 4.645341627581};
const DdeBiftoolTorus ddebiftool_l40{40, 7.051523363438, 4.645341627784};
const cplx ddebiftool_mu_l30(-0.5817100259, 0.8133962415);

}  // namespace

TEST_CASE("Duffing oscillator with delayed feedback (DDE-BIFTOOL minimal demo): the torus bifurcation of its orbits, against DDE-BIFTOOL") {
    const ExpressionSystem sys = duffing();
    const OrbitBranch b = duffing_orbits(sys, 30);
    REQUIRE(b.status == Status::Converged);
    // one torus point, and no fold or period doubling reported on this part of the branch
    REQUIRE(b.tori.size() == 1);
    CHECK(b.folds.empty());
    CHECK(b.period_doublings.empty());
    const OrbitCrossing& t = b.tori.front();
    REQUIRE(t.located);
    MESSAGE("torus at tau = " << t.par << ", period " << t.period << ", mu = " << t.multiplier);
    // the same point as DDE-BIFTOOL's on the same mesh
    CHECK(std::abs(t.par - ddebiftool_l30.tau) <= tol::torus_vs_ddebiftool);
    CHECK(std::abs(t.period - ddebiftool_l30.period) <= tol::torus_vs_ddebiftool);
    CHECK(std::abs(t.multiplier - ddebiftool_mu_l30) <= tol::torus_vs_ddebiftool);
    // a complex pair (not a real multiplier at -1 or +1), on the unit circle
    CHECK(t.multiplier.imag() > 0.5);
    CHECK(t.accuracy <= 1e-9);
    CHECK(t.par_bracket < 1e-5);

    // residual check: the multipliers recomputed on their own from the located orbit have a
    // complex pair on the unit circle, one multiplier at 1 (the trivial one) and none at -1
    const PeriodicMesh mesh(b.degree, t.orbit.breakpoints);
    const std::vector<cplx> mu = orbit_multipliers(sys, "tau", mesh, t.orbit.profile, t.orbit.period, t.orbit.par);
    REQUIRE(!mu.empty());
    int on_circle_complex = 0, at_one = 0, at_minus_one = 0;
    for (const cplx& m : mu) {
        if (std::abs(m.imag()) > 1e-3 && std::abs(std::abs(m) - 1.0) <= 1e-9) ++on_circle_complex;
        if (std::abs(m - 1.0) <= tol::orbit_trivial_multiplier) ++at_one;
        if (std::abs(m + 1.0) <= 1e-3) ++at_minus_one;
    }
    CHECK(on_circle_complex == 2);  // mu and its conjugate
    CHECK(at_one == 1);
    CHECK(at_minus_one == 0);

    // the crossing: two more multipliers outside the unit circle before it than after it (the pair
    // enters the circle as tau decreases along the branch; DDE-BIFTOOL: 3 unstable, then 1)
    const auto k = static_cast<std::size_t>(t.after);
    REQUIRE(k + 1 < b.points.size());
    CHECK(outside_unit_circle(b.points[k].multipliers) == outside_unit_circle(b.points[k + 1].multipliers) + 2);
    CHECK(outside_unit_circle(b.points[k + 1].multipliers) == 1);
    CHECK((t.par - b.points[k].par) * (t.par - b.points[k + 1].par) < 0.0);
}

TEST_CASE("Duffing oscillator: the torus point converges as the mesh is refined, and agrees with DDE-BIFTOOL's on 40 intervals" * doctest::test_suite("slow")) {
    const ExpressionSystem sys = duffing();
    std::vector<double> taus, periods;
    for (const int intervals : {20, 40, 80}) {
        const OrbitBranch b = duffing_orbits(sys, intervals);
        REQUIRE(b.tori.size() == 1);
        REQUIRE(b.tori.front().located);
        taus.push_back(b.tori.front().par);
        periods.push_back(b.tori.front().period);
        MESSAGE(intervals << " intervals: torus at tau = " << b.tori.front().par << ", period " << b.tori.front().period);
    }
    // the change from 20 to 40 intervals is larger than from 40 to 80 (measured 1.6e-8 and 3.6e-10)
    CHECK(std::abs(taus[1] - taus[2]) < std::abs(taus[0] - taus[1]));
    CHECK(std::abs(periods[1] - periods[2]) < std::abs(periods[0] - periods[1]));
    CHECK(std::abs(taus[1] - ddebiftool_l40.tau) <= tol::torus_vs_ddebiftool);
    CHECK(std::abs(periods[1] - ddebiftool_l40.period) <= tol::torus_vs_ddebiftool);
    // and the finest mesh is within the tolerance of DDE-BIFTOOL's 40 intervals too (the mesh
    // error of both at 40 intervals is below 1e-9)
    CHECK(std::abs(taus[2] - ddebiftool_l40.tau) <= tol::torus_vs_ddebiftool);
}

TEST_CASE("torus curve in (tau, b) of DDE-BIFTOOL's minimal demo: Floquet multipliers on it, its end at the double Hopf point, and a one-parameter branch's torus on it" *
          doctest::test_suite("slow")) {
    const ExpressionSystem sys = duffing();
    const OrbitBranch b = duffing_orbits(sys, 30);
    REQUIRE(b.tori.size() == 1);
    OrbitFoldCurveOptions fo;
    fo.orbit.parameter = "tau";
    fo.orbit.from = 0.0;
    fo.orbit.to = 20.0;
    fo.orbit.degree = 4;
    fo.orbit.intervals = 30;
    fo.orbit.max_points = 30;
    fo.parameter2 = "b";
    fo.from2 = 0.3;
    fo.to2 = 0.9;
    const OrbitFoldCurve c = orbit_torus_curve(sys, b.tori.front(), fo);
    INFO(c.message);
    REQUIRE(c.status == Status::Converged);
    REQUIRE(c.points.size() > 10);
    CHECK(c.stop_backward == "hopf");
    CHECK(c.stop_forward == "bound");
    // 1. every point: the orbit's Floquet multipliers (the monodromy matrix's eigenvalues, not the
    // bordered test) have e^{i phi} on the unit circle
    for (const OrbitFoldCurvePoint& q : c.points) {
        CHECK(q.test < 1e-10);
        CHECK(q.second_distance < 1e-9);
        CHECK(q.rotation > 0.0);
        CHECK(q.rotation < M_PI);
    }
    // 2. it ends where the orbits shrink onto the double Hopf point of the trivial equilibrium
    // (the Hopf curves of hopf_curves cross at tau = 8.728742694, b = 0.3544448049 with omega
    // 0.70836009 and 1.0975498): the orbits there have period 2 pi / 1.0975498 and the other pair's
    // multiplier e^{i 2 pi 0.70836009 / 1.0975498}
    const OrbitFoldCurvePoint& end = c.points.front();
    const double w_orbit = 1.0975498, w_other = 0.70836009;
    CHECK(std::abs(end.par - 8.728742694) < 1e-4);
    CHECK(std::abs(end.par2 - 0.3544448049) < 1e-4);
    CHECK(std::abs(end.orbit.period - 2.0 * M_PI / w_orbit) < 1e-3);
    CHECK(std::abs(end.rotation - std::abs(std::remainder(2.0 * M_PI * w_other / w_orbit, 2.0 * M_PI))) < 1e-3);
    // 3. a second path: at the b of a point of the curve, the branch in tau alone has its torus
    // bifurcation at that point's tau (the same mesh)
    auto torus_in_tau = [&](double bval, double near) {
        ExpressionSystem sys2 = duffing();
        sys2.set_parameter("b", bval);
        EquilibriumBranchOptions eo;
        eo.parameter = "tau";
        eo.from = 0.0;
        eo.to = 20.0;
        const EquilibriumBranch eq = equilibrium_branch(sys2, Eigen::VectorXd::Zero(2), eo);
        const HopfPoint* start = nullptr;
        for (const HopfPoint& h : eq.hopf)  // the second of the pair omega ~ 1.25, as at b = 0.6
            if (h.omega > 1.0 && (!start || std::abs(h.par - near) < std::abs(start->par - near))) start = &h;
        REQUIRE(start != nullptr);
        PeriodicOrbitOptions o = fo.orbit;
        o.max_points = 40;
        const OrbitBranch b2 = orbit_branch_from_hopf(sys2, *start, o);
        REQUIRE(!b2.tori.empty());
        REQUIRE(b2.tori.front().located);
        return b2.tori.front();
    };
    const OrbitFoldCurvePoint* q = nullptr;
    for (const OrbitFoldCurvePoint& p : c.points)
        if (!q || std::abs(p.par2 - 0.52) < std::abs(q->par2 - 0.52)) q = &p;
    const OrbitCrossing t2 = torus_in_tau(q->par2, q->par);
    MESSAGE("curve point tau = " << q->par << " at b = " << q->par2 << "; the branch in tau: torus at " << t2.par << " (difference "
                                    << t2.par - q->par << ")");
    CHECK(std::abs(t2.par - q->par) < 1e-8);
    CHECK(std::abs(std::arg(t2.multiplier) - q->rotation) < 1e-7);
    // 4. DDE-BIFTOOL's torus curve (SetupTorusBifurcation from the same torus, the same mesh:
    // bench/ddebiftool/duffing_torus_curve.m) passes (b, tau) = (0.526247199475, 7.448995471658)
    // and (0.856384049708, 6.046997638618); ddemap's torus points at those b (3.4e-9 and 9.9e-10)
    CHECK(std::abs(torus_in_tau(0.526247199475, 7.45).par - 7.448995471658) < 1e-8);
    CHECK(std::abs(torus_in_tau(0.856384049708, 6.05).par - 6.046997638618) < 1e-8);
}
