#pragma once
/// \file normal_forms.hpp
/// Normal-form coefficients of the codimension-two points of equilibria on fold curves, in
/// DDE-BIFTOOL's normalisation (nmfm_bt, nmfm_cusp), so that the numbers compare.
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

}  // namespace ddemap
