// Verdicts next to the boundaries (issue 15, "Wrong or contradictory answers"): the string and
// N = inf ring verdicts at c2 = +-1e-9, tiny delays against the tau = 0 polynomial roots, the
// computable range, marginal cases and --count.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/ring.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;
using test::ovrv;

namespace {

/// OVRV k2 for which c2 = 2 k1 [k1 th^2/2 + k2 th - 1 - tau (k1 th + k2)] equals `c2` exactly
/// (in exact arithmetic).
double ovrv_k2_for_c2(double c2, double k1, double th, double tau) {
    return (c2 / (2.0 * k1) + 1.0 + tau * k1 * th - k1 * th * th / 2.0) / (th - tau);
}

/// min over a grid of w in [w_lo, w_hi] of |D(i w)|^2 - |N(i w)|^2 for OVRV, in long double
/// (a second evaluation, 2^11 times finer rounding than double, independent of the library).
long double ovrv_min_loss(double k1, double k2, double th, double tau, double w_lo, double w_hi) {
    long double worst = 1e300L;
    for (int i = 0; i <= 4000; ++i) {
        const long double w = w_lo * std::pow((long double)w_hi / w_lo, i / 4000.0L);
        const std::complex<long double> s(0.0L, w), e = std::exp(-s * (long double)tau);
        const std::complex<long double> n = ((long double)k1 + (long double)k2 * s) * e;
        const std::complex<long double> d = s * s + ((long double)k1 * th + k2) * s + (long double)k1 * e;
        worst = std::min(worst, std::norm(d) - std::norm(n));
    }
    return worst;
}

/// The spectral abscissa of the OVRV ring of N cars at tau = 0 from the roots of the quadratics
/// lambda^2 + (k1 th + k2 - zeta k2) lambda + k1 (1 - zeta) = 0, zeta = e^{-2 pi i m / N}, m = 1..N-1,
/// and lambda = -(k1 th) of mode 0 (its other root is the trivial 0).
double ovrv_ring_abscissa_tau0(double k1, double k2, double th, int cars) {
    double best = -k1 * th;
    for (int m = 1; m < cars; ++m) {
        const std::complex<double> zeta = std::polar(1.0, -2.0 * M_PI * m / cars);
        const std::complex<double> b = k1 * th + k2 - zeta * k2, c = k1 * (1.0 - zeta);
        const std::complex<double> root = std::sqrt(b * b - 4.0 * c);
        best = std::max({best, (0.5 * (-b + root)).real(), (0.5 * (-b - root)).real()});
    }
    return best;
}

}  // namespace

TEST_CASE("string and N = inf ring verdicts on both sides of c2 = 0, down to 1e-9 (OVRV)") {
    const double k1 = 0.2, th = 1.5;
    for (double tau : {0.1, 0.2}) {
        for (double c2 : {1e-5, -1e-5, 1e-7, -1e-7, 1e-9, -1e-9}) {
            CAPTURE(tau);
            CAPTURE(c2);
            const double k2 = ovrv_k2_for_c2(c2, k1, th, tau);
            const Linearisation lin = ovrv(k1, k2, th, tau);
            // independent: the closed form lands on the intended side, and (where long double
            // resolves c2 w^2 at w = 1e-5 against eps |D|^2 ~ 4e-21) the sign of |D|^2 - |N|^2
            // over w in [1e-5, 3] follows c2
            const double c2_closed = 2.0 * k1 * (k1 * th * th / 2.0 + k2 * th - 1.0 - tau * (k1 * th + k2));
            REQUIRE((c2_closed > 0.0) == (c2 > 0.0));
            if (std::abs(c2) >= 1e-7) {
                const long double lowest = ovrv_min_loss(k1, k2, th, tau, 1e-5, 3.0);
                REQUIRE((lowest > 0.0L) == (c2 > 0.0));
            }
            const StringResult s = analyse_string(lin);
            CHECK(s.plant_verdict == Verdict::Stable);
            CHECK(s.string_verdict == (c2 > 0.0 ? Verdict::Stable : Verdict::Unstable));
            CHECK(s.string_stable == (c2 > 0.0));
            // never sup 1, margin 0 and unstable together; the margin carries the sign
            if (c2 > 0.0) CHECK(s.peak_margin > 0.0);
            else CHECK(s.peak_margin < 0.0);
            const RingResult r = analyse_ring(lin, 0);
            CHECK(r.status == Status::Converged);
            CHECK(r.verdict == (c2 > 0.0 ? Verdict::Stable : Verdict::Unstable));
            CHECK(r.stable == (c2 > 0.0));
            if (c2 > 0.0) {
                CHECK(r.spectral_abscissa == 0.0);
                CHECK(r.abscissa_is_limit);
                CHECK(r.marginal_roots == 0);
            } else {
                CHECK(r.spectral_abscissa > 0.0);
            }
        }
    }
}

TEST_CASE("string verdict on both sides of c2 = 0 for IDM, down to 1e-9") {
    // c2 as a function of the time headway th: bisection for its zero, then steps off it
    auto lin_at = [](double th) {
        return make_model("idm", {{"th", th}, {"tau", 0.3}, {"speed", 15.0}})->linearise();
    };
    auto c2_at = [&](double th) { return low_frequency_expansion(lin_at(th)).c2; };
    double lo = 0.5, hi = 4.0;
    REQUIRE(c2_at(lo) * c2_at(hi) < 0.0);
    const bool rising = c2_at(hi) > 0.0;
    for (int i = 0; i < 200 && hi - lo > 1e-15 * hi; ++i) {
        const double mid = 0.5 * (lo + hi);
        ((c2_at(mid) > 0.0) == rising ? hi : lo) = mid;
    }
    const double slope = (c2_at(hi + 1e-4) - c2_at(hi - 1e-4)) / 2e-4;
    REQUIRE(std::abs(slope) > 0.0);
    for (double target : {1e-5, -1e-5, 1e-7, -1e-7, 1e-9, -1e-9}) {
        CAPTURE(target);
        const double th = hi + target / slope;
        const Linearisation lin = lin_at(th);
        const LowFrequency lf = low_frequency_expansion(lin);
        REQUIRE((lf.c2 > 0.0) == (target > 0.0));  // the step lands on the intended side
        // independent: 1 - |Gamma|^2 = w^2 q / |D|^2 and q -> c2; direct |D|^2 - |N|^2 at w where
        // c2 w^2 still dominates rounding (|c2| w^2 >> eps |D|^2) has the same sign
        const TransferFunction tf(lin);
        // w where c2 w^2 dominates c4 w^4 (w <= 0.3 sqrt|c2/c4|), if rounding still resolves it there
        const double w = 0.3 * std::sqrt(std::abs(lf.c2 / lf.c4));
        if (std::abs(lf.c2) * w * w > 1e3 * 2.2e-16 * std::norm(tf.denominator(cplx(0.0, w)))) {
            const cplx s(0.0, w);
            CHECK(((std::norm(tf.denominator(s)) - std::norm(tf.numerator(s))) > 0.0) == (target > 0.0));
        }
        const StringResult s = analyse_string(lin);
        CHECK(s.plant_verdict == Verdict::Stable);
        CHECK(s.string_verdict == (target > 0.0 ? Verdict::Stable : Verdict::Unstable));
        if (target > 0.0) CHECK(s.peak_margin > 0.0);
        else CHECK(s.peak_margin < 0.0);
    }
}

TEST_CASE("tiny delays: roots and verdicts converge to the tau = 0 polynomial roots") {
    const double k1 = 0.2, k2 = 0.2, th = 1.5;
    const int cars = 22;
    const double a0 = ovrv_ring_abscissa_tau0(k1, k2, th, cars);
    REQUIRE(a0 > 0.0);  // the case of the issue: +0.0382 at tau = 0
    RingOptions o;
    o.roots.count = 3;
    for (double tau : {1e-300, 1e-12, 1e-9, 1e-6}) {
        CAPTURE(tau);
        const RingResult r = analyse_ring(ovrv(k1, k2, th, tau), cars, o);
        CHECK(r.status == Status::Converged);
        CHECK(r.verdict == Verdict::Unstable);
        CHECK(std::abs(r.spectral_abscissa - a0) <= tol::tau_continuity * tau + tol::root_abs);
        const StringResult s = analyse_string(ovrv(k1, k2, th, tau));
        CHECK(s.plant_roots.status == Status::Converged);
        // tau = 0 plant: lambda^2 + (k1 th + k2) lambda + k1, both roots Re = -(k1 th + k2)/2 = -0.25
        CHECK(s.plant_verdict == Verdict::Stable);
        CHECK(std::abs(s.plant_abscissa + 0.5 * (k1 * th + k2)) <= tol::tau_continuity * tau + tol::root_abs);
        CHECK(s.string_verdict == Verdict::Unstable);  // c2 = -0.19 at tau = 0
    }
}

TEST_CASE("computable range: c tau_max <= 10 and c <= 1e8 computed, beyond refused") {
    const double th = 1.5, k2 = 0.2, tau = 0.2;
    // c = k1 (1 + th) + 2 k2; c tau = 10 at k1 = (10 / tau - 2 k2) / (1 + th)
    const double k1_edge = (kMaxScaledDelay / tau - 2.0 * k2) / (1.0 + th);
    const Linearisation inside = ovrv(k1_edge * (1.0 - 1e-6), k2, th, tau);
    const Linearisation outside = ovrv(k1_edge * (1.0 + 1e-6), k2, th, tau);
    CHECK(scaled_delay(inside) <= kMaxScaledDelay);
    CHECK(scaled_delay(outside) > kMaxScaledDelay);
    CHECK_NOTHROW(require_computable(inside));
    CHECK_THROWS_AS(require_computable(outside), std::invalid_argument);
    CHECK_THROWS_AS(analyse_ring(outside, 22), std::invalid_argument);
    CHECK_THROWS_AS(analyse_string(outside), std::invalid_argument);
    CHECK_THROWS_AS(analyse_string(ovrv(1e300, k2, th, 0.0)), std::invalid_argument);
    CHECK_THROWS_AS(analyse_string(ovrv(0.2, 1e20, th, 0.0)), std::invalid_argument);
    CHECK_NOTHROW(require_computable(ovrv(0.999e8 / 2.5, 0.0, th, 0.0)));
    // inside the range the ring is decided; every listed root solves its mode's equation
    // D(lambda) - zeta N(lambda) = 0 (evaluated directly from the transfer function)
    const RingResult r = analyse_ring(inside, 22);
    CHECK(r.status == Status::Converged);
    CHECK(r.verdict != Verdict::Undecided);
    const TransferFunction tf(inside);
    for (const auto& x : r.roots) {
        if (x.mode == 0) continue;
        const cplx z = x.root.value, zeta = ring_zeta(x.mode, 22);
        const cplx f = tf.denominator(z) - zeta * tf.numerator(z);
        CHECK(std::abs(f) <= 1e-9 * (std::norm(z) + std::abs(tf.numerator(z)) + 1.0));
    }
}

TEST_CASE("marginal is not unstable, and --count is honoured") {
    // k1 = 0: gap = 0, so lambda = 0 solves every mode (D(0) = N(0) = 0): marginal everywhere
    const Linearisation lin = ovrv(0.0, 0.2, 1.5, 0.2);
    RingOptions o;
    o.roots.count = 6;
    const RingResult r = analyse_ring(lin, 22, o);
    CHECK(r.status == Status::Converged);
    CHECK(r.unstable_roots == 0);
    CHECK(r.marginal_roots > 0);
    CHECK(r.verdict == Verdict::Marginal);
    CHECK_FALSE(r.stable);
    CHECK(r.roots.size() == 6u);
    const RingResult inf = analyse_ring(lin, 0, o);
    CHECK(inf.verdict == Verdict::Marginal);
    CHECK(inf.roots.size() >= 6u);
    CHECK(inf.roots.size() <= 7u);  // a conjugate partner of the last may be added
    const StringResult s = analyse_string(lin);
    CHECK(s.plant_verdict == Verdict::Marginal);
    CHECK(s.string_verdict == Verdict::Marginal);
    // an ordinary case: exactly count rows (plus at most a conjugate partner)
    for (int count : {1, 3, 6}) {
        o.roots.count = count;
        const RingResult q = analyse_ring(ovrv(0.2, 0.2, 1.5, 0.2), 22, o);
        CHECK(q.roots.size() >= std::size_t(count));
        CHECK(q.roots.size() <= std::size_t(count + 1));
    }
}

TEST_CASE("never a verdict from an unconverged computation") {
    RingOptions o;
    o.roots.dense.max_degree = 8;  // too small to settle: max_degree_reached
    const RingResult r = analyse_ring(ovrv(0.2, 0.2, 1.5, 0.5), 22, o);
    REQUIRE(r.status != Status::Converged);
    CHECK(r.verdict == Verdict::Undecided);
    CHECK_FALSE(r.stable);
    StringOptions so;
    so.roots.dense.max_degree = 8;
    const StringResult s = analyse_string(ovrv(0.2, 0.2, 1.5, 0.5), so);
    REQUIRE(s.plant_roots.status != Status::Converged);
    CHECK(s.plant_verdict == Verdict::Undecided);
    CHECK(s.string_verdict == Verdict::Undecided);
}

TEST_SUITE_END();
