// Large gains with a short delay (c tau small, entries of the collocation ~ M^2 / tau): the
// certified short-delay path against the tau = 0 closed form, the quasi-polynomial itself and an
// argument-principle count of the roots right of -1/tau (a second, independent computation).
#include <doctest/doctest.h>

#include <cmath>
#include <complex>

#include "ddemap/solve/roots.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

// x' = y, y' = -(k1 th + k2) y - k1 (1 - z) x(t - tau) + z k2 y(t - tau) (an OVRV ring mode with
// a real ring factor z): D(lambda) = lambda^2 + (k1 th + k2) lambda + (k1 (1 - z) - z k2 lambda) e^{-lambda tau}
struct Mode {
    double k1, k2, th, z, tau;
    LinearDDE dde() const {
        MatrixXc a0 = MatrixXc::Zero(2, 2), a1 = MatrixXc::Zero(2, 2);
        a0(0, 1) = 1.0;
        a0(1, 1) = -(k1 * th + k2);
        a1(1, 0) = -k1 * (1.0 - z);
        a1(1, 1) = z * k2;
        return LinearDDE(a0, {{a1, tau}});
    }
    cplx d(cplx s) const { return s * s + (k1 * th + k2) * s + (k1 * (1.0 - z) - z * k2 * s) * std::exp(-s * tau); }
    // the tau = 0 roots: s^2 + (k1 th + k2 - z k2) s + k1 (1 - z) = 0
    void limit(cplx& a, cplx& b) const {
        const double p = k1 * th + k2 - z * k2, q = k1 * (1.0 - z);
        const cplx root = std::sqrt(cplx(p * p - 4.0 * q, 0.0));
        b = (-p - root) / 2.0;  // p > 0: no cancellation; the small root from the product a b = q
        a = q / b;
    }
};

// The number of zeros of D in the rectangle [left, right] x [-b, b]: the change of arg D along its
// boundary, walked with steps halved until arg moves by at most 0.2 rad and doubled after.
int winding(const Mode& m, double left, double right, double b) {
    const cplx corners[5] = {{right, -b}, {right, b}, {left, b}, {left, -b}, {right, -b}};
    double total = 0.0;
    for (int e = 0; e < 4; ++e) {
        const cplx from = corners[e], to = corners[e + 1];
        const double length = std::abs(to - from);
        double t = 0.0, h = 1e-6 * length;
        cplx prev = m.d(from);
        while (t < length) {
            const double step = std::min(h, length - t);
            const cplx next = m.d(from + (to - from) * ((t + step) / length));
            const double da = std::arg(next / prev);
            if (std::abs(da) > 0.2 && step > 1e-14 * length) {
                h = step / 2.0;
                continue;
            }
            total += da;
            prev = next;
            t += step;
            h = 2.0 * step;
        }
    }
    return static_cast<int>(std::lround(total / (2.0 * M_PI)));
}

}  // namespace

TEST_CASE("large gains, short delay: certified roots near the tau = 0 roots, complete by the argument principle") {
    for (double k1 : {1e3, 1e6}) {
        for (double tau : {1e-12, 1e-9, 1e-7}) {
            const Mode m{k1, 0.2, 1.5, 0.5, tau};
            CAPTURE(k1);
            CAPTURE(tau);
            RootOptions o;
            o.count = 2;
            const RootResult r = rightmost_roots(m.dde(), o);
            REQUIRE(r.status == Status::Converged);
            REQUIRE(r.roots.size() == 2);
            // the certified path (degree 0) is complete right of -1/tau: the argument principle on
            // D along the rectangle [-1/tau, 1] x [-B, B] (B = 10 (4 k1 + 1): every root with
            // Re >= -1/tau has |lambda| <= k1 th + k2 + e (k1 + k2) < 4 k1 + 1) counts the same two roots
            if (r.degree == 0) {
                CHECK(r.strip_floor <= -1.0 / tau * (1.0 - 1e-12));
                CHECK(winding(m, -1.0 / tau, 1.0, 10.0 * (k1 * 4.0 + 1.0)) == 2);
            }
            cplx slow, fast;
            m.limit(slow, fast);
            // each root solves D = 0 (relative to the size of its terms) ...
            for (const auto& x : r.roots) {
                const cplx s = x.value;
                const double size = std::norm(s) + (k1 * 1.5 + 0.2) * std::abs(s) + k1 + 0.2 * std::abs(s);
                CHECK(std::abs(m.d(s)) <= tol::product_residual * size);
            }
            // ... and is the tau = 0 root moved by O(c tau |lambda|), c = k1 (1 + th) + 2 k2
            const double c = k1 * 2.5 + 0.4;
            CHECK(std::abs(r.roots[0].value - slow) <= tol::short_delay_move * c * tau * std::abs(slow));
            CHECK(std::abs(r.roots[1].value - fast) <= tol::short_delay_move * c * tau * std::abs(fast));
        }
    }
}
