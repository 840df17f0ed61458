#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "numeric_helpers.hpp"
#include "two_parameter_box.hpp"
#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/io/hopf_output.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/solve/integrate.hpp"
#include "ddemap/traffic/ov_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

using test::bisect;
using test::pi;

/// max - min of y' = -alpha y(t - 1) (1 + y) on its attracting orbit: RK4 with Hermite history
/// (solve/integrate.hpp, order 4) from y = a0 cos(pi t / 2) on [-1, 0], until t_end; the extrema
/// over the last 40 time units, each refined by a parabola through the step values around it.
double wright_range(double alpha, double a0, double t_end, double h) {
    DdeSolver solver(
        1, 0.0, [&](double t, double* y) { y[0] = a0 * std::cos(pi * t / 2.0); },
        [&](double t, const double* y, const DdeSolver& s, double* dy) { dy[0] = -alpha * s.value(0, t - 1.0) * (1.0 + y[0]); });
    std::vector<double> ys, ts;
    solver.integrate(t_end, h, {}, [&](const DdeSolver& s) {
        if (s.time() >= t_end - 40.0 - 2 * h) {
            ys.push_back(s.state()[0]);
            ts.push_back(s.time());
        }
        return true;
    });
    double hi = -1e300, lo = 1e300;
    for (std::size_t k = 1; k + 1 < ys.size(); ++k) {
        const double a = ys[k - 1], b = ys[k], c = ys[k + 1];
        const bool peak = b >= a && b >= c, trough = b <= a && b <= c;
        if (!peak && !trough) continue;
        const double den = a - 2 * b + c;
        const double ext = den != 0.0 ? b - (c - a) * (c - a) / (8.0 * den) : b;  // the parabola's extremum
        if (peak) hi = std::max(hi, ext);
        if (trough) lo = std::min(lo, ext);
    }
    return hi - lo;
}

/// Hopf-curve options for the box [from, to] x [from2, to2] in (p1, p2), the rest by default.
HopfCurveOptions curve_box(const std::string& p1, double from, double to, const std::string& p2, double from2, double to2) {
    return test::two_parameter_box<HopfCurveOptions>(p1, from, to, p2, from2, to2);
}

ExpressionSystem neuron_system() {
    return ExpressionSystem({"x1", "x2"}, {"kappa", "beta", "a12", "a21", "tau1", "tau2", "taus"}, {0.5, -1, 1, 0.5, 0.2, 0.2, 1.5},
                            {"-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                             "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"});
}

}  // namespace

TEST_CASE("Wright's equation: L1, the crossing speed and the amplitude law in closed form") {
    // y'(t) = -alpha y(t - 1) (1 + y(t)) at y = 0: Delta(lambda) = lambda + alpha e^{-lambda}, Hopf at
    // alpha = omega = pi/2. With q = 1, Phi = (1, -i), B(a, b) = -alpha (a_0 b_1 + a_1 b_0), C = 0:
    // B(Phi, Phi) = i pi, h20 = i pi / (i pi - pi/2), B(Phi, conj Phi) = 0 (h11 = 0),
    // p = 1 / Delta'(i pi/2) = 1 / (1 + i pi/2), and
    //     c1 = p B(conj Phi, H20) / 2,  Re c1 = -pi (3 pi - 2) / (5 (4 + pi^2)),
    //     lambda'(alpha) = -p e^{-i pi/2} = i / (1 + i pi/2),  Re lambda' = 2 pi / (4 + pi^2),
    // so r^2 = -mu Re lambda' / Re c1 = 10 mu / (3 pi - 2) and y ~ 2 r cos(pi t/2): the range
    // max - min = 4 r, i.e. half-amplitude^2 = 40 mu / (3 pi - 2), the classical law of Chow and
    // Mallet-Paret (1977; also Hassard, Kazarinoff and Wan, 1981): alpha = pi/2 + (3 pi - 2) eps^2 / 40.
    ExpressionSystem wright({"y"}, {"alpha"}, {1.5}, {"-alpha*y(t - 1)*(1 + y)"});
    const HopfPoint h = correct_hopf(wright, 0, Eigen::VectorXd::Zero(1), 1.5, 1.5);
    REQUIRE(h.status == Status::Converged);
    CHECK(std::abs(h.par - pi / 2) < tol::special_point);
    CHECK(std::abs(h.omega - pi / 2) < tol::special_point);
    const HopfCoefficients c = hopf_coefficients(wright, 0, h);
    REQUIRE(c.status == Status::Converged);
    const double re_c1 = -pi * (3 * pi - 2) / (5 * (4 + pi * pi));
    CHECK(std::abs(c.c1.real() - re_c1) < tol::normal_form);
    CHECK(std::abs(c.l1 - re_c1 / (pi / 2)) < tol::normal_form);
    CHECK(c.criticality == Criticality::Supercritical);
    CHECK(std::abs(c.dre_dpar - 2 * pi / (4 + pi * pi)) < tol::normal_form);
    CHECK(std::abs(c.dlambda - cplx(0, 1) / cplx(1, pi / 2)) < tol::normal_form);
    CHECK(c.side == 1);
    REQUIRE(c.amplitude_coefficient.size() == 1);
    CHECK(std::abs(c.amplitude_coefficient[0] - 4 * std::sqrt(10 / (3 * pi - 2))) < tol::normal_form);
    CHECK(std::abs(c.q.norm() - 1) < 1e-14);
    CHECK(c.null_residual < tol::normal_form);
}

TEST_CASE("the crossing speed through a moving equilibrium and through a delay, in closed form") {
    // x' = p - x(t - 1)^2: x* = sqrt(p), Delta = lambda + 2 sqrt(p) e^{-lambda}, Hopf at p = pi^2/16,
    // omega = pi/2; the total dDelta/dp = e^{-lambda} / sqrt(p) (through x*(p)) gives
    // lambda' = (4 i / pi) / (1 + i pi/2), Re lambda' = 8 / (4 + pi^2).
    ExpressionSystem fold({"x"}, {"p"}, {0.6}, {"p - x(t - 1)^2"});
    const HopfPoint h1 = correct_hopf(fold, 0, Eigen::VectorXd::Constant(1, 0.78), 0.6, 1.5);
    REQUIRE(h1.status == Status::Converged);
    CHECK(std::abs(h1.par - pi * pi / 16) < tol::special_point);
    const HopfCoefficients c1 = hopf_coefficients(fold, 0, h1);
    REQUIRE(c1.status == Status::Converged);
    CHECK(std::abs(c1.dlambda - cplx(0, 4 / pi) / cplx(1, pi / 2)) < tol::normal_form);
    CHECK(std::abs(c1.dre_dpar - 8 / (4 + pi * pi)) < tol::normal_form);
    // x' = -x(t - tau) + x x(t - tau) in tau: Hopf at tau = pi/2, omega = 1; dDelta/dtau = -lambda e^{-lambda tau}
    // = -1, Delta' = 1 + i pi/2, so lambda' = 1 / (1 + i pi/2), Re lambda' = 4 / (4 + pi^2)
    ExpressionSystem delay({"x"}, {"tau"}, {1.5}, {"-x(t - tau) + x*x(t - tau)"});
    const HopfPoint h2 = correct_hopf(delay, 0, Eigen::VectorXd::Zero(1), 1.5, 1.0);
    REQUIRE(h2.status == Status::Converged);
    CHECK(std::abs(h2.par - pi / 2) < tol::special_point);
    const HopfCoefficients c2 = hopf_coefficients(delay, 0, h2);
    REQUIRE(c2.status == Status::Converged);
    CHECK(std::abs(c2.dlambda - 1.0 / cplx(1, pi / 2)) < tol::normal_form);
    CHECK(std::abs(c2.dre_dpar - 4 / (4 + pi * pi)) < tol::normal_form);
}

TEST_CASE("hopf output: a Hopf point that was not located is undecided, with null coefficients") {
    ExpressionSystem wright({"y"}, {"alpha"}, {1.5}, {"-alpha*y(t - 1)*(1 + y)"});
    HopfAnalysis a;
    a.branch.parameter = "alpha";
    HopfPoint bad;
    bad.x = Eigen::VectorXd::Zero(1);
    bad.par = 1.5;
    bad.omega = 1.5;
    a.points.push_back(hopf_coefficients(wright, 0, bad));
    a.points.push_back(hopf_coefficients(wright, 0, correct_hopf(wright, 0, Eigen::VectorXd::Zero(1), 1.5, 1.5)));
    const std::string j = hopf_points_json(a, {"y"});
    CHECK(j.find("\"criticality\":\"undecided\"") != std::string::npos);
    CHECK(j.find("\"l1\":null") != std::string::npos);
    CHECK(j.find("\"criticality\":\"supercritical\"") != std::string::npos);
    const std::string csv = hopf_points_csv(a, {"y"});
    CHECK(csv.find(",undecided,") != std::string::npos);
    CHECK(csv.find("nan") == std::string::npos);
    CHECK(csv.find("inf") == std::string::npos);
}

TEST_CASE("Wright's equation: the predicted amplitude against a long simulation, error O(mu)") {
    ExpressionSystem wright({"y"}, {"alpha"}, {1.5}, {"-alpha*y(t - 1)*(1 + y)"});
    const HopfPoint h = correct_hopf(wright, 0, Eigen::VectorXd::Zero(1), 1.5, 1.5);
    const HopfCoefficients c = hopf_coefficients(wright, 0, h);
    REQUIRE(c.status == Status::Converged);
    REQUIRE(c.side == 1);
    double err[2];
    const double mus[2] = {0.02, 0.01};
    for (int i = 0; i < 2; ++i) {
        const double mu = mus[i];
        const double predicted = c.amplitude_coefficient[0] * std::sqrt(mu);
        // from the predicted orbit: the distance to the attracting orbit decays like
        // exp(-2 mu Re lambda' t) (the orbit's nontrivial exponent), e^-10 by t = 5 / (mu Re lambda')
        const double t_end = 5.0 / (mu * c.dre_dpar) + 100.0;
        const double simulated = wright_range(h.par + mu, predicted / 2, t_end, 1.0 / 64);
        err[i] = std::abs(simulated / predicted - 1);
        MESSAGE("mu = " << mu << ": simulated range " << simulated << ", predicted " << predicted << ", relative error " << err[i]);
        CHECK(err[i] < tol::amplitude_law_per_mu * mu);
    }
    // the error is O(mu): it halves with mu (ratio 2 up to the O(mu^2) terms)
    CHECK(err[1] < err[0]);
    CHECK(std::abs(err[0] / err[1] - 2.0) < tol::order_ratio_band);
}

TEST_CASE("neuron demo: the predicted range of each variable against a long simulation, error O(mu)") {
    // a vector system: the range of x_j is predicted as amplitude_coefficient_j sqrt(mu), through
    // |q_j| (the direction of the eigenvector matters, its normalisation does not)
    ExpressionSystem neuron = neuron_system();
    const int j = neuron.parameter_index("a21");
    const HopfPoint h = correct_hopf(neuron, j, Eigen::VectorXd::Zero(2), 0.8, 0.78);
    const HopfCoefficients c = hopf_coefficients(neuron, j, h);
    REQUIRE(c.status == Status::Converged);
    REQUIRE(c.criticality == Criticality::Supercritical);
    REQUIRE(c.side == 1);
    double err[2][2];
    const double mus[2] = {0.02, 0.01};
    for (int i = 0; i < 2; ++i) {
        const double mu = mus[i];
        neuron.set_parameter("a21", h.par + mu);
        const std::vector<double> tau = neuron.delays();
        const double r = std::sqrt(-mu * c.dre_dpar / c.c1.real());
        // from the predicted orbit x ~ 2 r Re(q e^{i omega t})
        DdeSolver solver(
            2, 0.0,
            [&](double t, double* y) {
                for (int k = 0; k < 2; ++k) y[k] = 2 * r * std::real(c.q[k] * std::exp(cplx(0, c.omega * t)));
            },
            [&](double t, const double* y, const DdeSolver& s, double* dy) {
                Eigen::VectorXd u(2 * (tau.size() + 1));
                u << y[0], y[1], Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(tau.size()));
                for (std::size_t k = 0; k < tau.size(); ++k)
                    for (int m = 0; m < 2; ++m) u[2 * static_cast<Eigen::Index>(k + 1) + m] = s.value(m, t - tau[k]);
                const Eigen::VectorXd f = neuron.f(u);
                dy[0] = f[0];
                dy[1] = f[1];
            });
        const double t_end = 5.0 / (mu * c.dre_dpar) + 100.0;
        double hi[2] = {-1e300, -1e300}, lo[2] = {1e300, 1e300};
        std::vector<double> prev[2];
        solver.integrate(t_end, 1.0 / 32, {}, [&](const DdeSolver& s) {
            if (s.time() < t_end - 60.0) return true;
            for (int m = 0; m < 2; ++m) {
                prev[m].push_back(s.state()[m]);
                const std::size_t n = prev[m].size();
                if (n < 3) continue;
                const double a = prev[m][n - 3], b = prev[m][n - 2], cc = prev[m][n - 1], den = a - 2 * b + cc;
                if ((b >= a && b >= cc) || (b <= a && b <= cc)) {
                    const double ext = den != 0.0 ? b - (cc - a) * (cc - a) / (8.0 * den) : b;
                    hi[m] = std::max(hi[m], ext);
                    lo[m] = std::min(lo[m], ext);
                }
            }
            return true;
        });
        for (int m = 0; m < 2; ++m) {
            const double predicted = c.amplitude_coefficient[m] * std::sqrt(mu);
            err[i][m] = std::abs((hi[m] - lo[m]) / predicted - 1);
            MESSAGE("neuron, mu = " << mu << ", x" << m + 1 << ": simulated range " << hi[m] - lo[m] << ", predicted " << predicted
                                    << ", relative error " << err[i][m]);
            CHECK(err[i][m] < tol::amplitude_law_per_mu * mu);
        }
    }
    for (int m = 0; m < 2; ++m) CHECK(std::abs(err[0][m] / err[1][m] - 2.0) < tol::order_ratio_band);
}

TEST_CASE("a cubic term flips the criticality: x' = -a x(t - 1) + b x x(t - 1) + c x^3") {
    // At x = 0 the linearisation is Wright's (alpha = a): Hopf at a = omega = pi/2 for every b, c.
    // The quadratic term contributes b^2 times Wright's Re c1 / alpha^2 (Wright: b = -alpha), the
    // cubic one C(Phi, Phi, conj Phi) = 6 c |q|^2 q, so c1 = 3 c p, Re p = 4 / (4 + pi^2):
    //     Re c1 = -4 b^2 (3 pi - 2) / (5 pi (4 + pi^2)) + 12 c / (4 + pi^2),
    // zero at c* = b^2 (3 pi - 2) / (15 pi) (a generalised Hopf point).
    const double b = 1.0;
    const double cstar = b * b * (3 * pi - 2) / (15 * pi);
    for (const double cc : {0.0, 0.1, 0.2, 0.5}) {
        ExpressionSystem sys({"x"}, {"a", "b", "c"}, {1.5, b, cc}, {"-a*x(t - 1) + b*x*x(t - 1) + c*x^3"});
        const HopfPoint h = correct_hopf(sys, 0, Eigen::VectorXd::Zero(1), 1.5, 1.5);
        const HopfCoefficients k = hopf_coefficients(sys, 0, h);
        REQUIRE(k.status == Status::Converged);
        const double re_c1 = -4 * b * b * (3 * pi - 2) / (5 * pi * (4 + pi * pi)) + 12 * cc / (4 + pi * pi);
        CHECK(std::abs(k.c1.real() - re_c1) < tol::normal_form);
        CHECK(k.criticality == (cc < cstar ? Criticality::Supercritical : Criticality::Subcritical));
        CHECK(k.side == (cc < cstar ? 1 : -1));  // Re lambda' > 0: supercritical orbits for a > pi/2
    }
    // the Hopf curve in (a, c): the line a = pi/2, with the generalised Hopf point at c*
    ExpressionSystem sys({"x"}, {"a", "b", "c"}, {1.2, b, 0.0}, {"-a*x(t - 1) + b*x*x(t - 1) + c*x^3"});
    HopfCurveOptions o = curve_box("a", 1.2, 2.0, "c", -0.5, 0.5);
    const HopfCurves hc = hopf_curves(sys, Eigen::VectorXd::Zero(1), o);
    CHECK(hc.status == Status::Converged);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& curve = hc.curves[0];
    CHECK(curve.stop_forward == ContinuationStop::Bound);
    CHECK(curve.stop_backward == ContinuationStop::Bound);
    double c_lo = 1e300, c_hi = -1e300;
    for (const HopfCurvePoint& p : curve.points) {
        CHECK(std::abs(p.par - pi / 2) < tol::special_point);
        CHECK(std::abs(p.omega - pi / 2) < tol::special_point);
        c_lo = std::min(c_lo, p.par2);
        c_hi = std::max(c_hi, p.par2);
    }
    CHECK(c_lo == doctest::Approx(-0.5).epsilon(1e-12));
    CHECK(c_hi == doctest::Approx(0.5).epsilon(1e-12));
    REQUIRE(curve.generalised.size() == 1);
    CHECK(curve.generalised[0].status == Status::Converged);
    CHECK(std::abs(curve.generalised[0].par2 - cstar) < tol::special_point);
    CHECK(std::abs(curve.generalised[0].par - pi / 2) < tol::special_point);
}

TEST_CASE("the Hopf curve of x' = -a x(t - tau) + x x(t - tau) - x^3 in (a, tau) is a tau = pi/2, omega = a") {
    ExpressionSystem sys({"x"}, {"a", "tau"}, {1.0, 1.0}, {"-a*x(t - tau) + x*x(t - tau) - x^3"});
    HopfCurveOptions o = curve_box("a", 1.0, 2.5, "tau", 0.7, 2.0);
    const HopfCurves hc = hopf_curves(sys, Eigen::VectorXd::Zero(1), o);
    CHECK(hc.status == Status::Converged);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& c = hc.curves[0];
    CHECK(c.points.size() > 10);
    for (const HopfCurvePoint& p : c.points) {
        CHECK(std::abs(p.par * p.par2 - pi / 2) < tol::special_point);
        CHECK(std::abs(p.omega - p.par) < tol::special_point);
        CHECK(p.coefficients.status == Status::Converged);
        CHECK(p.coefficients.criticality == Criticality::Supercritical);
    }
    // it leaves the box through tau = 0.7 (a = pi / 1.4 < 2.5) and a = 1 (tau = pi/2 < 2)
    const HopfCurvePoint& first = c.points.front();
    const HopfCurvePoint& last = c.points.back();
    const double lo_tau = std::min(first.par2, last.par2), hi_tau = std::max(first.par2, last.par2);
    CHECK(lo_tau == doctest::Approx(0.7).epsilon(1e-12));
    CHECK(hi_tau == doctest::Approx(pi / 2).epsilon(tol::special_point));
    CHECK(c.generalised.empty());
}

TEST_CASE("normalisation independence: rescaled variables keep the criticality, the crossing speed and the amplitudes") {
    // the neuron system in x and in (x1, z2) with x2 = s z2: ||q|| = 1 is another normalisation in
    // the new coordinates, so L1 changes, but not its sign, lambda', omega, nor the amplitudes
    // (of z2 = x2 / s)
    ExpressionSystem a = neuron_system();
    const double s = 7.0;
    ExpressionSystem b({"x1", "z2"}, {"kappa", "beta", "a12", "a21", "tau1", "tau2", "taus"}, {0.5, -1, 1, 0.5, 0.2, 0.2, 1.5},
                       {"-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(7*z2(t - tau2))",
                        "(-kappa*7*z2 + beta*tanh(7*z2(t - taus)) + a21*tanh(x1(t - tau1)))/7"});
    const int j = a.parameter_index("a21");
    const HopfPoint ha = correct_hopf(a, j, Eigen::VectorXd::Zero(2), 0.8, 0.78);
    const HopfPoint hb = correct_hopf(b, j, Eigen::VectorXd::Zero(2), 0.8, 0.78);
    REQUIRE(ha.status == Status::Converged);
    REQUIRE(hb.status == Status::Converged);
    const HopfCoefficients ca = hopf_coefficients(a, j, ha), cb = hopf_coefficients(b, j, hb);
    REQUIRE(ca.status == Status::Converged);
    REQUIRE(cb.status == Status::Converged);
    CHECK(std::abs(ca.l1 - cb.l1) > 1e-3 * std::abs(ca.l1));  // the normalisation does change L1
    CHECK(ca.criticality == cb.criticality);
    CHECK(ca.side == cb.side);
    CHECK(std::abs(ca.dlambda - cb.dlambda) < tol::normal_form);
    CHECK(std::abs(ca.omega - cb.omega) < tol::special_point);
    REQUIRE(ca.amplitude_coefficient.size() == 2);
    REQUIRE(cb.amplitude_coefficient.size() == 2);
    CHECK(std::abs(ca.amplitude_coefficient[0] / cb.amplitude_coefficient[0] - 1) < tol::normal_form);
    CHECK(std::abs(ca.amplitude_coefficient[1] / (s * cb.amplitude_coefficient[1]) - 1) < tol::normal_form);
}

TEST_CASE("ov ring: Hopf points at the ring modes' closed form, L1 the same from the expression form of the ring" * doctest::test_suite("slow")) {
    // the closed form (Orosz, Wilson, Stepan, Phys. Rev. E 70, 026207 (2004)): a Fourier mode
    // z = exp(i theta_k) of the linearisation at the uniform flow has
    //     lambda^2 + alpha lambda + alpha f (1 - z) e^{-lambda tau} = 0,   f = V'(h*),
    // so at lambda = i omega: omega sqrt(omega^2 + alpha^2) = 2 alpha f sin(theta_k / 2) and
    // omega tau = theta_k / 2 - pi/2 + arctan(alpha / omega).
    const int N = 3;
    const double alpha = 1.0, tau = 1.0;
    OvRing ring(N, alpha, tau, 1.0, 1.0, 1.2);
    EquilibriumBranchOptions o;
    o.parameter = "headway";
    o.from = 1.2;
    o.to = 3.0;
    const HopfAnalysis ha = hopf_points(ring, ring.uniform_flow(), o);
    CHECK(ha.status == Status::Converged);
    REQUIRE(ha.points.size() == 2);
    // the same ring written as expressions (a second implementation of f and its derivatives)
    const std::string V = "(H - 1)^3/(1 + (H - 1)^3)";
    auto v_of = [&](const std::string& h) {
        std::string s = V;
        for (std::size_t at; (at = s.find('H')) != std::string::npos;) s.replace(at, 1, h);
        return s;
    };
    ExpressionSystem expr({"h0", "h1", "v0", "v1", "v2"}, {"alpha", "tau", "hm"}, {alpha, tau, 1.2},
                          {"v1 - v0", "v2 - v1", "alpha*(" + v_of("h0(t - tau)") + " - v0)", "alpha*(" + v_of("h1(t - tau)") + " - v1)",
                           "alpha*(" + v_of("(3*hm - h0(t - tau) - h1(t - tau))") + " - v2)"});
    for (const HopfCoefficients& c : ha.points) {
        REQUIRE(c.status == Status::Converged);
        const double f = ring.optimal_velocity_slope(c.par);
        const double th = 2 * pi / N;  // modes 1 and 2 are conjugate: one family of crossings with omega > 0
        const double w = bisect([&](double ww) { return ww * tau - th / 2 + pi / 2 - std::atan(alpha / ww); }, 1e-9, 10.0);
        CHECK(std::abs(c.omega - w) < tol::special_point);
        CHECK(std::abs(f - w * std::sqrt(w * w + alpha * alpha) / (2 * alpha * std::sin(th / 2))) < tol::special_point);
        std::vector<double> pe{alpha, tau, c.par};
        const HopfCoefficients ce = hopf_coefficients(expr, 2, pe, c.x, c.omega);
        REQUIRE(ce.status == Status::Converged);
        CHECK(std::abs(ce.l1 - c.l1) < tol::normal_form * std::max(1.0, std::abs(c.l1)));
        CHECK(std::abs(ce.dre_dpar - c.dre_dpar) < tol::normal_form);
        CHECK(ce.criticality == c.criticality);
        // Orosz and Stepan, Proc. R. Soc. A 462, 2643 (2006), "Subcritical Hopf bifurcations in a
        // car-following model with reaction-time delay": where the uniform flow of this OV ring loses
        // stability (the first mode, the only one for N = 3) "the subcritical Hopf bifurcation occurs
        // robustly"
        CHECK(c.criticality == Criticality::Subcritical);
        MESSAGE("ov ring N = 3: Hopf at headway " << c.par << ", omega " << c.omega << ", L1 " << c.l1 << " (" << to_string(c.criticality)
                                                 << "), dRe/dpar " << c.dre_dpar);
    }
}

TEST_CASE("DDE-BIFTOOL demo 1 (neuron): the Hopf curve in (a21, taus) is supercritical" * doctest::test_suite("reference")) {
    // DDE-Biftool, demos/neuron/html/demo1_normalforms.html (published output of
    // demo1_normalforms.m): along the Hopf curves in (a21, taus) of demo1_hopf.m "the Lyapunov
    // coefficient is negative such that the Hopf bifurcation is supercritical" (except at a21 = 0,
    // a non-semisimple eigenvalue, outside the box here). The curve starts at the published Hopf
    // point a21 = 0.80712 (taus = 1.5) and is followed in demo1_hopf.m's box taus <= 10, a21 <= 4.
    // (The printed "L1: -0.0127" at the double Hopf point comes from the 2014 double-Hopf normal
    // form, Re g2100 / omega1 in that version's scaling: not the Hopf normalisation used here.)
    ExpressionSystem neuron = neuron_system();
    HopfCurveOptions o = curve_box("a21", 0.3, 2.0, "taus", 0.0, 10.0);
    const HopfCurves hc = hopf_curves(neuron, Eigen::VectorXd::Zero(2), o);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& c = hc.curves[0];
    CHECK(c.status == Status::Converged);
    CHECK(c.points.size() > 20);
    for (const HopfCurvePoint& p : c.points) {
        REQUIRE(p.coefficients.status == Status::Converged);
        CHECK(p.coefficients.criticality == Criticality::Supercritical);
    }
    CHECK(c.generalised.empty());
    MESSAGE("neuron Hopf curve: " << c.message << "; L1 at the start " << hc.start.points[0].l1);
}

TEST_CASE("DDE-BIFTOOL minimal demo (delayed Duffing oscillator): published L1 values and the generalised Hopf point" *
          doctest::test_suite("reference")) {
    // DDE-Biftool, demos/minimal_demo/html/minimal_demo.html (published output of minimal_demo.m,
    // DDE-BIFTOOL's current normal form code): x'' + d x' + a x + x^3 + b (x - x(t - tau)) = 0 with
    // a = 0.5, b = 0.6, d = 0.05, continued in tau from 0: LocateSpecialPoints prints the Hopf points
    // with "L1: 0.12631", "L1: 0.13109", "L1: -0.48039"; along the Hopf curve in (b, tau) from the
    // second one (b <= 0.6, tau <= 20) BranchFromCodimension2 prints "from genh at par(3)=0.036906,
    // par(1)=14.8348" (par(3) = b, par(1) = tau).
    ExpressionSystem duffing({"x1", "x2"}, {"a", "b", "d", "tau"}, {0.5, 0.6, 0.05, 0.0},
                             {"x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"});
    EquilibriumBranchOptions o;
    o.parameter = "tau";
    o.from = 0.0;
    o.to = 10.0;
    const HopfAnalysis ha = hopf_points(duffing, Eigen::VectorXd::Zero(2), o);
    CHECK(ha.status == Status::Converged);
    REQUIRE(ha.points.size() == 3);
    const double published[3] = {0.12631, 0.13109, -0.48039};
    for (int i = 0; i < 3; ++i) {
        REQUIRE(ha.points[static_cast<std::size_t>(i)].status == Status::Converged);
        CHECK(std::abs(ha.points[static_cast<std::size_t>(i)].l1 / published[i] - 1) < tol::published_5_digits_rel);
    }
    HopfCurveOptions co;
    co.branch = o;
    co.branch.to = 20.0;
    co.parameter2 = "b";
    co.from2 = 0.0;
    co.to2 = 0.6;
    const HopfCurve c = hopf_curve(duffing, ha.branch.hopf[1], co);
    CHECK(c.status == Status::Converged);
    REQUIRE(c.generalised.size() == 1);
    const GeneralisedHopfPoint& g = c.generalised[0];
    CHECK(g.status == Status::Converged);
    CHECK(std::abs(g.par / 14.8348 - 1) < tol::published_5_digits_rel);
    CHECK(std::abs(g.par2 / 0.036906 - 1) < tol::published_5_digits_rel);
    MESSAGE("generalised Hopf point at tau = " << g.par << ", b = " << g.par2 << ", omega = " << g.omega << "; curve: " << c.message);
}

TEST_CASE("Hopf coefficients: inputs and failures") {
    ExpressionSystem wright({"y"}, {"alpha"}, {1.5}, {"-alpha*y(t - 1)*(1 + y)"});
    HopfPoint bad;  // not located
    const HopfCoefficients c = hopf_coefficients(wright, 0, bad);
    CHECK(c.status != Status::Converged);
    CHECK(!c.message.empty());
    CHECK_THROWS_AS(hopf_coefficients(wright, 3, bad), std::invalid_argument);
    CHECK_THROWS_AS(hopf_coefficients(wright, 0, {1.5}, Eigen::VectorXd::Zero(1), -1.0), std::invalid_argument);
    CHECK_THROWS_AS(hopf_coefficients(wright, 0, {1.5, 2.0}, Eigen::VectorXd::Zero(1), 1.0), std::invalid_argument);
    HopfCoefficientOptions o;
    o.degenerate_tolerance = -1;
    CHECK_THROWS_AS(hopf_coefficients(wright, 0, {1.5}, Eigen::VectorXd::Zero(1), 1.0, o), std::invalid_argument);
    // a linear system: L1 = 0 exactly, degenerate, no amplitude
    ExpressionSystem lin({"y"}, {"alpha"}, {1.5}, {"-alpha*y(t - 1)"});
    const HopfCoefficients cl = hopf_coefficients(lin, 0, correct_hopf(lin, 0, Eigen::VectorXd::Zero(1), 1.5, 1.5));
    CHECK(cl.status == Status::Converged);
    CHECK(cl.criticality == Criticality::Degenerate);
    CHECK(cl.side == 0);
    CHECK(cl.amplitude_coefficient.size() == 0);
    // curve options
    HopfCurveOptions ho;
    ho.branch.parameter = "alpha";
    ho.branch.from = 1.0;
    ho.branch.to = 2.0;
    ho.parameter2 = "alpha";
    CHECK_FALSE(ho.is_valid());
    ExpressionSystem two({"y"}, {"alpha", "beta"}, {1.5, 3.0}, {"-alpha*y(t - 1)*(1 + beta*y)"});
    ho.parameter2 = "beta";
    ho.from2 = 0.0;
    ho.to2 = 1.0;  // the held beta = 3 is outside
    CHECK_THROWS_AS(hopf_curves(two, Eigen::VectorXd::Zero(1), ho), std::invalid_argument);
}

namespace {

/// The roots of the linearisation at (x, p) within `band` of the imaginary axis with Im > 0,
/// from the linear root solver (solve/roots.hpp), an algorithm independent of the defining systems.
std::vector<cplx> axis_roots(const NonlinearDDE& s, const Eigen::VectorXd& x, const std::vector<double>& p, double band) {
    RootOptions ro;
    ro.count = 12;
    const RootResult rr = rightmost_roots(linearise(s, x, p), ro);
    REQUIRE(rr.status == Status::Converged);
    std::vector<cplx> out;
    for (const Root& r : rr.roots)
        if (std::abs(r.value.real()) <= band && r.value.imag() > 0.0) out.push_back(r.value);
    return out;
}

}  // namespace

TEST_CASE("DDE-BIFTOOL neuron demo: the double Hopf point where its two Hopf curves cross, from either curve" *
          doctest::test_suite("reference")) {
    // DDE-Biftool, demos/neuron/html/demo1_normalforms.html (published output of br_bifdet along
    // the Hopf curves of demo1_hopf.m in (a21, taus)): "hoho point found at par(4) = 0.2072962661,
    // par(7) = 8.6340742204", "omega1 = 0.3287154066, omega2 = 0.9157115877" on branch2 (from the
    // Hopf point a21 = 0.80712 at taus = 1.5), and par(4) = 0.2072962626, par(7) = 8.6340742187 on
    // branch3, the second curve, which demo1_hopf.m starts from that double Hopf point.
    // At a21 = 0 the neurons decouple and the pair of -kappa + beta e^{-lambda taus} is double
    // (a 1:1 resonance, which the demo calls spurious): omega = sqrt(1 - kappa^2) = sqrt(3)/2 and
    // omega taus = 2 pi / 3 + 2 pi k, in closed form (the demo prints 2.4183994947 and 9.6735990351).
    ExpressionSystem neuron = neuron_system();
    // demo1_hopf.m's box
    HopfCurveOptions o = curve_box("a21", 0.0, 4.0, "taus", 0.0, 10.0);
    const HopfCurves hc = hopf_curves(neuron, Eigen::VectorXd::Zero(2), o);
    INFO(hc.message);
    CHECK(hc.status == Status::Converged);
    REQUIRE(hc.start.branch.hopf.size() == 1);  // a21 = 0.80712 at taus = 1.5
    REQUIRE(hc.curves.size() == 2);             // the second one started from the double Hopf point
    CHECK(hc.curves[1].start == -1);
    const double w0 = std::sqrt(3.0) / 2.0;
    std::vector<DoubleHopfPoint> genuine;
    for (std::size_t i = 0; i < 2; ++i) {
        int resonant = 0;
        for (const DoubleHopfPoint& d : hc.curves[i].double_hopf) {
            REQUIRE(d.status == Status::Converged);
            if (d.resonant) {
                ++resonant;
                CHECK(std::abs(d.par) < tol::special_point);
                CHECK(std::abs(d.omega1 - w0) < tol::special_point);
                CHECK(std::abs(d.par2 - (2 * pi / 3 + 2 * pi * static_cast<double>(i)) / w0) < tol::special_point);
            } else {
                genuine.push_back(d);
                CHECK(d.other_curve == static_cast<int>(1 - i));
            }
        }
        CHECK(resonant == 1);
    }
    REQUIRE(genuine.size() == 2);  // one crossing, seen from both curves
    CHECK(std::abs(genuine[0].par - genuine[1].par) < 1e-12);
    CHECK(std::abs(genuine[0].par2 - genuine[1].par2) < 1e-12);
    const DoubleHopfPoint& d = genuine[0];
    CHECK(std::abs(d.par - 0.2072962661) < tol::published_double_hopf);
    CHECK(std::abs(d.par2 - 8.6340742204) < tol::published_double_hopf);
    CHECK(std::abs(d.omega1 - 0.3287154066) < tol::published_double_hopf);
    CHECK(std::abs(d.omega2 - 0.9157115877) < tol::published_double_hopf);
    CHECK(d.residual < 1e-11);
    // the linear root solver finds both pairs on the axis there
    std::vector<double> p = neuron.parameter_values();
    p[3] = d.par, p[6] = d.par2;
    const std::vector<cplx> on_axis = axis_roots(neuron, d.x, p, 1e-9);
    REQUIRE(on_axis.size() == 2);
    const double lo = std::min(on_axis[0].imag(), on_axis[1].imag()), hi = std::max(on_axis[0].imag(), on_axis[1].imag());
    CHECK(std::abs(lo - std::min(d.omega1, d.omega2)) < 1e-9);
    CHECK(std::abs(hi - std::max(d.omega1, d.omega2)) < 1e-9);
    MESSAGE("neuron double Hopf: a21 " << d.par << ", taus " << d.par2 << ", omega " << d.omega1 << " and " << d.omega2 << ", residual " << d.residual);
}

TEST_CASE("double Hopf points: two delayed equations with crossing Hopf lines, the second curve started at the crossing") {
    // y1' = -c1 y1(t - 1) (1 + y1),  y2' = -c2 y2(t - 3/2) + y1 + y2^2 (triangular: det Delta =
    // (lambda + c1 e^-lambda)(lambda + c2 e^-3lambda/2)), c1 = a + b / 2, c2 = a / 2 + b. The Hopf
    // curves are the lines c1 = pi/2 (omega pi/2) and c2 = pi/3 (omega pi/3), crossing at
    // a = 4 pi / 9, b = pi / 9 (no resonance: 2 omega is neither frequency).
    ExpressionSystem sys({"y1", "y2"}, {"a", "b"}, {1.0, 0.0}, {"-(a + b/2)*y1(t - 1)*(1 + y1)", "-(a/2 + b)*y2(t - 1.5) + y1 + y2^2"});
    HopfCurveOptions o = curve_box("a", 1.2, 2.0, "b", -0.5, 0.6);
    const HopfCurves hc = hopf_curves(sys, Eigen::VectorXd::Zero(2), o);
    INFO(hc.message);
    CHECK(hc.status == Status::Converged);
    // at b = 0 the branch in a meets only c1 = pi/2 (a = 1.5708) in [1.2, 2] (c2 = pi/3 needs a = 2.09):
    // the second curve is traced only because it is started from the double Hopf point
    REQUIRE(hc.start.branch.hopf.size() == 1);
    CHECK(hc.curves.size() == 2);
    int located = 0, linked = 0;
    for (std::size_t i = 0; i < hc.curves.size(); ++i) {
        const HopfCurve& c = hc.curves[i];
        CHECK(c.status == Status::Converged);
        for (const DoubleHopfPoint& d : c.double_hopf) {
            REQUIRE(d.status == Status::Converged);
            ++located;
            CHECK(std::abs(d.par - 4 * pi / 9) < tol::special_point);
            CHECK(std::abs(d.par2 - pi / 9) < tol::special_point);
            const double w1 = std::min(d.omega1, d.omega2), w2 = std::max(d.omega1, d.omega2);
            CHECK(std::abs(w1 - pi / 3) < tol::special_point);
            CHECK(std::abs(w2 - pi / 2) < tol::special_point);
            if (d.other_curve >= 0 && d.other_curve != static_cast<int>(i)) ++linked;
        }
    }
    // found from both curves, each naming the other
    CHECK(located == 2);
    CHECK(linked == 2);
}

TEST_CASE("zero-Hopf point: the Hopf curve passes the fold of the equilibria, where a real root crosses 0") {
    // y1' = -(a + y2) y1(t - 1) (1 + y1),  y2' = b - y2^2: equilibria y1 = 0, y2 = +-sqrt(b) (a fold
    // at b = 0); the Hopf curve a + y2 = pi/2 (omega pi/2) is a = pi/2 -+ sqrt(b) in (a, b), and at
    // b = 0 it passes from y2 > 0 (the root -2 y2 < 0) to y2 < 0 (a real root > 0): a zero-Hopf point
    // at a = pi/2, b = 0, where det Delta(0) = 0.
    ExpressionSystem sys({"y1", "y2"}, {"a", "b"}, {1.0, 0.25}, {"-(a + y2)*y1(t - 1)*(1 + y1)", "b - y2^2"});
    Eigen::VectorXd guess(2);
    guess << 0.0, 0.5;
    HopfCurveOptions o = curve_box("a", 0.5, 2.5, "b", -0.1, 1.0);
    const HopfCurves hc = hopf_curves(sys, guess, o);
    INFO(hc.message);
    CHECK(hc.status == Status::Converged);
    REQUIRE(hc.curves.size() == 1);
    const HopfCurve& c = hc.curves[0];
    REQUIRE(c.zero_hopf.size() == 1);
    const ZeroHopfPoint& z = c.zero_hopf[0];
    CHECK(z.status == Status::Converged);
    CHECK(std::abs(z.par - pi / 2) < tol::special_point);
    CHECK(std::abs(z.par2) < tol::special_point);
    CHECK(std::abs(z.omega - pi / 2) < tol::special_point);
    CHECK(std::abs(z.x[1]) < 1e-6);  // y2 = sqrt(b): the square root of the parameter error
    CHECK(z.residual < 1e-9);
    CHECK(c.double_hopf.empty());
    // its normal form by hand: the fold variable y2 (q0 = e2, p0 = e2: Delta'(0) = 1 there),
    // g200 = p0 B[phi0, phi0] / 2 = -1 (from -y2^2); the pair of y1' = -(pi/2) y1(t - 1):
    // q1 = e1, p1 = e1 / Delta1'(i pi/2) = e1 / (1 + i pi/2); B[phi0, phi1] from -y2 y1(t - 1):
    // -(1 e^{-i pi/2}) = i, so g110 = i / (1 + i pi/2); g011 = 0 (y2 does not see y1 at second
    // order: a degenerate point, e undefined); theta = Re g110 / g200
    const ZeroHopfNormalForm& nf = z.normal_form;
    REQUIRE(nf.status == Status::Converged);
    const cplx g110 = cplx(0.0, 1.0) / cplx(1.0, pi / 2);
    CHECK(std::abs(nf.g200 + 1.0) < tol::special_point);
    CHECK(std::abs(nf.g110 - g110) < tol::special_point);
    CHECK(std::abs(nf.g011) < tol::special_point);
    CHECK(std::abs(nf.theta + g110.real()) < tol::special_point);
    CHECK(!std::isfinite(nf.e));
    // the count of roots right of the axis besides the pair: 0 on the y2 > 0 side, 1 on the other
    int zeros = 0, ones = 0;
    for (const HopfCurvePoint& p : c.points) {
        CHECK((p.unstable == 0 || p.unstable == 1));
        (p.unstable == 0 ? zeros : ones) += 1;
        if (p.unstable >= 0) CHECK((p.unstable == 1) == (p.x[1] < 0.0));
    }
    CHECK(zeros > 0);
    CHECK(ones > 0);
}

TEST_CASE("ov ring (N = 5) in (headway, tau): the root counts along every Hopf curve equal the ring modes' closed form, no double Hopf point" *
          doctest::test_suite("slow")) {
    // Mode k (theta_k = 2 pi k / N) is unstable where V'(h) > f_k(tau), f_k = omega sqrt(omega^2 + alpha^2) /
    // (2 alpha sin(theta_k / 2)) with omega tau = theta_k / 2 - pi / 2 + arctan(alpha / omega) (the closed form of
    // test_equilibrium_branch.cpp): mode k crosses at +i omega_k, and its root's conjugate (a root of mode N - k)
    // at -i omega_k, so every unstable mode brings a conjugate pair. On the curve of mode m the roots right of the
    // axis besides its pair are 2 per mode k != m with V'(h) > f_k(tau); the curves f_k(tau) never cross, so there
    // is no double Hopf point in this plane.
    const int N = 5;
    const double alpha = 1.0;
    OvRing ring(N, alpha, 1.0, 1.0, 1.0, 1.2);
    HopfCurveOptions o = curve_box("headway", 1.2, 3.0, "tau", 0.5, 1.5);
    const HopfCurves hc = hopf_curves(ring, ring.uniform_flow(), o);
    INFO(hc.message);
    CHECK(hc.status == Status::Converged);
    REQUIRE(hc.curves.size() >= 2);
    auto f = [&](int k, double tau) {
        const double th = 2 * pi * k / N;
        const double w = bisect([&](double ww) { return ww * tau - th / 2 + pi / 2 - std::atan(alpha / ww); }, 1e-9, 10.0);
        return w * std::sqrt(w * w + alpha * alpha) / (2 * alpha * std::sin(th / 2));
    };
    int compared = 0;
    for (const HopfCurve& c : hc.curves) {
        CHECK(c.double_hopf.empty());
        CHECK(c.zero_hopf.empty());
        for (const HopfCurvePoint& p : c.points) {
            REQUIRE(p.unstable >= 0);
            const double slope = ring.optimal_velocity_slope(p.par);
            // the curve's mode: the one whose f_k is V'(h) here
            int m = 1;
            for (int k = 1; k < N; ++k)
                if (std::abs(f(k, p.par2) - slope) < std::abs(f(m, p.par2) - slope)) m = k;
            REQUIRE(std::abs(f(m, p.par2) - slope) < 1e-6);
            int expected = 0;
            bool near = false;
            for (int k = 1; k < N; ++k) {
                if (k == m) continue;
                near = near || std::abs(slope - f(k, p.par2)) < 1e-6;
                if (slope > f(k, p.par2)) expected += 2;
            }
            if (near) continue;
            CHECK_MESSAGE(p.unstable == expected, "headway " << p.par << ", tau " << p.par2 << ": " << p.unstable << " roots right of the axis");
            ++compared;
        }
    }
    CHECK(compared > 50);
    MESSAGE("root counts compared with the closed form at " << compared << " Hopf-curve points");
}

namespace {

/// DDE-BIFTOOL's normal-form demo (nmfm_demo): two layers of neurons,
/// x1' = -x1 - a g(b x1(t - tau1)) + c g(d x2(t - tau2)) and symmetrically, g(z) = (tanh(z - 1) +
/// tanh 1) cosh(1)^2 (g(0) = 0, g'(0) = 1), b = 2, d = 1.2, tau1 = 12.7, tau2 = 20.2.
ExpressionSystem two_layers(double a, double c) {
    const double C2 = 2.3810978455418157, T1 = 0.7615941559557649;  // cosh(1)^2, tanh(1)
    char c2[64];
    std::snprintf(c2, sizeof c2, "%.17g", C2);
    char t1[64];
    std::snprintf(t1, sizeof t1, "%.17g", T1);
    auto g = [&](const std::string& var, const std::string& gain, const std::string& tau) {
        return std::string("(tanh(") + gain + "*" + var + "(t - " + tau + ") - 1) + " + t1 + ")*" + c2;
    };
    return ExpressionSystem({"x1", "x2"}, {"a", "b", "c", "d", "tau1", "tau2"}, {a, 2.0, c, 1.2, 12.7, 20.2},
                            {"-x1 - a*" + g("x1", "b", "tau1") + " + c*" + g("x2", "d", "tau2"),
                             "-x2 - a*" + g("x2", "b", "tau1") + " + c*" + g("x1", "d", "tau2")});
}

/// The root of the symmetric mode's Delta_s(lambda) = lambda + 1 + 2 a e^{-12.7 lambda} -
/// 1.2 c e^{-20.2 lambda} near `start` (complex Newton).
cplx two_layers_root(double a, double c, cplx start) {
    cplx l = start;
    for (int it = 0; it < 60; ++it) {
        const cplx e1 = std::exp(-12.7 * l), e2 = std::exp(-20.2 * l);
        l -= (l + 1.0 + 2.0 * a * e1 - 1.2 * c * e2) / (1.0 - 25.4 * a * e1 + 24.24 * c * e2);
    }
    return l;
}

}  // namespace

TEST_CASE("DDE-BIFTOOL's normal-form demo (two layers of neurons): the zero-Hopf point where the trivial equilibrium is a pitchfork, its normal form, no generalised Hopf point at L1's pole") {
    // (two_layers). At x = 0 the
    // symmetric mode has Delta_s(lambda) = lambda + 1 + 2 a e^{-12.7 lambda} - 1.2 c e^{-20.2 lambda}: a
    // real root crosses 0 where 1 + 2a - 1.2c = 0 (a pitchfork of the symmetric equilibrium, where
    // the curve system is singular). The demo (nmfm_demo, its published output) prints the
    // zero-Hopf point a = 0.0133327150, c = 0.8554382654 (where 1 + 2a - 1.2c = 1.4e-4: located to
    // its secant tolerance) with s = 0.0000803411 and theta = 2.0969328059, its generalised Hopf point
    // a = 0.2518504300, c = 0.5812203535.
    const ExpressionSystem sys = two_layers(0.25, 15.0 / 29.0);
    HopfCurveOptions o = curve_box("a", 0.0, 0.55, "c", 0.3, 1.0);
    const HopfCurves hc = hopf_curves(sys, Eigen::VectorXd::Zero(2), o);
    REQUIRE(!hc.curves.empty());
    const HopfCurve& c = hc.curves[0];
    INFO(c.message);
    CHECK(c.status == Status::Converged);
    REQUIRE(c.zero_hopf.size() == 1);
    const ZeroHopfPoint& z = c.zero_hopf[0];
    REQUIRE(z.status == Status::Converged);
    // the closed form: the fold condition of the symmetric mode and its pair +-i omega
    const double a = z.par, cc = z.par2, w = z.omega;
    CHECK(std::abs(1.0 + 2.0 * a - 1.2 * cc) < 1e-7);
    const cplx l(0.0, w);
    CHECK(std::abs(l + 1.0 + 2.0 * a * std::exp(-12.7 * l) - 1.2 * cc * std::exp(-20.2 * l)) < 1e-7);
    // the demo's point, located to its tolerance
    CHECK(std::abs(a - 0.0133327150) < 1e-4);
    CHECK(std::abs(cc - 0.8554382654) < 1e-4);
    CHECK(std::abs(w - 0.2958015628) < 1e-5);
    // its normal form: theta as printed; s in the demo's normalisation of that version (q1 scaled by
    // 1/sqrt(p1 Delta'(i omega) q1) from unit vectors, which divides s by |Delta_s'(i omega)|)
    const ZeroHopfNormalForm& nf = z.normal_form;
    REQUIRE(nf.status == Status::Converged);
    const cplx ds = 1.0 - 2.0 * a * 12.7 * std::exp(-12.7 * l) + 1.2 * cc * 20.2 * std::exp(-20.2 * l);
    CHECK(std::abs(nf.theta - 2.0969328059) < 5e-4 * 2.0969328059);
    CHECK(std::abs(nf.s / std::abs(ds) - 0.0000803411) < 5e-4 * 0.0000803411);
    // L1's pole at the zero-Hopf point is not a generalised Hopf point: the one there is the demo's
    REQUIRE(c.generalised.size() == 1);
    CHECK(c.generalised[0].status == Status::Converged);
    CHECK(std::abs(c.generalised[0].par - 0.2518504300) < 5e-5);
    CHECK(std::abs(c.generalised[0].par2 - 0.5812203535) < 5e-5);
    // its second Lyapunov coefficient: checked against the folds of orbits in the test below; the
    // demo prints L2 = 0.0011029849 in the normalisation of its s (which divides L2 by
    // |Delta_s'(i omega)|^2): 1.9 % below ddemap's (see the guide)
    const GeneralisedHopfNormalForm& gnf = c.generalised[0].normal_form;
    REQUIRE(gnf.status == Status::Converged);
    CHECK(std::abs(gnf.l1) < 1e-8);
    const cplx lg(0.0, c.generalised[0].omega);
    const cplx dsg = 1.0 - 2.0 * c.generalised[0].par * 12.7 * std::exp(-12.7 * lg) + 1.2 * c.generalised[0].par2 * 20.2 * std::exp(-20.2 * lg);
    CHECK(std::abs(gnf.l2 / std::norm(dsg) - 0.0011029849) < 0.03 * 0.0011029849);
    // the double Hopf point where the curve of the pair omega ~ 0.29 crosses that of omega ~ 0.156:
    // the demo prints theta(0) = 1.6984018466, delta(0) = 1.5254221873 at a = 0.0900149247,
    // c = 0.7736041399 (1.2e-4 off its second pair's equation); theta and delta are ratios, free of
    // the normalisation. At ddemap's point they agree to 6e-4, at the demo's point to 4.3e-4.
    const DoubleHopfPoint* dh = nullptr;
    for (const HopfCurve& cv : hc.curves)
        for (const DoubleHopfPoint& d : cv.double_hopf)
            if (std::abs(d.par - 0.09) < 1e-3 && d.omega1 > d.omega2) dh = &d;
    REQUIRE(dh != nullptr);
    REQUIRE(dh->normal_form.status == Status::Converged);
    CHECK(std::abs(dh->par - 0.0900149247) < 5e-4);
    CHECK(std::abs(dh->par2 - 0.7736041399) < 5e-4);
    CHECK(std::abs(dh->normal_form.theta - 1.6984018466) < 1e-3 * 1.6984018466);
    CHECK(std::abs(dh->normal_form.delta - 1.5254221873) < 1e-3 * 1.5254221873);
    std::vector<double> at_demo = sys.parameter_values();
    at_demo[0] = 0.0900149247, at_demo[2] = 0.7736041399;
    const DoubleHopfNormalForm demo = double_hopf_normal_form(sys, Eigen::VectorXd::Zero(2), at_demo, dh->omega1, dh->omega2);
    REQUIRE(demo.status == Status::Converged);
    CHECK(std::abs(demo.theta - 1.6984018466) < 5e-4 * 1.6984018466);
    CHECK(std::abs(demo.delta - 1.5254221873) < 5e-4 * 1.5254221873);
}

TEST_CASE("second Lyapunov coefficient of DDE-BIFTOOL's normal-form demo against the folds of periodic orbits near its generalised Hopf point" *
          doctest::test_suite("slow")) {
    // Near a generalised Hopf point the radial normal form rho' = rho (mu + omega L1 rho^2 +
    // omega L2 rho^4) has a fold of orbits where its discriminant vanishes: mu = omega L1^2 / (4 L2)
    // (mu the real part of the critical root at the fold's parameter), up to O(L1) relative. On
    // lines c = const at four distances, the Hopf point in a gives omega and L1, the orbit branch
    // from it (collocation, a different computation) its fold a_F, the characteristic equation mu at
    // a_F; the estimates omega L1^2 / (4 mu) extrapolated to L1 = 0 by a quadratic must give L2.
    const ExpressionSystem at_gh = two_layers(0.25, 15.0 / 29.0);
    HopfCurveOptions o = curve_box("a", 0.0, 0.55, "c", 0.3, 1.0);
    const HopfCurves hc = hopf_curves(at_gh, Eigen::VectorXd::Zero(2), o);
    REQUIRE(!hc.curves.empty());
    REQUIRE(hc.curves[0].generalised.size() == 1);
    const GeneralisedHopfPoint& gh = hc.curves[0].generalised[0];
    REQUIRE(gh.normal_form.status == Status::Converged);
    std::vector<double> l1s, estimates;
    for (const double c : {0.57, 0.5725, 0.575, 0.5775}) {
        const ExpressionSystem sys = two_layers(0.2, c);
        EquilibriumBranchOptions eo;
        eo.parameter = "a";
        eo.from = 0.2;
        eo.to = 0.28;
        const HopfAnalysis h = hopf_points(sys, Eigen::VectorXd::Zero(2), eo);
        REQUIRE(h.points.size() == 1);
        const HopfCoefficients& hp = h.points[0];
        REQUIRE(hp.status == Status::Converged);
        REQUIRE(hp.l1 < 0.0);  // the side of the generalised Hopf point where the fold exists (L2 > 0)
        PeriodicOrbitOptions po;
        po.parameter = "a";
        po.from = 0.2;
        po.to = 0.28;
        po.degree = 5;
        po.intervals = 60;
        const OrbitBranch b = orbit_branch_from_hopf(sys, h.branch.hopf[0], po);
        REQUIRE(!b.folds.empty());
        REQUIRE(b.folds[0].located);
        const double mu = two_layers_root(b.folds[0].par, c, cplx(0.0, hp.omega)).real();
        REQUIRE(mu > 0.0);
        l1s.push_back(hp.l1);
        estimates.push_back(hp.omega * hp.l1 * hp.l1 / (4.0 * mu));
    }
    // the quadratic through the last three estimates, at L1 = 0 (Lagrange)
    const double x0 = l1s[1], x1 = l1s[2], x2 = l1s[3];
    const double extrapolated = estimates[1] * x1 * x2 / ((x0 - x1) * (x0 - x2)) + estimates[2] * x0 * x2 / ((x1 - x0) * (x1 - x2)) +
                                estimates[3] * x0 * x1 / ((x2 - x0) * (x2 - x1));
    MESSAGE("L2 at the generalised Hopf point " << gh.normal_form.l2 << "; from the folds of orbits " << estimates[0] << ", " << estimates[1]
                                                << ", " << estimates[2] << ", " << estimates[3] << ", extrapolated " << extrapolated);
    // the estimates alone are 5 to 17 % off (first order in L1); the extrapolation removes that
    CHECK(std::abs(estimates[3] - gh.normal_form.l2) > 0.01 * gh.normal_form.l2);
    CHECK(std::abs(extrapolated - gh.normal_form.l2) < 1e-4 * gh.normal_form.l2);
}
