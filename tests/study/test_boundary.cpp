// Boundary continuation against the closed-form D-subdivision curves of OVRV (docs/mathematics.md section 4).
#include <doctest/doctest.h>

#include "tolerances.hpp"

#include <cmath>

#include "ddemap/study/boundary.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "chart_helpers.hpp"

namespace tol = ddemap::test::tol;

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
/// Closed form: k1 [i w th + e^{-i w tau}(1 - zeta)] + k2 [i w (1 - zeta e^{-i w tau})] = w^2.
void closed_form(double w, cplx zeta, double th, double tau, double& k1, double& k2) {
    const cplx e = std::exp(cplx(0.0, -w * tau));
    const cplx a = cplx(0.0, w * th) + e * (1.0 - zeta);
    const cplx b = cplx(0.0, w) * (1.0 - zeta * e);
    const double det = a.real() * b.imag() - b.real() * a.imag();
    k1 = w * w * b.imag() / det;
    k2 = -w * w * a.imag() / det;
}
}  // namespace

TEST_CASE("ring Hopf curves equal the closed-form D-subdivision curves to 1e-8") {
    for (const auto& [th, tau] : {std::pair{1.5, 0.5}, std::pair{1.0, 0.2}}) {
        const SweepSpec spec = ddemap::test::ovrv_chart(31, 12, th, tau);
        const SweepResult sweep = run_sweep(spec);
        const BoundarySet set = trace_boundaries(sweep);
        int ring_points = 0, ring_curves = 0;
        for (const auto& c : set.curves) {
            CHECK(c.max_residual < 1e-11);
            if (c.kind != BoundaryKind::RingHopf) continue;
            ++ring_curves;
            const cplx zeta = ring_zeta(c.mode, 12);
            for (const auto& p : c.points) {
                CHECK(p.omega > 0.0);
                if (c.mode == 0) continue;  // mode 0 crosses only where f_s (1 - zeta) = 0
                double k1, k2;
                closed_form(p.omega, zeta, th, tau, k1, k2);
                CAPTURE(c.mode);
                CAPTURE(p.omega);
                CHECK(std::abs(k1 - p.x) < tol::boundary_closed_form);
                CHECK(std::abs(k2 - p.y) < tol::boundary_closed_form);
                ++ring_points;
            }
        }
        CHECK(ring_curves >= 1);
        CHECK(ring_curves <= 12);  // each branch traced once, not once per seed
        CHECK(ring_points > 50);
        // every branch runs to the window edges (or closes, or its frequency reaches 0)
        for (const auto& c : set.curves) {
            CAPTURE(subkind_name(c.kind));
            CAPTURE(c.mode);
            CHECK(c.points.size() >= 5);
            if (c.closed) continue;
            for (const auto* e : {&c.points.front(), &c.points.back()}) {
                const bool edge = std::abs(e->x - 0.01) < 1e-9 || std::abs(e->x - 1) < 1e-9 ||
                                  std::abs(e->y - 0.01) < 1e-9 || std::abs(e->y - 1) < 1e-9;
                CHECK((edge || std::abs(e->omega) < 0.05));
            }
        }
    }
}

TEST_CASE("the low-frequency string boundary is c2 = 0 and ends on the window edges") {
    const SweepSpec spec = ddemap::test::ovrv_chart(31, 12, 1.5, 0.5);
    const BoundarySet set = trace_boundaries(run_sweep(spec));
    int found = 0;
    for (const auto& c : set.curves) {
        if (c.kind != BoundaryKind::LowFrequency) continue;
        ++found;
        for (const auto& p : c.points) {
            // OVRV closed form: k1 th^2/2 + k2 th = 1 + tau (k1 th + k2)
            CHECK(std::abs(p.x * 1.5 * 1.5 / 2 + p.y * 1.5 - 1 - 0.5 * (p.x * 1.5 + p.y)) < 1e-9);
        }
        const auto& a = c.points.front();
        const auto& b = c.points.back();
        auto on_edge = [](const BoundaryPoint& p) {
            return std::abs(p.x - 0.01) < 1e-9 || std::abs(p.x - 1) < 1e-9 || std::abs(p.y - 0.01) < 1e-9 || std::abs(p.y - 1) < 1e-9;
        };
        CHECK(on_edge(a));
        CHECK(on_edge(b));
    }
    CHECK(found == 1);
}

TEST_CASE("a model that is not linear in its parameters: IDM boundaries have vanishing residuals") {
    SweepSpec spec;
    spec.model = "idm";
    spec.fixed = {{"tau", 0.6}, {"speed", 15.0}};
    spec.x = parse_axis("th", "0.3:2.5:25");
    spec.y = parse_axis("a", "0.3:2.5:25");
    spec.cars = 20;
    const SweepResult sweep = run_sweep(spec);
    const BoundarySet set = trace_boundaries(sweep);
    int points = 0;
    for (const auto& c : set.curves)
        for (const auto& p : c.points) {
            CHECK(boundary_residual(spec, c.kind, c.mode, p) < 1e-10);
            ++points;
        }
    CHECK(points > 20);
}

TEST_SUITE_END();
