// The ring envelope (BoundaryOptions::ring_curves = Envelope): arcs of the modes' Hopf curves
// that bound the ring-stable region, seeded from the winding sweep, checked against the
// per-mode curves (RingCurves::All), the per-mode ring analysis, and the sweep's verdicts.
#include <doctest/doctest.h>

#include "tolerances.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/study/boundary.hpp"
#include "chart_helpers.hpp"

namespace tol = ddemap::test::tol;

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

double X(const SweepSpec& s, double x) { return (x - s.x.lo) / (s.x.hi - s.x.lo); }
double Y(const SweepSpec& s, double y) { return (y - s.y.lo) / (s.y.hi - s.y.lo); }

/// Distance (window units) from (px, py) to the polyline of a curve.
double polyline_distance(const SweepSpec& s, double px, double py, const BoundaryCurve& c) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
        const double ax = X(s, c.points[i].x), ay = Y(s, c.points[i].y);
        const double dx = X(s, c.points[i + 1].x) - ax, dy = Y(s, c.points[i + 1].y) - ay;
        const double l2 = dx * dx + dy * dy;
        const double t = l2 > 0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / l2, 0.0, 1.0) : 0.0;
        best = std::min(best, std::hypot(px - ax - t * dx, py - ay - t * dy));
    }
    return best;
}

bool segments_cross(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
    auto o = [](double px, double py, double qx, double qy, double rx, double ry) {
        const double v = (qx - px) * (ry - py) - (qy - py) * (rx - px);
        return v > 0 ? 1 : (v < 0 ? -1 : 0);
    };
    return o(ax, ay, bx, by, cx, cy) != o(ax, ay, bx, by, dx, dy) && o(cx, cy, dx, dy, ax, ay) != o(cx, cy, dx, dy, bx, by);
}

BoundarySet trace(const SweepResult& sw, RingCurves r) {
    BoundaryOptions o;
    o.ring_curves = r;
    return trace_boundaries(sw, o);
}

/// Every grid edge with unstable ring roots at one end only (both ends certified) is crossed by a
/// ring arc, or one of its ends lies within the chords' sag of one.
void check_edges_crossed(const SweepResult& sw, const BoundarySet& set) {
    const SweepSpec& s = sw.spec;
    const int nx = s.x.count, ny = s.y.count;
    int edges = 0;
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix)
            for (int dir = 0; dir < 2; ++dir) {
                const int jx = ix + (dir == 0), jy = iy + (dir == 1);
                if (jx >= nx || jy >= ny) continue;
                const SweepPoint &a = sw.at(ix, iy), &b = sw.at(jx, jy);
                if (!a.certified || !b.certified || (a.unstable_roots > 0) == (b.unstable_roots > 0)) continue;
                ++edges;
                const double ax = X(s, a.x), ay = Y(s, a.y), bx = X(s, b.x), by = Y(s, b.y);
                bool crossed = false;
                for (const auto& c : set.curves) {
                    if (c.kind != BoundaryKind::RingHopf) continue;
                    for (std::size_t i = 0; i + 1 < c.points.size() && !crossed; ++i)
                        crossed = segments_cross(ax, ay, bx, by, X(s, c.points[i].x), Y(s, c.points[i].y), X(s, c.points[i + 1].x),
                                                 Y(s, c.points[i + 1].y));
                    crossed = crossed || polyline_distance(s, ax, ay, c) < tol::envelope_edge ||
                              polyline_distance(s, bx, by, c) < tol::envelope_edge;
                    if (crossed) break;
                }
                CAPTURE(a.x);
                CAPTURE(a.y);
                CAPTURE(dir);
                CHECK(crossed);
            }
    CHECK(edges > 0);
}

/// The same curves, bit for bit: kind, mode and every point.
void check_same_curves(const BoundarySet& a, const BoundarySet& b) {
    REQUIRE(a.curves.size() == b.curves.size());
    for (std::size_t i = 0; i < a.curves.size(); ++i) {
        CHECK(a.curves[i].kind == b.curves[i].kind);
        CHECK(a.curves[i].mode == b.curves[i].mode);
        REQUIRE(a.curves[i].points.size() == b.curves[i].points.size());
        for (std::size_t k = 0; k < a.curves[i].points.size(); ++k) {
            CHECK(a.curves[i].points[k].x == b.curves[i].points[k].x);
            CHECK(a.curves[i].points[k].y == b.curves[i].points[k].y);
            CHECK(a.curves[i].points[k].omega == b.curves[i].points[k].omega);
        }
    }
}

}  // namespace

TEST_CASE("envelope arcs lie on their modes' Hopf curves, the ones RingCurves::All traces (N = 22, 100)" * doctest::test_suite("slow")) {
    for (int cars : {22, 100}) {
        CAPTURE(cars);
        SweepSpec spec = ddemap::test::ovrv_chart(41, cars, 1.5, 0.5);
        const SweepResult winding = run_sweep(spec);
        REQUIRE(winding.ring_method == "winding");
        const BoundarySet env = trace(winding, RingCurves::Envelope);
        CHECK(env.ring_curves == RingCurves::Envelope);
        spec.ring_method = "modes";
        const BoundarySet all = trace(run_sweep(spec), RingCurves::All);
        int arcs = 0, points = 0;
        for (const auto& c : env.curves) {
            if (c.kind != BoundaryKind::RingHopf) continue;
            ++arcs;
            CAPTURE(c.mode);
            CHECK(c.max_residual < 1e-11);
            const BoundaryCurve* same = nullptr;
            for (const auto& a : all.curves)
                if (a.kind == BoundaryKind::RingHopf && a.mode == c.mode) same = &a;
            REQUIRE(same != nullptr);
            for (const auto& p : c.points) {
                CHECK(p.omega > 0.0);
                CHECK(boundary_residual(spec, BoundaryKind::RingHopf, c.mode, p) < 1e-10);
                CHECK(polyline_distance(spec, X(spec, p.x), Y(spec, p.y), *same) < tol::envelope_vs_all);
                ++points;
            }
        }
        CHECK(arcs >= 1);
        CHECK(arcs < static_cast<int>(all.curves.size()));  // only the boundary, not every mode's curve
        CHECK(points > 20);
        check_edges_crossed(winding, env);
    }
}

TEST_CASE("at envelope points the per-mode ring analysis puts the crossing pair on the axis and every other mode left of it" * doctest::test_suite("slow")) {
    for (int cars : {22, 100}) {
        CAPTURE(cars);
        const SweepSpec spec = ddemap::test::ovrv_chart(41, cars, 1.5, 0.5);
        const BoundarySet env = trace(run_sweep(spec), RingCurves::Envelope);
        int sampled = 0;
        for (const auto& c : env.curves) {
            if (c.kind != BoundaryKind::RingHopf) continue;
            for (std::size_t i = 0; i < c.points.size(); i += 7) {
                const auto& p = c.points[i];
                const RingResult r = analyse_ring(model_at(spec, p.x, p.y)->linearise(), cars);
                CAPTURE(p.x);
                CAPTURE(p.y);
                REQUIRE(r.status == Status::Converged);
                CHECK(std::abs(r.spectral_abscissa) < tol::envelope_abscissa);
                for (const auto& root : r.roots) {
                    if (root.root.value.real() < -tol::envelope_abscissa) continue;
                    // on the axis: only the traced mode's pair (mode m at +w, N - m at -w)
                    CHECK((root.mode == c.mode || root.mode == cars - c.mode || root.mode == 0));
                    CHECK(std::abs(std::abs(root.root.value.imag()) - p.omega) < 1e-6 * std::max(1.0, p.omega));
                }
                ++sampled;
            }
        }
        CHECK(sampled >= 5);
    }
}

TEST_CASE("the envelope of a ring of 10^6 cars: arcs on their modes' curves from the winding sweep, every verdict change crossed") {
    const SweepSpec spec = ddemap::test::ovrv_chart(41, 1000000, 1.5, 0.5);
    const SweepResult sw = run_sweep(spec);
    REQUIRE(sw.modes == 0);  // no per-mode roots: the winding tables
    const BoundarySet env = trace(sw, RingCurves::Auto);
    CHECK(env.ring_curves == RingCurves::Envelope);
    int arcs = 0;
    for (const auto& c : env.curves) {
        if (c.kind != BoundaryKind::RingHopf) continue;
        ++arcs;
        CHECK(c.max_residual < 1e-11);
        for (const auto& p : c.points) CHECK(boundary_residual(spec, BoundaryKind::RingHopf, c.mode, p) < 1e-10);
    }
    CHECK(arcs >= 1);
    check_edges_crossed(sw, env);
}

TEST_CASE("a 2-car ring whose unstable side has a real rightmost root: the seed finds the crossing by a frequency scan") {
    SweepSpec spec;
    spec.fixed = {{"th", 0.6}, {"tau", 0.9}};
    spec.x = parse_axis("k1", "0.01:3:41");
    spec.y = parse_axis("k2", "0.01:3:41");
    spec.cars = 2;
    const SweepResult sw = run_sweep(spec);
    bool real_root = false;  // the premise: the winding sweep gives frequency 0 at some unstable point
    for (const auto& p : sw.points) real_root = real_root || (p.unstable_roots > 0 && p.abscissa_omega == 0.0);
    CHECK(real_root);
    const BoundarySet env = trace(sw, RingCurves::Envelope);
    SweepSpec modes = spec;
    modes.ring_method = "modes";
    const BoundarySet all = trace(run_sweep(modes), RingCurves::All);
    int arcs = 0;
    for (const auto& c : env.curves) {
        if (c.kind != BoundaryKind::RingHopf) continue;
        ++arcs;
        const BoundaryCurve* same = nullptr;
        for (const auto& a : all.curves)
            if (a.kind == BoundaryKind::RingHopf && a.mode == c.mode) same = &a;
        REQUIRE(same != nullptr);
        for (const auto& p : c.points) {
            CHECK(boundary_residual(spec, BoundaryKind::RingHopf, c.mode, p) < 1e-10);
            CHECK(polyline_distance(spec, X(spec, p.x), Y(spec, p.y), *same) < tol::envelope_vs_all);
        }
    }
    CHECK(arcs >= 1);
    check_edges_crossed(sw, env);
}

TEST_CASE("N = inf: the boundaries from the winding sweep equal those from the per-mode sweep") {
    SweepSpec spec = ddemap::test::ovrv_chart(31, 0, 1.5, 0.5);
    const BoundarySet a = trace(run_sweep(spec), RingCurves::Auto);
    spec.ring_method = "modes";
    const BoundarySet b = trace(run_sweep(spec), RingCurves::All);
    CHECK(a.curves.size() >= 1);
    check_same_curves(a, b);
}

TEST_CASE("the envelope is the same for 1 and 2 threads") {
    const SweepSpec spec = ddemap::test::ovrv_chart(31, 200, 1.5, 0.5);
    ExecutionPolicy one, two;
    one.threads = 1;
    two.threads = 2;
    const BoundarySet a = trace(run_sweep(spec, one), RingCurves::Envelope);
    const BoundarySet b = trace(run_sweep(spec, two), RingCurves::Envelope);
    check_same_curves(a, b);
}

TEST_CASE("ring curves: names, auto by ring size, envelope refused for a law with two leaders") {
    CHECK(parse_ring_curves("all") == RingCurves::All);
    CHECK(parse_ring_curves("envelope") == RingCurves::Envelope);
    CHECK(parse_ring_curves("auto") == RingCurves::Auto);
    CHECK_THROWS_AS(parse_ring_curves("some"), std::invalid_argument);
    CHECK(ring_curves_name(RingCurves::Envelope) == "envelope");
    CHECK(resolve_ring_curves(RingCurves::Auto, ddemap::test::ovrv_chart(5, kEnvelopeAutoCars, 1.5, 0.5)) == RingCurves::All);
    CHECK(resolve_ring_curves(RingCurves::Auto, ddemap::test::ovrv_chart(5, kEnvelopeAutoCars + 1, 1.5, 0.5)) == RingCurves::Envelope);
    CHECK(resolve_ring_curves(RingCurves::Auto, ddemap::test::ovrv_chart(5, 0, 1.5, 0.5)) == RingCurves::Envelope);
    CHECK(resolve_ring_curves(RingCurves::All, ddemap::test::ovrv_chart(5, 0, 1.5, 0.5)) == RingCurves::All);
    SweepSpec ccc = ddemap::test::ovrv_chart(5, 100, 1.5, 0.5);
    ccc.model = "ccc";
    ccc.fixed["k3"] = 0.2;
    ccc.fixed["tau2"] = 0.5;
    CHECK(resolve_ring_curves(RingCurves::Auto, ccc) == RingCurves::All);
    CHECK_THROWS_AS(resolve_ring_curves(RingCurves::Envelope, ccc), std::invalid_argument);
}

TEST_SUITE_END();
