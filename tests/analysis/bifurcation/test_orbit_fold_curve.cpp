// Curves of folds of periodic orbits in two parameters (orbit_fold_curve), on the optimal-velocity
// ring of 3 cars in (headway, tau): checked against the folds of one-parameter branches at another
// tau (a second path), against the generalised Hopf points of the Hopf curves (where a fold curve
// of orbits must end), and against the Floquet multipliers (a double multiplier 1 at a fold).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "tolerances.hpp"
#include "analysis/bifurcation/ov_ring_branch.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/traffic/ov_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

using ddemap::test::ov3_headway_options;

OrbitFoldCurveOptions curve_options(double from2, double to2) {
    OrbitFoldCurveOptions f;
    f.orbit = ov3_headway_options();
    f.orbit.from = 0.5;
    f.orbit.to = 5.0;
    f.orbit.max_points = 200;
    f.parameter2 = "tau";
    f.from2 = from2;
    f.to2 = to2;
    return f;
}

/// The two multipliers nearest 1 at a fold curve's point are both near it (a fold of orbits makes
/// the trivial multiplier double), while a regular orbit has only one there.
void check_double_multiplier(const OrbitFoldCurvePoint& q) {
    REQUIRE(q.orbit.multipliers.size() >= 2);
    CHECK(q.second_distance <= orbit_accuracy_limit);
}

}  // namespace

TEST_CASE("fold curve of orbits (ov ring N = 3): its point on the face tau = 0.8 is the fold of the one-parameter branch at tau = 0.8" *
          doctest::test_suite("slow")) {
    const OrbitBranch at1 = ddemap::test::ov3_headway_branch(1.0);
    REQUIRE(at1.folds.size() == 2);
    const OrbitBranch at08 = ddemap::test::ov3_headway_branch(0.8);
    REQUIRE(at08.status == Status::Converged);
    REQUIRE(at08.folds.size() == 2);
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    for (const OrbitFold& fold : at1.folds) {
        CAPTURE(fold.par);
        const OrbitFoldCurve c = orbit_fold_curve(ring, fold, curve_options(0.8, 1.2));
        CHECK(c.status == Status::Converged);
        REQUIRE(c.points.size() >= 3);
        CHECK(c.stop_backward == "bound");  // towards tau = 0.8 (tau decreases backward)
        const OrbitFoldCurvePoint& end = c.points.front();
        CHECK(end.par2 == doctest::Approx(0.8).epsilon(1e-12));
        // the fold of the branch at tau = 0.8 nearest the curve's end
        double best = 1e9, period = 0.0;
        for (const OrbitFold& f : at08.folds)
            if (std::abs(f.par - end.par) < std::abs(best - end.par)) {
                best = f.par;
                period = f.period;
            }
        CHECK(std::abs(end.par - best) <= tol::fold_curve_vs_branch);
        CHECK(std::abs(end.orbit.period - period) <= tol::fold_curve_vs_branch * period);
        // the start is the given fold, and every point a fold: g = 0 and a double multiplier 1
        CHECK(std::abs(c.points[static_cast<std::size_t>(c.start)].par - fold.par) <= tol::fold_curve_vs_branch);
        CHECK(c.max_test <= 1e-12);
        CHECK(c.max_residual <= 1e-8);
        for (const OrbitFoldCurvePoint& q : c.points) check_double_multiplier(q);
    }
    // a regular orbit of the branch (between its folds) has its second multiplier far from 1
    const PeriodicOrbit& mid = at1.points[static_cast<std::size_t>((at1.folds[0].after + at1.folds[1].after) / 2)];
    std::vector<double> dist;
    for (cplx m : mid.multipliers) dist.push_back(std::abs(m - 1.0));
    std::sort(dist.begin(), dist.end());
    REQUIRE(dist.size() >= 2);
    CHECK(dist[1] > 10 * orbit_accuracy_limit);
}

TEST_CASE("fold curves of orbits (ov ring N = 3) end at the generalised Hopf points of the Hopf curves" * doctest::test_suite("slow")) {
    // the Hopf curves in (headway, tau) and their generalised Hopf points (L1 = 0), by the Hopf
    // system without any orbit: where the criticality changes, a fold curve of orbits is born
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    HopfCurveOptions ho;
    ho.branch.parameter = "headway";
    ho.branch.from = 1.2;
    ho.branch.to = 5.0;
    ho.parameter2 = "tau";
    ho.from2 = 0.3;
    ho.to2 = 2.0;
    const HopfCurves hc = hopf_curves(ring, ring.uniform_flow(), ho);
    std::vector<GeneralisedHopfPoint> gh;
    for (const HopfCurve& c : hc.curves)
        for (const GeneralisedHopfPoint& g : c.generalised)
            if (g.status == Status::Converged) gh.push_back(g);
    REQUIRE(gh.size() == 2);
    const OrbitBranch at1 = ddemap::test::ov3_headway_branch(1.0);
    REQUIRE(at1.folds.size() == 2);
    std::vector<bool> met(gh.size(), false);
    for (const OrbitFold& fold : at1.folds) {
        CAPTURE(fold.par);
        const OrbitFoldCurve c = orbit_fold_curve(ring, fold, curve_options(0.3, 2.0));
        CHECK(c.status == Status::Converged);
        CHECK(c.stop_backward == "hopf");
        CHECK(c.stop_forward == "bound");
        const OrbitFoldCurvePoint& end = c.points.front();
        const double amp = (end.orbit.max - end.orbit.min).maxCoeff();
        CHECK(amp < 0.05);
        // near a generalised Hopf point the fold curve lies O(a^2) from it (a the amplitude) and the
        // period tends to the Hopf curve's 2 pi / omega there
        std::size_t k = 0;
        for (std::size_t i = 1; i < gh.size(); ++i)
            if (std::hypot(gh[i].par - end.par, gh[i].par2 - end.par2) < std::hypot(gh[k].par - end.par, gh[k].par2 - end.par2)) k = i;
        CAPTURE(gh[k].par);
        CAPTURE(gh[k].par2);
        CAPTURE(end.par);
        CAPTURE(end.par2);
        CHECK(std::hypot(gh[k].par - end.par, gh[k].par2 - end.par2) <= amp * amp + tol::fold_curve_floor);
        CHECK(std::abs(end.orbit.period * gh[k].omega / (2.0 * 3.14159265358979323846) - 1.0) <= amp * amp + tol::fold_curve_floor);
        met[k] = true;
        for (std::size_t i = 0; i < c.points.size(); ++i)
            if ((c.points[i].orbit.max - c.points[i].orbit.min).maxCoeff() > 0.1) check_double_multiplier(c.points[i]);
    }
    CHECK(met[0]);
    CHECK(met[1]);
}

TEST_CASE("fold curve options: bad input is std::invalid_argument") {
    OvRing ring(3, 1.0, 1.0, 1.0, 1.0, 1.2);
    OrbitFold fold;
    fold.par = 1.3;
    fold.orbit.period = 11.0;
    fold.orbit.profile = Eigen::MatrixXd::Zero(160, ring.dimension());
    OrbitFoldCurveOptions f = curve_options(0.3, 2.0);
    f.parameter2 = "headway";
    CHECK_THROWS_AS(orbit_fold_curve(ring, fold, f), std::invalid_argument);  // the first parameter again
    f = curve_options(0.3, 0.3);
    CHECK_THROWS_AS(orbit_fold_curve(ring, fold, f), std::invalid_argument);  // an empty range
    f = curve_options(1.5, 2.0);
    CHECK_THROWS_AS(orbit_fold_curve(ring, fold, f), std::invalid_argument);  // tau = 1 outside it
    f = curve_options(0.3, 2.0);
    f.parameter2 = "no_such";
    CHECK_THROWS_AS(orbit_fold_curve(ring, fold, f), std::invalid_argument);
    f = curve_options(0.3, 2.0);
    fold.orbit.profile = Eigen::MatrixXd::Zero(100, ring.dimension());  // not the mesh's 160 points
    CHECK_THROWS_AS(orbit_fold_curve(ring, fold, f), std::invalid_argument);
}

TEST_SUITE_END();
