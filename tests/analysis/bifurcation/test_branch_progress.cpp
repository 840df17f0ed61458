// The progress callbacks of the branches (equilibria, Hopf curves, periodic orbits): called once
// per finished point with (done, total, parameter), and a callback that throws stops the work
// after that point with its exception reaching the caller (how Ctrl-C stops them from Python).
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "fleet_helpers.hpp"
#include "numeric_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

using ddemap::test::pi;

/// What a callback saw.
struct Seen {
    std::vector<long> done, total;
    std::vector<double> par;
};

/// The calls that report a newly finished unit (the count changed): a branch repeats the last
/// count from within a point's root search (a heartbeat), and those repeats are dropped here.
Seen finished(const Seen& all) {
    Seen s;
    long last = 0;
    for (std::size_t k = 0; k < all.done.size(); ++k) {
        if (all.done[k] == last) continue;
        last = all.done[k];
        s.done.push_back(all.done[k]);
        s.total.push_back(all.total[k]);
        s.par.push_back(all.par[k]);
    }
    return s;
}

/// Records every call; throws `Stop` at the call with done == stop_at (never when 0).
struct Stop : std::runtime_error {
    Stop() : std::runtime_error("stopped by the caller") {}
};
BranchProgress recorder(Seen& seen, long stop_at = 0) {
    return [&seen, stop_at](long done, long total, double par) {
        seen.done.push_back(done);
        seen.total.push_back(total);
        seen.par.push_back(par);
        if (stop_at > 0 && done == stop_at) throw Stop();
    };
}

}  // namespace

TEST_CASE("equilibrium branch: one progress call per point after its roots, and a throwing callback stops it") {
    // x' = p - x(t - 1)^2: the branch x = sqrt(p) with a fold at p = 0 (tests/cli/test_cli.sh)
    const ExpressionSystem sys({"x"}, {"p"}, {0.9}, {"p - x(t - 1)^2"});
    EquilibriumBranchOptions o;
    o.parameter = "p";
    o.from = 0.9;
    o.to = -1.0;
    Seen all;
    o.progress = recorder(all);
    const EquilibriumBranch b = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.9), o);
    const std::size_t n = b.points.size();
    REQUIRE(n > 5);
    const Seen seen = finished(all);
    REQUIRE(seen.done.size() == n);
    // the pilot points first (the ends, the middle, the quarters), then the others in order
    std::vector<std::size_t> order = {0, n - 1, n / 2, n / 4, (3 * n) / 4};
    for (std::size_t k = 1; k + 1 < n; ++k)
        if (k != n / 2 && k != n / 4 && k != (3 * n) / 4) order.push_back(k);
    REQUIRE(order.size() == n);
    for (std::size_t k = 0; k < n; ++k) {
        CHECK(seen.done[k] == static_cast<long>(k + 1));
        CHECK(seen.total[k] == static_cast<long>(n));  // known: the continuation ran first
        CHECK(seen.par[k] == b.points[order[k]].par);
    }
    // the repeats come from within a point: the count of the points finished before it
    for (std::size_t k = 0; k < all.done.size(); ++k) CHECK((all.done[k] >= 0 && all.done[k] <= static_cast<long>(n)));

    Seen stopped;
    o.progress = recorder(stopped, 3);
    CHECK_THROWS_AS(equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.9), o), Stop);
    CHECK(finished(stopped).done == std::vector<long>{1, 2, 3});
    CHECK(stopped.done.back() == 3);  // nothing after the throwing call
}

TEST_CASE("equilibrium branch: the size guard sees the points before any root and the pilots' measured time, and may refuse") {
    const ExpressionSystem sys({"x"}, {"p"}, {0.9}, {"p - x(t - 1)^2"});
    EquilibriumBranchOptions o;
    o.parameter = "p";
    o.from = 0.9;
    o.to = -1.0;
    std::vector<int> measured;
    std::vector<long> points;
    std::vector<double> seconds;
    long progress_calls = 0;
    o.progress = [&](long, long, double) { ++progress_calls; };
    o.before_roots = [&](long n, const RootWorkEstimate& one, int m) {
        if (m == 0) CHECK(progress_calls == 0);  // before any root
        measured.push_back(m);
        points.push_back(n);
        seconds.push_back(one.seconds);
    };
    const EquilibriumBranch b = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.9), o);
    REQUIRE(b.points.size() > 5);
    CHECK(measured == std::vector<int>{0, 1, 2, 3, 4, 5});
    for (const long n : points) CHECK(n == static_cast<long>(b.points.size()));
    for (const double s : seconds) CHECK((std::isfinite(s) && s > 0.0));

    // the same branch with and without the guard (the order of the roots changes nothing)
    EquilibriumBranchOptions plain = o;
    plain.before_roots = nullptr;
    plain.progress = nullptr;
    const EquilibriumBranch c = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.9), plain);
    REQUIRE(c.points.size() == b.points.size());
    for (std::size_t k = 0; k < b.points.size(); ++k) {
        CHECK(c.points[k].par == b.points[k].par);
        CHECK(c.points[k].unstable == b.points[k].unstable);
        CHECK(c.points[k].abscissa == b.points[k].abscissa);
    }

    // a guard that refuses before the roots: no point's roots computed
    progress_calls = 0;
    o.before_roots = [](long, const RootWorkEstimate&, int) { throw Stop(); };
    CHECK_THROWS_AS(equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.9), o), Stop);
    CHECK(progress_calls == 0);
}

TEST_CASE("ring: the size guard of the per-mode path sees N/2 + 1 modes before any is solved") {
    const Linearisation lin = test::ovrv(0.2, 0.2, 1.5, 0.1);  // the paper's example
    RingOptions o;
    long modes = -1, progress_calls = 0;
    o.progress = [&](long, long) { ++progress_calls; };
    o.before = [&](long m, const RootWorkEstimate& one) {
        CHECK(progress_calls == 0);
        CHECK((std::isfinite(one.seconds) && one.seconds > 0.0));
        modes = m;
    };
    const RingResult r = analyse_ring(lin, 9, o);
    CHECK(modes == 5);
    CHECK(progress_calls >= 5);
    o.before = [](long, const RootWorkEstimate&) { throw Stop(); };
    progress_calls = 0;
    CHECK_THROWS_AS(analyse_ring(lin, 9, o), Stop);
    CHECK(progress_calls == 0);
}

TEST_CASE("Hopf curve: one progress call per traced point, and a throwing callback stops the continuation") {
    // the curve a tau = pi/2 of x' = -a x(t - tau) + x x(t - tau) - x^3 (test_hopf.cpp)
    const ExpressionSystem sys({"x"}, {"a", "tau"}, {1.0, 1.0}, {"-a*x(t - tau) + x*x(t - tau) - x^3"});
    HopfCurveOptions o;
    o.branch.parameter = "a";
    o.branch.from = 1.0;
    o.branch.to = 2.5;
    o.parameter2 = "tau";
    o.from2 = 0.7;
    o.to2 = 2.0;
    Seen branch, curve;
    o.branch.progress = recorder(branch);
    o.progress = recorder(curve);
    const HopfCurves hc = hopf_curves(sys, Eigen::VectorXd::Zero(1), o);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& c = hc.curves[0];
    CHECK(finished(branch).done.size() == hc.start.branch.points.size());
    // every point but the start (a Hopf point of the branch) is reported, numbered from 2
    REQUIRE(curve.done.size() + 1 == c.points.size());
    for (std::size_t k = 0; k < curve.done.size(); ++k) {
        CHECK(curve.done[k] == static_cast<long>(k + 2));
        CHECK(curve.total[k] == 2L * o.continuation.max_points - 1);
        CHECK((curve.par[k] >= 1.0 && curve.par[k] <= 2.5));  // p1 = a, in its box
    }
    // the backward pass is reported last, and its last point is the curve's first
    CHECK(curve.par.back() == c.points.front().par);

    Seen stopped;
    o.progress = recorder(stopped, 5);
    CHECK_THROWS_AS(hopf_curves(sys, Eigen::VectorXd::Zero(1), o), Stop);
    CHECK(stopped.done == std::vector<long>{2, 3, 4, 5});
}

TEST_CASE("periodic orbits: one progress call per orbit, and a throwing callback stops the branch") {
    // Wright's equation from its Hopf point alpha = omega = pi/2 (test_periodic_orbit.cpp)
    const ExpressionSystem sys({"y"}, {"alpha"}, {1.6}, {"-alpha*y(t - 1)*(1 + y)"});
    HopfPoint h;
    h.par = pi / 2;
    h.omega = pi / 2;
    h.x = Eigen::VectorXd::Zero(1);
    h.q = VectorXc::Constant(1, cplx(1.0, 0.0));
    h.status = Status::Converged;
    PeriodicOrbitOptions o;
    o.parameter = "alpha";
    o.from = 1.5;
    o.to = 2.0;
    o.max_points = 8;
    o.intervals = 20;
    Seen seen;
    o.progress = recorder(seen);
    const OrbitBranch b = orbit_branch_from_hopf(sys, h, o);
    REQUIRE(b.points.size() >= 4);
    REQUIRE(seen.done.size() == b.points.size());
    for (std::size_t k = 0; k < b.points.size(); ++k) {
        CHECK(seen.done[k] == static_cast<long>(k + 1));
        CHECK(seen.total[k] == 8);
        CHECK(seen.par[k] == b.points[k].par);
    }

    Seen stopped;
    o.progress = recorder(stopped, 3);
    CHECK_THROWS_AS(orbit_branch_from_hopf(sys, h, o), Stop);
    CHECK(stopped.done == std::vector<long>{1, 2, 3});
}

TEST_CASE("ring of N cars, per-mode path: one progress call per mode of the first pass, and a throwing callback stops it") {
    const Linearisation lin = test::ovrv(0.2, 0.2, 1.5, 0.1);  // the paper's example
    std::vector<long> done;
    RingOptions o;
    o.progress = [&](long d, long total) {
        CHECK(total == 12);  // N / 2 + 1 modes
        done.push_back(d);
    };
    const RingResult r = analyse_ring(lin, 22, o);
    CHECK(r.modes_solved >= 12);
    REQUIRE(done.size() == 12);
    for (std::size_t k = 0; k < done.size(); ++k) CHECK(done[k] == static_cast<long>(k + 1));
    // the same through analyse_ring_fast on the per-mode path, stopped after 5 modes
    long calls = 0;
    const Progress stop = [&](long d, long) {
        ++calls;
        if (d == 5) throw std::runtime_error("stopped by the caller");
    };
    CHECK_THROWS_AS(analyse_ring_fast(lin, 22, "modes", 6, stop), std::runtime_error);
    CHECK(calls == 5);
}
