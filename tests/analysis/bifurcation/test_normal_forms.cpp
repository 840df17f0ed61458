// Normal-form coefficients of Bogdanov-Takens and cusp points against closed forms derived by
// hand from the normalisation stated in normal_forms.hpp (DDE-BIFTOOL's).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "ddemap/analysis/bifurcation/normal_forms.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

TEST_CASE("Bogdanov-Takens normal form of x' = p1 + x^2 + p2 x(t - tau) at p2 = -1/tau: a = 2/tau, b = 4/3") {
    // n = 1: q0 = 1, q1 = 0, p1 = 1, p0 = 0 before the normalisation; Delta'' = -tau^2 p2 = tau,
    // Delta''' = tau^3 p2 = -tau^2: beta = tau/3, alpha = tau/2, so p0 = 2/3, p1 = 2/tau;
    // phi0 = 1, phi1(theta) = theta, B[u, v] = 2 u(0) v(0): a = p1 = 2/tau, b = 2 p0 = 4/3.
    for (double tau : {2.0, 0.8}) {
        CAPTURE(tau);
        const double p2 = -1.0 / tau, x = -p2 / 2.0, p1 = -x * x - p2 * x;
        ExpressionSystem sys({"x"}, {"p1", "p2", "tau"}, {p1, p2, tau}, {"p1 + x^2 + p2*x(t - tau)"});
        Eigen::VectorXd xv(1);
        xv << x;
        const BogdanovTakensNormalForm nf = bogdanov_takens_normal_form(sys, xv, sys.parameter_values());
        INFO(nf.message);
        REQUIRE(nf.status == Status::Converged);
        CHECK(std::abs(nf.a - 2.0 / tau) < tol::normal_form_exact);
        CHECK(std::abs(nf.b - 4.0 / 3.0) < tol::normal_form_exact);
        CHECK(nf.kernel_residual < 1e-14);
        CHECK(nf.double_root_residual < 1e-14);
    }
}

TEST_CASE("Bogdanov-Takens normal form with the nonlinearity delayed: x1' = x2, x2' = A x1(t - tau)^2 + B x1 x2(t - sigma) has a = A, b = B - 2 A tau") {
    // J = [[0, 1], [0, 0]], Delta'(0) = I: q0 = e1, q1 = e2, p0 = e1, p1 = e2; phi1(theta) = e2 + theta e1
    // enters through x1(t - tau): B[phi0, phi1] = (0, 2 A (-tau) + B), B[phi0, phi0] = (0, 2 A).
    const double A = 0.7, B = -1.3, tau = 0.9, sigma = 0.4;
    ExpressionSystem sys({"x1", "x2"}, {"A", "B", "tau", "sigma"}, {A, B, tau, sigma}, {"x2", "A*x1(t - tau)^2 + B*x1*x2(t - sigma)"});
    const BogdanovTakensNormalForm nf = bogdanov_takens_normal_form(sys, Eigen::VectorXd::Zero(2), sys.parameter_values());
    INFO(nf.message);
    REQUIRE(nf.status == Status::Converged);
    CHECK(std::abs(nf.a - A) < tol::normal_form_exact);
    CHECK(std::abs(nf.b - (B - 2.0 * A * tau)) < tol::normal_form_exact);
    // the same system with the sign of the nonlinearity reversed: both coefficients change sign
    ExpressionSystem neg({"x1", "x2"}, {"A", "B", "tau", "sigma"}, {-A, -B, tau, sigma}, {"x2", "A*x1(t - tau)^2 + B*x1*x2(t - sigma)"});
    const BogdanovTakensNormalForm nn = bogdanov_takens_normal_form(neg, Eigen::VectorXd::Zero(2), neg.parameter_values());
    CHECK(std::abs(nn.a + A) < tol::normal_form_exact);
    CHECK(std::abs(nn.b + (B - 2.0 * A * tau)) < tol::normal_form_exact);
}

TEST_CASE("cusp normal form of x' = k (x(t - tau) - x) + C x(t - tau)^3 + E x^2 x(t - tau) at 0: b = 0, c = (C + E) / (1 + tau k)") {
    // Delta(0) = 0, Delta'(0) = 1 + tau k: q = 1, p = 1/(1 + tau k); B[phi, phi] = 0 (so h2 = 0) and
    // C[phi, phi, phi] = 6 C + 6 E.
    const double k = 0.6, tau = 1.5, C = -0.8, E = 0.3;
    ExpressionSystem sys({"x"}, {"k", "tau", "C", "E"}, {k, tau, C, E}, {"k*(x(t - tau) - x) + C*x(t - tau)^3 + E*x^2*x(t - tau)"});
    const CuspNormalForm nf = cusp_normal_form(sys, Eigen::VectorXd::Zero(1), sys.parameter_values());
    INFO(nf.message);
    REQUIRE(nf.status == Status::Converged);
    CHECK(std::abs(nf.b) < tol::normal_form_exact);
    CHECK(std::abs(nf.c - (C + E) / (1.0 + tau * k)) < tol::normal_form_exact);
}

TEST_CASE("cusp normal form where the centre manifold bends: x1' = -x1 + x2^2, x2' = x1 x2 + a x2^3 has c = 1 + a") {
    // Reduction by hand: x1 is slaved, x1 = x2^2 + O(x2^4) on the centre manifold, so
    // x2' = x2^3 + a x2^3: c = 1 + a (q = p = e2, p Delta'(0) q = 1). By the formula: Delta(0) =
    // diag(1, 0), B[phi, phi] = (2, 0), y = (2, 0), h2 = y = (2, 0), B[phi, h2] = (0, 2),
    // C[phi, phi, phi] = (0, 6 a): c = (3 * 2 + 6 a) / 6.
    for (double a : {0.45, -2.5}) {
        CAPTURE(a);
        ExpressionSystem sys({"x1", "x2"}, {"a"}, {a}, {"-x1 + x2^2", "x1*x2 + a*x2^3"});
        const CuspNormalForm nf = cusp_normal_form(sys, Eigen::VectorXd::Zero(2), sys.parameter_values());
        INFO(nf.message);
        REQUIRE(nf.status == Status::Converged);
        CHECK(std::abs(nf.b) < tol::normal_form_exact);
        CHECK(std::abs(nf.c - (1.0 + a)) < tol::normal_form_exact);
    }
}

TEST_SUITE_END();

TEST_CASE("zero-Hopf normal form of a fold and a Hopf pair coupled through delays: every g against its reduction by hand") {
    // u' = a (u - u(t - tau)) + beta u^2 + c (y1^2 + y2^2) + e3 u^3,
    // y' = omega J y + delta u(t - sigma) y + rho |y|^2 y   (J the rotation by pi/2),
    // at 0: the root 0 of u (Delta_u'(0) = 1 - a tau = 1/k) and +-i omega of y. q0 = e_u, p0 = k e_u,
    // q1 = (0, 1, -i)/sqrt2, p1 = (0, 1, i)/sqrt2; the centre manifold's u-parts
    // h200(theta) = H200 + 2 beta k theta, h011(theta) = H011 + 2 c k theta with H = -(coefficient) a tau^2 k^2
    // (the bordered inverse's gamma term: Delta_u''(0) = a tau^2), h110 = delta theta e^{i omega theta} q1,
    // h020 = 0, so that
    //   g200 = beta k, g011 = 2 c k, g110 = delta, g300 = beta k H200 + e3 k, g111 = 2 beta k H011,
    //   g210 = delta (H200 - 2 beta k sigma) / 2, g021 = delta (H011 - 2 c k sigma) + 2 rho
    // (rho: y = w1 q1 + conj, |y|^2 = 2 |w1|^2, projected by p1: 2 rho w1 |w1|^2).
    const double a = 0.5, tau = 0.8, beta = 0.7, c = -0.3, delta = 1.3, omega = 1.1, sigma = 0.6, e3 = 0.4, rho = -0.25;
    // sign -1: the system mirrored in u (u -> -u flips the terms even in u)
    auto system = [&](const std::string& sign) {
        return ExpressionSystem({"u", "y1", "y2"}, {"a", "tau", "beta", "c", "delta", "omega", "sigma", "e3", "rho"},
                                {a, tau, beta, c, delta, omega, sigma, e3, rho},
                                {"a*(u - u(t - tau)) " + sign + " beta*u^2 " + sign + " c*(y1^2 + y2^2) + e3*u^3",
                                 "-omega*y2 " + sign + " delta*u(t - sigma)*y1 + rho*(y1^2 + y2^2)*y1",
                                 "omega*y1 " + sign + " delta*u(t - sigma)*y2 + rho*(y1^2 + y2^2)*y2"});
    };
    const ExpressionSystem sys = system("+");
    const ZeroHopfNormalForm nf = zero_hopf_normal_form(sys, Eigen::VectorXd::Zero(3), sys.parameter_values(), omega);
    REQUIRE(nf.status == Status::Converged);
    CHECK(nf.kernel_residual < 1e-14);
    CHECK(nf.hopf_residual < 1e-14);
    const double k = 1.0 / (1.0 - a * tau);
    const double H200 = -beta * a * tau * tau * k * k, H011 = -c * a * tau * tau * k * k;
    const double g200 = beta * k, g011 = 2.0 * c * k, g300 = beta * k * H200 + e3 * k, g111 = 2.0 * beta * k * H011;
    const cplx g110(delta, 0.0), g210(delta * (H200 - 2.0 * beta * k * sigma) / 2.0, 0.0), g021(delta * (H011 - 2.0 * c * k * sigma) + 2.0 * rho, 0.0);
    CHECK(std::abs(nf.g200 - g200) < tol::normal_form_exact);
    CHECK(std::abs(nf.g011 - g011) < tol::normal_form_exact);
    CHECK(std::abs(nf.g110 - g110) < tol::normal_form_exact);
    CHECK(std::abs(nf.g300 - g300) < tol::normal_form_exact);
    CHECK(std::abs(nf.g111 - g111) < tol::normal_form_exact);
    CHECK(std::abs(nf.g210 - g210) < tol::normal_form_exact);
    CHECK(std::abs(nf.g021 - g021) < tol::normal_form_exact);
    // Gavrilov's coefficients from these, as DDE-BIFTOOL forms them
    const cplx I(0.0, 1.0);
    CHECK(std::abs(nf.d - (g110 - I * omega * g300 / g200)) < tol::normal_form_exact);
    CHECK(std::abs(nf.e - (g210 + g110 * (g021.real() / g011 - 1.5 * g300 / g200 + g111 / (2.0 * g011)) - g021 * g200 / g011).real()) <
          tol::normal_form_exact);
    CHECK(std::abs(nf.s - g200 * g011) < tol::normal_form_exact);
    CHECK(std::abs(nf.theta - delta / g200) < tol::normal_form_exact);
    // s and theta do not depend on the sign of q0: the system mirrored in u (u -> -u) has
    // g200, g011, g110 of the other sign and the same s and theta
    const ExpressionSystem mirrored = system("-");
    const ZeroHopfNormalForm m = zero_hopf_normal_form(mirrored, Eigen::VectorXd::Zero(3), mirrored.parameter_values(), omega);
    REQUIRE(m.status == Status::Converged);
    CHECK(std::abs(m.s - nf.s) < tol::normal_form_exact);
    CHECK(std::abs(m.theta - nf.theta) < tol::normal_form_exact);
    CHECK(std::abs(std::abs(m.g200) - std::abs(nf.g200)) < tol::normal_form_exact);
    CHECK_THROWS_AS(zero_hopf_normal_form(sys, Eigen::VectorXd::Zero(3), sys.parameter_values(), 0.0), std::invalid_argument);
}
