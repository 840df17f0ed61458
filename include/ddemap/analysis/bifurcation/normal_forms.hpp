#pragma once
/// \file normal_forms.hpp
/// Normal-form coefficients of the codimension-two points of equilibria, in DDE-BIFTOOL's
/// normalisation (nmfm_bt, nmfm_cusp, nmfm_zeho, nmfm_hoho, nmfm_genh), so that the numbers compare.
///
/// At an equilibrium x* of x'(t) = f(x(t), x(t - tau_1), ..., x(t - tau_m); p), with
/// A_k = D_{u_k} f and the characteristic matrix Delta(lambda) = lambda I - A_0 - sum_k A_k
/// e^{-lambda tau_k}, its derivatives at 0 are
///     Delta(0) = -sum_k A_k,  Delta'(0) = I + sum_k tau_k A_k,  Delta''(0) = -sum_k tau_k^2 A_k,
///     Delta'''(0) = sum_k tau_k^3 A_k.
/// B[phi, psi] = D^2 f[(phi(0), phi(-tau_1), ...), (psi(0), ...)] and C likewise with D^3 f are
/// the multilinear forms on functions of theta in [-tau_max, 0].
///
/// Bogdanov-Takens (a double root 0 with one eigenvector): the Jordan chain Delta(0) q0 = 0,
/// Delta(0) q1 = -Delta'(0) q0 with |q0| = 1, q0 . q1 = 0, the eigenfunctions phi0(theta) = q0,
/// phi1(theta) = q1 + theta q0; the adjoint chain p1 Delta(0) = 0, p0 Delta(0) = -p1 Delta'(0),
/// normalised (<phi*_i, phi_j> = delta_ij) by
///     p0 Delta' q0 + p1 Delta'' q0 / 2 = 1,
///     p0 Delta' q1 + p0 Delta'' q0 / 2 + p1 Delta'' q1 / 2 + p1 Delta''' q0 / 6 = 0.
/// The normal form w0' = w1, w1' = a w0^2 + b w0 w1 + ... has
///     a = p1 B[phi0, phi0] / 2,   b = p0 B[phi0, phi0] + p1 B[phi0, phi1].
/// (a, b) change sign together with q0 (here its largest component is positive); a b and the
/// sign of a b (which side the homoclinic orbit lies on) do not.
///
/// Cusp (a simple root 0 where the fold's quadratic coefficient vanishes): Delta(0) q = 0,
/// |q| = 1 (largest component positive), p Delta(0) = 0 with p Delta'(0) q = 1, phi = q constant;
/// the centre manifold's quadratic term h2 = y - (p Delta'(0) y) q with
/// [Delta(0) q; p 0] [y; s] = [B[phi, phi]; 0], and
///     b = p B[phi, phi] / 2 (0 at the cusp),   c = p (3 B[phi, h2] + C[phi, phi, phi]) / 6,
/// the coefficients of w' = b w^2 + c w^3 on the centre manifold. DDE-BIFTOOL's nmfm_cusp (v3.2
/// source) writes h2 with the opposite sign (-y + ...), which disagrees with the reduction onto
/// the centre manifold (tested here on a planar system whose reduction is done by hand) and with
/// the sign of its own nmfm_zeho (h = Delta^-1 B); c here is the reduction's.
///
/// Zero-Hopf (fold-Hopf: a simple root 0 and a simple pair +-i omega), as DDE-BIFTOOL's nmfm_zeho:
/// Delta(0) q0 = 0, |q0| = 1 (largest component positive), p0 Delta(0) = 0, p0 Delta'(0) q0 = 1;
/// Delta(i omega) q1 = 0, |q1| = 1, p1 Delta(i omega) = 0, p1 Delta'(i omega) q1 = 1 (p a row,
/// no conjugation); phi0 = q0, phi1(theta) = e^{i omega theta} q1. With the bordered inverse
/// binv(lambda, q, p, zeta, kappa) = theta -> e^{lambda theta} (xi + gamma q - kappa theta q),
/// [Delta(lambda) q; p 0] [xi; s] = [zeta + kappa Delta'(lambda) q; 0],
/// gamma = -p Delta'(lambda) xi + kappa p Delta''(lambda) q / 2, the centre manifold's
///     h200 = binv(0, q0, p0, B00, -p0 B00),  h011 = binv(0, q0, p0, B11b, -p0 B11b),
///     h110 = binv(i omega, q1, p1, B01, -p1 B01),  h020 = e^{2 i omega theta} Delta(2 i omega)^-1 B11,
/// (B00 = B[phi0, phi0], B01 = B[phi0, phi1], B11 = B[phi1, phi1], B11b = B[phi1, conj phi1]) and
///     g200 = p0 B00 / 2,  g110 = p1 B01,  g011 = p0 B11b,
///     g300 = p0 (3 B[phi0, h200] + C[phi0, phi0, phi0]) / 6,
///     g111 = p0 (B[phi0, h011] + B[conj phi1, h110] + B[phi1, conj h110] + C[phi0, phi1, conj phi1]),
///     g210 = p1 (B[phi1, h200] + 2 B[phi0, h110] + C[phi0, phi0, phi1]) / 2,
///     g021 = p1 (B[conj phi1, h020] + 2 B[phi1, h011] + C[phi1, phi1, conj phi1]) / 2,
/// the coefficients of w0' = g200 w0^2 + g011 |w1|^2 + g300 w0^3 + g111 w0 |w1|^2,
/// w1' = i omega w1 + g110 w0 w1 + g210 w0^2 w1 + g021 w1 |w1|^2; Gavrilov's b = g200, c = g011,
/// d = g110 - i omega g300 / g200, e = Re(g210 + g110 (Re g021 / g011 - 3 g300 / (2 g200) +
/// g111 / (2 g011)) - g021 g200 / g011), s = b c and theta = Re g110 / g200 (s and theta decide the
/// unfolding's type: s = +1 or -1, theta's sign; they do not depend on the sign of q0).
///
/// Double Hopf (two simple pairs +-i omega1, +-i omega2, no resonance 1:1, 1:2, 1:3: refused), as
/// DDE-BIFTOOL's nmfm_hoho: the pairs (q_j, p_j) normalised as above, phi_j = e^{i omega_j theta} q_j,
/// lambda_j = i omega_j; with h_lambda[v] = theta -> e^{lambda theta} Delta(lambda)^-1 v,
///     h1100 = h_0[B(phi1, conj phi1)],  h2000 = h_{2 lambda1}[B(phi1, phi1)],
///     h1010 = h_{lambda1 + lambda2}[B(phi1, phi2)],  h1001 = h_{lambda1 - lambda2}[B(phi1, conj phi2)],
///     h0020 = h_{2 lambda2}[B(phi2, phi2)],  h0011 = h_0[B(phi2, conj phi2)],
///     g2100 = p1 (2 B(h1100, phi1) + B(h2000, conj phi1) + C(phi1, phi1, conj phi1)) / 2,
///     g1011 = p1 (B(h0011, phi1) + B(h1001, phi2) + B(h1010, conj phi2) + C(phi1, phi2, conj phi2)),
///     g1110 = p2 (B(conj h1001, phi1) + B(h1010, conj phi1) + B(h1100, phi2) + C(phi1, conj phi1, phi2)),
///     g0021 = p2 (2 B(h0011, phi2) + B(h0020, conj phi2) + C(phi2, phi2, conj phi2)) / 2,
/// the coefficients of w1' = i omega1 w1 + g2100 w1 |w1|^2 + g1011 w1 |w2|^2,
/// w2' = i omega2 w2 + g1110 w2 |w1|^2 + g0021 w2 |w2|^2; theta = Re g1011 / Re g0021 and
/// delta = Re g1110 / Re g2100 (with the signs of Re g2100, Re g0021 they decide the unfolding's
/// type: simple or difficult case, and which tori and three-tori it has).
///
/// Generalised Hopf (Bautin: a simple pair +-i omega where L1 = 0), as DDE-BIFTOOL's nmfm_genh
/// (Kuznetsov's formulas for the centre manifold of a DDE): with (q, p) and phi = e^{i omega theta} q,
/// lambda = i omega and D, E the fourth and fifth derivatives of f as multilinear forms,
///     h20 = h_{2 lambda}[B(phi, phi)],  h11 = h_0[B(phi, conj phi)],
///     c1 = p (B(conj phi, h20) + 2 B(phi, h11) + C(phi, phi, conj phi)) / 2,
///     h30 = h_{3 lambda}[3 B(phi, h20) + C(phi, phi, phi)],
///     h21 = binv(lambda, q, p, B(conj phi, h20) + 2 B(phi, h11) + C(phi, phi, conj phi), -2 c1),
///     h31 = theta -> e^{2 lambda theta} (Delta(2 lambda)^-1 (R31 - 6 c1 Delta'(2 lambda) y20) + 6 c1 theta y20),
///       y20 = Delta(2 lambda)^-1 B(phi, phi),
///       R31 = B(conj phi, h30) + 3 B(phi, h21) + 3 B(h20, h11) + 3 C(phi, conj phi, h20) + 3 C(phi, phi, h11)
///             + D(phi, phi, phi, conj phi),
///     h22 = h_0[2 B(conj phi, h21) + 2 B(h11, h11) + 2 B(phi, conj h21) + B(h20, conj h20)
///             + C(conj phi, conj phi, h20) + C(phi, phi, conj h20) + 4 C(phi, conj phi, h11) + D(phi, phi, conj phi, conj phi)],
///     c2 = p (6 B(h11, h21) + 3 B(conj h21, h20) + B(conj h20, h30) + 3 B(phi, h22) + 2 B(conj phi, h31)
///             + 6 C(conj phi, h20, h11) + 6 C(phi, h11, h11) + 3 C(phi, h20, conj h20) + 6 C(phi, conj phi, h21)
///             + 3 C(phi, phi, conj h21) + C(conj phi, conj phi, h30) + 6 D(phi, phi, conj phi, h11)
///             + 3 D(phi, conj phi, conj phi, h20) + D(phi, phi, phi, conj h20) + E(phi, phi, phi, conj phi, conj phi)) / 12,
/// the coefficients of w' = i omega w + c1 w |w|^2 + c2 w |w|^4; L1 = Re c1 / omega and the second
/// Lyapunov coefficient L2 = Re c2 / omega (defined where L1 = 0; its sign says whether the fold of
/// periodic orbits born there lies on the side where the equilibrium is stable, L2 < 0, or not).

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

struct BogdanovTakensNormalForm {
    Status status = Status::NumericalIssue;
    std::string message;
    double a = std::numeric_limits<double>::quiet_NaN();
    double b = std::numeric_limits<double>::quiet_NaN();
    Eigen::VectorXd q0, q1, p0, p1;
    /// How far the point is from a Bogdanov-Takens point: sigma_min(Delta(0)) / |Delta(0)| and
    /// |p1 Delta'(0) q0| / (|p1| |Delta'(0)| |q0|) (both ~0 at the point; the caller's located point)
    double kernel_residual = std::numeric_limits<double>::quiet_NaN();
    double double_root_residual = std::numeric_limits<double>::quiet_NaN();
};

struct CuspNormalForm {
    Status status = Status::NumericalIssue;
    std::string message;
    double b = std::numeric_limits<double>::quiet_NaN();  ///< quadratic coefficient (0 at a cusp)
    double c = std::numeric_limits<double>::quiet_NaN();  ///< cubic coefficient
    Eigen::VectorXd q, p;
    double kernel_residual = std::numeric_limits<double>::quiet_NaN();  ///< sigma_min(Delta(0)) / |Delta(0)|
};

struct ZeroHopfNormalForm {
    Status status = Status::NumericalIssue;
    std::string message;
    double g200 = std::numeric_limits<double>::quiet_NaN(), g011 = std::numeric_limits<double>::quiet_NaN();
    double g300 = std::numeric_limits<double>::quiet_NaN(), g111 = std::numeric_limits<double>::quiet_NaN();
    cplx g110{std::numeric_limits<double>::quiet_NaN(), 0.0}, g210{std::numeric_limits<double>::quiet_NaN(), 0.0},
        g021{std::numeric_limits<double>::quiet_NaN(), 0.0};
    double b = std::numeric_limits<double>::quiet_NaN(), c = std::numeric_limits<double>::quiet_NaN();
    cplx d{std::numeric_limits<double>::quiet_NaN(), 0.0};
    double e = std::numeric_limits<double>::quiet_NaN(), s = std::numeric_limits<double>::quiet_NaN(),
           theta = std::numeric_limits<double>::quiet_NaN();
    Eigen::VectorXd q0, p0;
    VectorXc q1, p1;
    /// sigma_min / sigma_max of Delta(0) and of Delta(i omega) (both ~0 at the point)
    double kernel_residual = std::numeric_limits<double>::quiet_NaN();
    double hopf_residual = std::numeric_limits<double>::quiet_NaN();
};

struct DoubleHopfNormalForm {
    Status status = Status::NumericalIssue;
    std::string message;
    cplx g2100{std::numeric_limits<double>::quiet_NaN(), 0.0}, g1011{std::numeric_limits<double>::quiet_NaN(), 0.0},
        g1110{std::numeric_limits<double>::quiet_NaN(), 0.0}, g0021{std::numeric_limits<double>::quiet_NaN(), 0.0};
    double theta = std::numeric_limits<double>::quiet_NaN(), delta = std::numeric_limits<double>::quiet_NaN();
    VectorXc q1, p1, q2, p2;
    /// sigma_min / sigma_max of Delta(i omega1) and of Delta(i omega2) (both ~0 at the point)
    double hopf1_residual = std::numeric_limits<double>::quiet_NaN();
    double hopf2_residual = std::numeric_limits<double>::quiet_NaN();
};

struct GeneralisedHopfNormalForm {
    Status status = Status::NumericalIssue;
    std::string message;
    cplx c1{std::numeric_limits<double>::quiet_NaN(), 0.0}, c2{std::numeric_limits<double>::quiet_NaN(), 0.0};
    double l1 = std::numeric_limits<double>::quiet_NaN();  ///< Re c1 / omega (0 at the point)
    double l2 = std::numeric_limits<double>::quiet_NaN();  ///< Re c2 / omega
    VectorXc q, p;
    double hopf_residual = std::numeric_limits<double>::quiet_NaN();  ///< sigma_min / sigma_max of Delta(i omega)
};

/// The Bogdanov-Takens coefficients (a, b) at the equilibrium x of `system` at parameter values p
/// (the system's second derivatives are needed: has_higher_derivatives(), else
/// std::invalid_argument). Status NumericalIssue when the Jordan chain cannot be formed (the
/// kernel of Delta(0) not one-dimensional, the bordered systems singular) or a value is not finite.
BogdanovTakensNormalForm bogdanov_takens_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p);

/// The cusp coefficients (b, c) at the equilibrium x at parameter values p (second and third
/// derivatives needed); as above.
CuspNormalForm cusp_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p);

/// The zero-Hopf coefficients at the equilibrium x at parameter values p with the pair +-i omega
/// (omega > 0; second and third derivatives needed); status NumericalIssue when a kernel is not
/// one-dimensional, a normalisation or bordered system is singular or a g is not finite. At a
/// degenerate point (g200 = 0 or g011 = 0) the status is Converged, the g are given and what
/// divides by them (d, theta; e) is NaN, the message says which.
ZeroHopfNormalForm zero_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, double omega);

/// The double Hopf coefficients at the equilibrium x at parameter values p with the pairs
/// +-i omega1, +-i omega2 (0 < omega1 != omega2; second and third derivatives needed); status
/// NumericalIssue at a 1:2 or 1:3 resonance (omega2 = k omega1 or omega1 = k omega2 to 1e-6
/// relative; within 1e-2 the message warns), when a kernel is not one-dimensional, an inverse is
/// singular (2 omega_j or omega1 +- omega2 a root frequency too) or a g is not finite. Where Re g2100 or
/// Re g0021 is 0, delta or theta is NaN and the message says so (status Converged).
DoubleHopfNormalForm double_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, double omega1,
                                             double omega2);

/// c1, c2, L1 and L2 at the equilibrium x at parameter values p with the pair +-i omega (omega > 0;
/// derivatives of order 2 to 5 needed: has_higher_derivatives()); status NumericalIssue when the
/// root is not simple, 2 i omega or 3 i omega is a root too, or a coefficient is not finite.
GeneralisedHopfNormalForm generalised_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p,
                                                       double omega);

}  // namespace ddemap
