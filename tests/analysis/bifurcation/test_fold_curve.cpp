// Fold curves of equilibria in two parameters (analysis/bifurcation/fold_curve.hpp) against
// closed forms: the cusp of x' = p1 + p2 x(t - 1) - x^3, and a Bogdanov-Takens point whose place
// depends on the delay, x' = p1 + x^2 + p2 x(t - 2).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tolerances.hpp"
#include "two_parameter_box.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/problem/expression_system.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

FoldCurveOptions fold_box(const std::string& p1, double from, double to, const std::string& p2, double from2, double to2) {
    return test::two_parameter_box<FoldCurveOptions>(p1, from, to, p2, from2, to2);
}

/// max |p1 - p2^2 / 4| over the curve's points: the fold curve of x' = p1 + x^2 + p2 x(t - tau)
/// (and of the same law with -p2) in closed form.
double off_parabola(const FoldCurve& c) {
    double e = 0.0;
    for (const FoldCurvePoint& p : c.points) e = std::max(e, std::abs(p.par - p.par2 * p.par2 / 4));
    return e;
}

/// The one fold curve of a converged result (checked).
const FoldCurve& only_curve(const FoldCurves& fc) {
    INFO(fc.message);
    CHECK(fc.status == Status::Converged);
    REQUIRE(fc.curves.size() == 1);
    return fc.curves[0];
}

}  // namespace

TEST_CASE("fold curve with a cusp: x' = p1 + p2 x(t - 1) - x^3, the curve (p1, p2) = (-2 x^3, 3 x^2)") {
    // F(x) = p1 + p2 x - x^3: F = F_x = 0 gives p2 = 3 x^2, p1 = -2 x^3, one curve through both
    // folds of the branch in p1 at p2 = 1 (x = -+1/sqrt(3)); the cusp (F_xx = -6 x = 0) at the origin
    ExpressionSystem sys({"x"}, {"p1", "p2"}, {-1.0, 1.0}, {"p1 + p2*x(t - 1) - x^3"});
    Eigen::VectorXd guess(1);
    guess << -1.3;
    const FoldCurves fc = fold_curves(sys, guess, fold_box("p1", -1.5, 1.5, "p2", -0.5, 2.0));
    INFO(fc.message);
    CHECK(fc.status == Status::Converged);
    REQUIRE(fc.start.folds.size() == 2);
    REQUIRE(fc.curves.size() == 1);  // the second fold lies on the first one's curve
    const FoldCurve& c = fc.curves[0];
    CHECK(c.stop_forward == ContinuationStop::Bound);
    CHECK(c.stop_backward == ContinuationStop::Bound);
    REQUIRE(c.points.size() > 20);
    double xmin = 1e300, xmax = -1e300;
    for (const FoldCurvePoint& p : c.points) {
        const double x = p.x[0];
        CHECK(std::abs(p.par2 - 3 * x * x) < tol::special_point);
        CHECK(std::abs(p.par + 2 * x * x * x) < tol::special_point);
        CHECK(p.residual < 1e-9);
        // the tests: a = w F'' v^2 = -+6 x (w's sign carried along), b = w (1 + tau p2) v, |b| = 1 + p2
        CHECK(std::abs(std::abs(p.cusp_test) - 6 * std::abs(x)) < 1e-8);
        CHECK(std::abs(std::abs(p.bt_test) - (1 + p.par2)) < 1e-8);
        xmin = std::min(xmin, x);
        xmax = std::max(xmax, x);
    }
    // both ends on the face p2 = 2: x = -+sqrt(2/3)
    CHECK(std::abs(xmin + std::sqrt(2.0 / 3.0)) < tol::special_point);
    CHECK(std::abs(xmax - std::sqrt(2.0 / 3.0)) < tol::special_point);
    REQUIRE(c.special.size() == 1);
    const FoldCurveSpecialPoint& cusp = c.special[0];
    CHECK(cusp.kind == "cusp");
    CHECK(cusp.status == Status::Converged);
    CHECK(std::abs(cusp.x[0]) < tol::special_point);
    CHECK(std::abs(cusp.par) < tol::special_point);
    CHECK(std::abs(cusp.par2) < tol::special_point);
    CHECK(std::abs(std::abs(cusp.other) - 1.0) < tol::special_point);  // b = 1 + p2 there: not a BT point
    // the normal form w' = b w^2 + c w^3 there: q = p = 1 (Delta'(0) = 1 + p2 = 1), c = F_xxx / 6 = -1
    CHECK(std::abs(cusp.nf_b) < tol::normal_form_located);
    CHECK(std::abs(cusp.nf_c + 1.0) < tol::normal_form_located);
    CHECK(std::isnan(cusp.nf_a));
    // the sign of a changes at the cusp and nowhere else (w carried continuously)
    int changes = 0;
    for (std::size_t k = 0; k + 1 < c.points.size(); ++k) changes += (c.points[k].cusp_test < 0) != (c.points[k + 1].cusp_test < 0);
    CHECK(changes == 1);
}

TEST_CASE("two cusps 0.003 apart in p2 on a box of width 2: both located, against the closed form") {
    // F(x) = p1 + p2 x + a x^2 - x^4 (a = 0.02): F = F_x = 0 gives p2 = 4 x^3 - 2 a x,
    // p1 = a x^2 - 3 x^4; the cusps where F_xx = 2 a - 12 x^2 = 0, x = -+sqrt(a/6): p1 = a^2/12,
    // p2 = -+(4 a/3) sqrt(a/6) = -+0.0015396. The steps are at most 0.05 of the box (0.1 in p2),
    // 30 times the cusps' distance: a sign test on the step's ends alone would see no change
    // and both would be missed (the tracer shortens its steps where the curve turns at a cusp).
    const double a = 0.02;
    ExpressionSystem sys({"x"}, {"p1", "p2", "a"}, {0.2, 0.5, a}, {"p1 + p2*x(t - 1) + a*x(t - 1)^2 - x^4"});
    Eigen::VectorXd guess(1);
    guess << 0.902;
    const FoldCurves fc = fold_curves(sys, guess, fold_box("p1", 0.2, -0.5, "p2", -1.0, 1.0));
    INFO(fc.message);
    REQUIRE(!fc.curves.empty());
    std::vector<double> p2;
    for (const FoldCurve& c : fc.curves)
        for (const FoldCurveSpecialPoint& sp : c.special)
            if (sp.kind == "cusp") {
                CHECK(sp.status == Status::Converged);
                CHECK(std::abs(sp.par - a * a / 12) < tol::special_point);
                CHECK(std::abs(std::abs(sp.x[0]) - std::sqrt(a / 6)) < tol::special_point);
                p2.push_back(sp.par2);
            }
    REQUIRE(p2.size() == 2);
    std::sort(p2.begin(), p2.end());
    const double p2c = 4 * a / 3 * std::sqrt(a / 6);
    CHECK(std::abs(p2[0] + p2c) < tol::special_point);
    CHECK(std::abs(p2[1] - p2c) < tol::special_point);
}

TEST_CASE("fold curve with a Bogdanov-Takens point: x' = p1 + x^2 + p2 x(t - tau), the double root at 0 where p2 = -1/tau") {
    // F(x) = p1 + x^2 + p2 x: folds at x = -p2/2, p1 = p2^2/4; Delta(lambda) = lambda - 2 x - p2 e^{-lambda tau}
    // has Delta(0) = 0 there and Delta'(0) = 1 + tau p2 = 0 at p2 = -1/tau: the Bogdanov-Takens point
    // (p1, p2) = (1/(4 tau^2), -1/tau), x = 1/(2 tau). No cusp (F_xx = 2).
    for (double tau : {2.0, 0.8}) {
        CAPTURE(tau);
        ExpressionSystem sys({"x"}, {"p1", "p2", "tau"}, {-0.5, 0.5, tau}, {"p1 + x^2 + p2*x(t - tau)"});
        Eigen::VectorXd guess(1);
        guess << -1.0;  // -0.5 + 1 - 0.5 = 0 at p1 = -0.5, p2 = 0.5
        const FoldCurves fc = fold_curves(sys, guess, fold_box("p1", -0.5, 2.0, "p2", -1.5, 1.5));
        const FoldCurve& c = only_curve(fc);
        CHECK(off_parabola(c) < tol::special_point);
        for (const FoldCurvePoint& p : c.points) CHECK(std::abs(p.x[0] + p.par2 / 2) < tol::special_point);
        REQUIRE(c.special.size() == 1);
        const FoldCurveSpecialPoint& bt = c.special[0];
        CHECK(bt.kind == "bogdanov_takens");
        CHECK(bt.status == Status::Converged);
        CHECK(std::abs(bt.par2 + 1 / tau) < tol::special_point);
        CHECK(std::abs(bt.par - 1 / (4 * tau * tau)) < tol::special_point);
        CHECK(std::abs(bt.x[0] - 1 / (2 * tau)) < tol::special_point);
        CHECK(std::abs(std::abs(bt.other) - 2.0) < 1e-8);  // a = w F'' v^2 = 2 (|v| = |w| = 1): not a cusp
        // the normal form at the located point against its closed form (test_normal_forms.cpp):
        // a = 2 / tau, b = 4 / 3
        CHECK(std::abs(bt.nf_a - 2.0 / tau) < tol::normal_form_located);
        CHECK(std::abs(bt.nf_b - 4.0 / 3.0) < tol::normal_form_located);
        CHECK(std::isnan(bt.nf_c));
    }
}

TEST_CASE("a fold curve with a Bogdanov-Takens and a zero-Hopf point: the root counts along it explained by both") {
    // x' = p1 - p2 x(t - 2) + x^2 with an oscillator y' = (x - 1/2) y + rotation: the fold curve
    // (p1, p2) = (p2^2 / 4, p2), x = p2 / 2; Delta'(0) e_x = (1 - 2 p2) e_x: BT at p2 = 1/2 (a real root
    // through 0: the count besides the fold's root goes 0 -> 1); the pair x - 1/2 +- i crosses the
    // axis at x = 1/2: zero-Hopf at (p1, p2) = (1/4, 1) with omega = 1 (1 -> 3)
    ExpressionSystem sys({"x", "y1", "y2"}, {"p1", "p2", "tau"}, {-0.5, -0.5, 2.0},
                         {"p1 - p2*x(t - tau) + x^2", "(x - 0.5)*y1 - y2", "y1 + (x - 0.5)*y2"});
    Eigen::VectorXd guess(3);
    guess << -1.0, 0.0, 0.0;
    const FoldCurves fc = fold_curves(sys, guess, fold_box("p1", -0.5, 2.0, "p2", -1.5, 1.5));
    const FoldCurve& c = only_curve(fc);
    CHECK(off_parabola(c) < tol::special_point);
    for (const FoldCurvePoint& p : c.points) {
        REQUIRE(p.unstable >= 0);
        // the closed-form count away from the two points (within 1e-6 of them a root is near the axis)
        if (std::abs(p.par2 - 0.5) > 1e-6 && std::abs(p.par2 - 1.0) > 1e-6) CHECK(p.unstable == (p.par2 < 0.5 ? 0 : p.par2 < 1.0 ? 1 : 3));
    }
    REQUIRE(c.special.size() == 2);
    const FoldCurveSpecialPoint* bt = nullptr;
    const FoldCurveSpecialPoint* zh = nullptr;
    for (const FoldCurveSpecialPoint& q : c.special) (q.kind == "bogdanov_takens" ? bt : zh) = &q;
    REQUIRE(bt != nullptr);
    REQUIRE(zh != nullptr);
    CHECK(zh->kind == "zero_hopf");
    CHECK(bt->status == Status::Converged);
    CHECK(zh->status == Status::Converged);
    CHECK(std::abs(bt->par2 - 0.5) < tol::special_point);
    CHECK(std::abs(bt->par - 0.0625) < tol::special_point);
    CHECK(std::abs(zh->par2 - 1.0) < tol::special_point);
    CHECK(std::abs(zh->par - 0.25) < tol::special_point);
    CHECK(std::abs(zh->x[0] - 0.5) < tol::special_point);
    CHECK(std::abs(zh->omega - 1.0) < 1e-8);
    // its normal form: with u = x - 1/2 the system is u' = u - u(t - 2) + u^2, y' = J y + u y
    // (test_normal_forms.cpp's reduction with a = 1, tau = 2, so k = 1/(1 - a tau) = -1, beta = 1,
    // c = 0, delta = 1, sigma = 0): g200 = -1, g110 = 1, g011 = 0 (degenerate: e undefined),
    // g300 = beta k H200 = 4 (H200 = -beta a tau^2 k^2 = -4), g111 = 0, g210 = H200 / 2 = -2,
    // g021 = 0, theta = -1, d = g110 - i g300 / g200 = 1 + 4i
    const ZeroHopfNormalForm& nf = zh->zero_hopf;
    REQUIRE(nf.status == Status::Converged);
    CHECK(std::abs(nf.g200 + 1.0) < tol::special_point);
    CHECK(std::abs(nf.g110 - cplx(1.0, 0.0)) < tol::special_point);
    CHECK(std::abs(nf.g011) < tol::special_point);
    CHECK(std::abs(nf.g300 - 4.0) < tol::special_point);
    CHECK(std::abs(nf.g111) < tol::special_point);
    CHECK(std::abs(nf.g210 - cplx(-2.0, 0.0)) < tol::special_point);
    CHECK(std::abs(nf.g021) < tol::special_point);
    CHECK(std::abs(nf.theta + 1.0) < tol::special_point);
    CHECK(std::abs(nf.d - cplx(1.0, 4.0)) < tol::special_point);
}

TEST_CASE("the Hopf curve of x' = p1 + x^2 + p2 x(t - 2) ends at the Bogdanov-Takens point of its fold curve (omega -> 0)") {
    // an independent check of the located point: the Hopf curve iw = 2 x + p2 e^{-2 i w} (p2 = -w / sin 2w)
    // leaves the domain omega > 0 at the BT point; its last point is within O(omega^2) of it
    ExpressionSystem sys({"x"}, {"p1", "p2", "tau"}, {-0.5, -0.8, 2.0}, {"p1 + x^2 + p2*x(t - tau)"});
    Eigen::VectorXd guess(1);
    guess << 0.5;
    FoldCurveOptions fo = fold_box("p1", -0.5, 1.0, "p2", -1.5, -0.3);
    const FoldCurves fc = fold_curves(sys, guess, fo);
    REQUIRE(fc.curves.size() == 1);
    REQUIRE(fc.curves[0].special.size() == 1);
    const FoldCurveSpecialPoint& bt = fc.curves[0].special[0];
    REQUIRE(bt.kind == "bogdanov_takens");
    HopfCurveOptions ho;
    ho.branch = fo.branch;
    ho.parameter2 = "p2";
    ho.from2 = -1.5;
    ho.to2 = -0.3;
    const HopfCurves hc = hopf_curves(sys, guess, ho);
    INFO(hc.message);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& c = hc.curves[0];
    CHECK((c.stop_forward == ContinuationStop::LeftDomain || c.stop_backward == ContinuationStop::LeftDomain));
    const auto last = std::min_element(c.points.begin(), c.points.end(), [](const HopfCurvePoint& a, const HopfCurvePoint& b) { return a.omega < b.omega; });
    CHECK(last->omega < 0.1);
    const double w2 = last->omega * last->omega;
    CHECK(std::abs(last->par - bt.par) < w2);
    CHECK(std::abs(last->par2 - bt.par2) < w2);
    CHECK(std::abs(last->x[0] - bt.x[0]) < w2);
    // the Hopf curve locates the point itself: the closed form p2 = -1/tau, x = -p2/2, p1 = -x^2 -
    // p2 x (the fold 2 x + p2 = 0 and Delta'(0) = 1 + tau p2 = 0), and its normal form a = 2/tau,
    // b = 4/3 (normal_forms' test), as the fold curve's
    REQUIRE(c.bogdanov_takens.size() == 1);
    const HopfCurveBogdanovTakens& hb = c.bogdanov_takens[0];
    INFO(hb.message);
    REQUIRE(hb.status == Status::Converged);
    CHECK(std::abs(hb.par2 + 0.5) < 1e-10);
    CHECK(std::abs(hb.x[0] - 0.25) < 1e-10);
    CHECK(std::abs(hb.par - 0.0625) < 1e-10);
    REQUIRE(hb.normal_form.status == Status::Converged);
    CHECK(std::abs(hb.normal_form.a - 1.0) < tol::normal_form_exact);
    CHECK(std::abs(hb.normal_form.b - 4.0 / 3.0) < tol::normal_form_exact);
    CHECK(std::abs(hb.normal_form.a - bt.nf_a) < tol::normal_form_exact);
}

TEST_CASE("fold curves: bad options are refused naming the field") {
    ExpressionSystem sys({"x"}, {"p1", "p2"}, {-1.0, 1.0}, {"p1 + p2*x - x^3"});
    Eigen::VectorXd guess(1);
    guess << -1.3;
    FoldCurveOptions o = fold_box("p1", -1.5, 1.5, "p1", -0.5, 2.0);
    CHECK_THROWS_WITH_AS(fold_curves(sys, guess, o), doctest::Contains("expected a parameter other than the first"), std::invalid_argument);
    o = fold_box("p1", -1.5, 1.5, "p2", 2.0, 3.0);
    CHECK_THROWS_WITH_AS(fold_curves(sys, guess, o), doctest::Contains("p2 = 1 (its value in the system): expected a value in [2, 3]"),
                         std::invalid_argument);
    o = fold_box("p1", -1.5, 1.5, "q", -0.5, 2.0);
    CHECK_THROWS_AS(fold_curves(sys, guess, o), std::invalid_argument);
}
