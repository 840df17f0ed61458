// Normal-form coefficients of Bogdanov-Takens, cusp and zero-Hopf points against closed forms
// derived by hand from the normalisation stated in normal_forms.hpp (DDE-BIFTOOL's); double Hopf
// and generalised Hopf (L2) coefficients against the exact tori and rotating waves of systems
// with a rotation symmetry.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

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

namespace {

/// z' = c z(t - tau) + a2 y(t - sigma) z + a3 z |z|^2 + a5 z |z|^4,  y' = -k y + b |z(t - sigma2)|^2
/// (z = x1 + i x2 complex, y real), written out in real arithmetic. It commutes with z -> e^{i s} z,
/// so its periodic orbits are rotating waves z = r e^{i Omega t}, y = b r^2 / k, exactly, with
///     i Omega - c e^{-i Omega tau} = A r^2 + a5 r^4,   A = a2 b / k + a3.
struct RotatingWaves {
    cplx c, a2, a3, a5;
    double k = 2.0, b = 1.5, tau = 0.5, sigma = 0.3, sigma2 = 0.7;
    ExpressionSystem system() const {
        return ExpressionSystem(
            {"x1", "x2", "y"}, {"cr", "ci", "a2r", "a2i", "a3r", "a3i", "a5r", "a5i", "k", "b", "tau", "sigma", "sigma2"},
            {c.real(), c.imag(), a2.real(), a2.imag(), a3.real(), a3.imag(), a5.real(), a5.imag(), k, b, tau, sigma, sigma2},
            {"cr*x1(t - tau) - ci*x2(t - tau) + y(t - sigma)*(a2r*x1 - a2i*x2) + (x1^2 + x2^2)*(a3r*x1 - a3i*x2) + (x1^2 + x2^2)^2*(a5r*x1 - a5i*x2)",
             "cr*x2(t - tau) + ci*x1(t - tau) + y(t - sigma)*(a2r*x2 + a2i*x1) + (x1^2 + x2^2)*(a3r*x2 + a3i*x1) + (x1^2 + x2^2)^2*(a5r*x2 + a5i*x1)",
             "-k*y + b*(x1(t - sigma2)^2 + x2(t - sigma2)^2)"});
    }
    /// The root of lambda = (1 + beta) c e^{-lambda tau} near `start` (complex Newton).
    cplx root(double beta, cplx start) const {
        cplx l = start;
        for (int it = 0; it < 50; ++it) {
            const cplx e = (1.0 + beta) * c * std::exp(-l * tau);
            l -= (l - e) / (1.0 + tau * e);
        }
        return l;
    }
    /// The parameter beta (c scaled by 1 + beta) at which the rotating wave of amplitude r exists:
    /// beta = (i Omega - E - A r^2 - a5 r^4) / E with E = c e^{-i Omega tau}, Omega such that it is real.
    double wave_beta(double r, double omega) const {
        const cplx A = a2 * b / k + a3;
        auto ratio = [&](double w) {
            const cplx e = c * std::exp(cplx(0.0, -w * tau));
            return (cplx(0.0, w) - e - A * r * r - a5 * std::pow(r, 4)) / e;
        };
        double w0 = omega, w1 = omega * (1.0 + 1e-3);
        double f0 = ratio(w0).imag(), f1 = ratio(w1).imag();
        for (int it = 0; it < 60 && f1 != f0 && std::abs(f1) > 0.0; ++it) {
            const double w2 = w1 - f1 * (w1 - w0) / (f1 - f0);
            w0 = w1, f0 = f1, w1 = w2, f1 = ratio(w1).imag();
        }
        return ratio(w1).real();
    }
};

}  // namespace

TEST_CASE("second Lyapunov coefficient against the exact rotating waves of a symmetric DDE") {
    // At the generalised Hopf point the orbits' amplitude obeys 0 = mu + Re c2 rho^4 + O(rho^6)
    // (mu the real part of the critical root, Re c1 = 0), and |z| = sqrt2 rho (1 + O(rho^2)) since
    // |z(q)| = sqrt2 for the unit eigenvector: L2 = Re c2 / omega = lim -4 mu(beta(r)) / (omega r^4).
    // The limit by Richardson extrapolation in r^2 from the exact waves is independent of the
    // normal-form formulas, and the quadratic coupling through y (with its delays) makes h11, h21,
    // h22 and h31 nonzero.
    RotatingWaves w;
    const double omega = 1.0;
    w.c = omega * std::exp(cplx(0.0, M_PI / 2.0 + omega * w.tau));  // i omega = c e^{-i omega tau}
    w.a2 = cplx(0.6, -0.3);
    w.a5 = cplx(-0.8, 0.3);
    // Re c1 = 0: c1 = 2 A / Delta_z'(i omega) with Delta_z'(i omega) = 1 + i omega tau, so A = i s (1 + i omega tau)
    const double s = 0.7;
    const cplx A = cplx(0.0, s) * cplx(1.0, omega * w.tau);
    w.a3 = A - w.a2 * w.b / w.k;
    const ExpressionSystem sys = w.system();
    const GeneralisedHopfNormalForm nf = generalised_hopf_normal_form(sys, Eigen::VectorXd::Zero(3), sys.parameter_values(), omega);
    REQUIRE(nf.status == Status::Converged);
    CHECK(nf.hopf_residual < 1e-14);
    CHECK(std::abs(nf.c1 - 2.0 * A / cplx(1.0, omega * w.tau)) < tol::normal_form_exact);
    CHECK(std::abs(nf.l1) < tol::normal_form_exact);
    auto estimate = [&](double r) {
        const double beta = w.wave_beta(r, omega);
        const double mu = w.root(beta, cplx(0.0, omega)).real();
        return -4.0 * mu / (omega * std::pow(r, 4));
    };
    const double e1 = estimate(0.04), e2 = estimate(0.02), e3 = estimate(0.01);
    const double r12 = (4.0 * e2 - e1) / 3.0, r23 = (4.0 * e3 - e2) / 3.0;
    MESSAGE("L2 = " << nf.l2 << ", waves " << e1 << " " << e2 << " " << e3 << ", extrapolated " << r12 << " " << r23);
    CHECK(std::abs(r23 - nf.l2) < 1e-6 * std::abs(nf.l2));
    CHECK(std::abs(r23 - r12) < 1e-5 * std::abs(nf.l2));  // the extrapolation has converged
    CHECK_THROWS_AS(generalised_hopf_normal_form(sys, Eigen::VectorXd::Zero(3), sys.parameter_values(), -1.0), std::invalid_argument);
}

TEST_CASE("double Hopf normal form of two oscillators coupled through delays against their exact invariant tori") {
    // z_j' = c_j z_j(t - tau_j) + e_j y(t - sigma) z_j + (a_j1 |z1|^2 + a_j2 |z2|^2) z_j,
    // y' = -k y + b1 |z1(t - sigma2)|^2 + b2 |z2|^2: it commutes with rotating z1 and z2 apart, so
    // z_j = r_j e^{i Omega_j t}, y = (b1 r1^2 + b2 r2^2) / k are exact solutions (tori) with
    //     i Omega_j - c_j e^{-i Omega_j tau_j} = A_j1 r1^2 + A_j2 r2^2,  A_ji = a_ji + e_j b_i / k.
    // Near i omega_j the left side is Delta_j'(i omega_j) i (Omega_j - omega_j), Delta_j'(i omega_j)
    // = 1 + i omega_j tau_j, and r_j^2 = 2 |w_j|^2 (|z(q_j)| = sqrt2), so the normal form's
    // coefficients are g2100 = 2 A11 / Delta_1', g1011 = 2 A12 / Delta_1', g1110 = 2 A21 / Delta_2',
    // g0021 = 2 A22 / Delta_2'.
    const double w1 = 1.0, w2 = 1.7, t1 = 0.5, t2 = 0.8, k = 2.0, b1 = 1.5, b2 = -0.6;
    const cplx c1 = w1 * std::exp(cplx(0.0, M_PI / 2.0 + w1 * t1)), c2 = w2 * std::exp(cplx(0.0, M_PI / 2.0 + w2 * t2));
    const cplx e1(0.6, -0.3), e2(-0.4, 0.9), a11(-0.5, 0.2), a12(0.3, -0.7), a21(-1.1, 0.4), a22(-0.2, -0.5);
    // every complex coefficient a as two parameters a_r, a_i; a * (x + i y) in real arithmetic
    std::vector<std::string> names{"t1", "t2", "k", "b1", "b2", "sigma", "sigma2"};
    std::vector<double> values{t1, t2, k, b1, b2, 0.3, 0.7};
    auto coefficient = [&](const std::string& name, cplx a) {
        names.push_back(name + "_r"), values.push_back(a.real());
        names.push_back(name + "_i"), values.push_back(a.imag());
    };
    coefficient("c1", c1), coefficient("c2", c2), coefficient("e1", e1), coefficient("e2", e2);
    coefficient("a11", a11), coefficient("a12", a12), coefficient("a21", a21), coefficient("a22", a22);
    auto cmul = [](const std::string& a, const std::string& x, const std::string& y, bool imaginary_part) {
        return imaginary_part ? a + "_r*" + y + " + " + a + "_i*" + x : a + "_r*" + x + " - " + a + "_i*" + y;
    };
    const std::string m1 = "(x1^2 + x2^2)", m2 = "(x3^2 + x4^2)";
    std::vector<std::string> eq;
    for (int j = 0; j < 4; ++j) {
        const bool im = j % 2 == 1;
        const std::string J = j < 2 ? "1" : "2", x = j < 2 ? "x1" : "x3", y = j < 2 ? "x2" : "x4";
        eq.push_back(cmul("c" + J, x + "(t - t" + J + ")", y + "(t - t" + J + ")", im) + " + y(t - sigma)*(" + cmul("e" + J, x, y, im) + ") + " + m1 +
                     "*(" + cmul("a" + J + "1", x, y, im) + ") + " + m2 + "*(" + cmul("a" + J + "2", x, y, im) + ")");
    }
    eq.push_back("-k*y + b1*(x1(t - sigma2)^2 + x2(t - sigma2)^2) + b2*" + m2);
    const ExpressionSystem sys({"x1", "x2", "x3", "x4", "y"}, names, values, eq);
    const DoubleHopfNormalForm nf = double_hopf_normal_form(sys, Eigen::VectorXd::Zero(5), sys.parameter_values(), w1, w2);
    REQUIRE(nf.status == Status::Converged);
    CHECK(nf.hopf1_residual < 1e-14);
    CHECK(nf.hopf2_residual < 1e-14);
    const cplx d1(1.0, w1 * t1), d2(1.0, w2 * t2);
    const cplx A11 = a11 + e1 * b1 / k, A12 = a12 + e1 * b2 / k, A21 = a21 + e2 * b1 / k, A22 = a22 + e2 * b2 / k;
    CHECK(std::abs(nf.g2100 - 2.0 * A11 / d1) < tol::normal_form_exact);
    CHECK(std::abs(nf.g1011 - 2.0 * A12 / d1) < tol::normal_form_exact);
    CHECK(std::abs(nf.g1110 - 2.0 * A21 / d2) < tol::normal_form_exact);
    CHECK(std::abs(nf.g0021 - 2.0 * A22 / d2) < tol::normal_form_exact);
    CHECK(std::abs(nf.theta - (2.0 * A12 / d1).real() / (2.0 * A22 / d2).real()) < tol::normal_form_exact);
    CHECK(std::abs(nf.delta - (2.0 * A21 / d2).real() / (2.0 * A11 / d1).real()) < tol::normal_form_exact);
    // the pairs swapped: the same point seen from the other curve swaps the roles
    const DoubleHopfNormalForm sw = double_hopf_normal_form(sys, Eigen::VectorXd::Zero(5), sys.parameter_values(), w2, w1);
    REQUIRE(sw.status == Status::Converged);
    CHECK(std::abs(sw.g2100 - nf.g0021) < tol::normal_form_exact);
    CHECK(std::abs(sw.g1011 - nf.g1110) < tol::normal_form_exact);
    CHECK_THROWS_AS(double_hopf_normal_form(sys, Eigen::VectorXd::Zero(5), sys.parameter_values(), w1, w1), std::invalid_argument);
    // a strong resonance (omega2 = 2 omega1 or 3 omega1) has another normal form: refused, with the reason
    const DoubleHopfNormalForm r2 = double_hopf_normal_form(sys, Eigen::VectorXd::Zero(5), sys.parameter_values(), w1, 2.0 * w1);
    CHECK(r2.status == Status::NumericalIssue);
    CHECK(r2.message.find("1:2 resonance") != std::string::npos);
    CHECK(double_hopf_normal_form(sys, Eigen::VectorXd::Zero(5), sys.parameter_values(), 3.0 * w2, w2).message.find("1:3 resonance") != std::string::npos);
    REQUIRE(nf.status == Status::Converged);
}

TEST_SUITE_END();
