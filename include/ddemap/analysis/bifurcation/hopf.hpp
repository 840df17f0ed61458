#pragma once
/// \file hopf.hpp
/// Criticality of Hopf points of a nonlinear DDE (problem/nonlinear_dde.hpp) and two-parameter
/// continuation of Hopf curves.
///
/// Normal form (DDE-BIFTOOL's nmfm_hopf normalisation). At a Hopf point (x*, p_H, omega) with
///     Delta(lambda) = lambda I - A_0 - sum_k A_k exp(-lambda tau_k):
///  - q: the right null vector of Delta(i omega), ||q||_2 = 1 (phase: its largest entry real > 0);
///  - p: the left null vector (a row), scaled so that p Delta'(i omega) q = 1, with
///    Delta'(lambda) = I + sum_k tau_k A_k exp(-lambda tau_k);
///  - Phi = (q, q e^{-i omega tau_1}, ..., q e^{-i omega tau_m}) the stacked eigenfunction;
///  - B, C: the second and third derivatives of f in the stacked argument u (exact, nested dual
///    numbers; complex directions by multilinearity);
///  - h20 = Delta(2 i omega)^{-1} B(Phi, Phi),  H20 = (h20 e^{-2 i omega tau_k})_k,
///    h11 = Delta(0)^{-1} B(Phi, conj Phi),     H11 = (h11)_k;
///  - c1 = 1/2 p [C(Phi, Phi, conj Phi) + B(conj Phi, H20) + 2 B(Phi, H11)],  L1 = Re c1 / omega.
/// (DDE-BIFTOOL writes h11 with the factor 2 and c1 with B(Phi, h11): the same number.) On the
/// centre manifold x = x* + z q + conj(z q) + O(|z|^2) and z' = lambda(mu) z + c1 z |z|^2 + ...
/// (mu = p - p_H). Quantities that do not depend on the normalisation of q:
///  - the criticality: L1 < 0 supercritical (a stable orbit is born where the equilibrium loses
///    stability), L1 > 0 subcritical; degenerate when |L1| <= degenerate_tolerance * L1 scale,
///    the scale being (|p C(..)| + |p B(conj Phi, H20)| + 2 |p B(Phi, H11)|) / (2 omega);
///  - lambda'(p) = -p (dDelta/dp) q / (p Delta'(i omega) q) = -p (dDelta/dp) q, dDelta/dp the
///    total derivative along the equilibrium branch (x*'(p) = Delta(0)^{-1} df/dp, and the delays'
///    derivatives), and d Re(lambda)/dp = Re lambda'(p);
///  - the orbit: it exists on the side -mu Re lambda' / Re c1 > 0 with |z| = r,
///    r^2 = -mu Re lambda' / Re c1, so x(t) ~ x* + 2 r Re(q e^{i omega t}) and the range
///    max - min of variable j is ~ 4 r |q_j| = amplitude_coefficient_j sqrt(|mu|),
///    amplitude_coefficient_j = 4 |q_j| sqrt(|Re lambda' / Re c1|) (leading order; the error is
///    O(|mu|) relative).

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/normal_forms.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/continuation.hpp"

namespace ddemap {

enum class Criticality { Supercritical, Subcritical, Degenerate };
/// "supercritical", "subcritical", "degenerate"
std::string to_string(Criticality c);

struct HopfCoefficientOptions {
    /// |L1| <= this times its scale (see the file comment) is degenerate: the terms of c1 are
    /// exact derivatives combined in double precision, cancellations leave ~1e-14 relative, and
    /// a Hopf point located to a residual 1e-9 moves L1 by about that much relative.
    double degenerate_tolerance = 1e-7;
    /// |Re lambda'| <= this times |lambda'|: the crossing is not transversal (no side, no amplitude).
    double transversal_tolerance = 1e-10;
    bool is_valid(std::string* why = nullptr) const;
};

/// The normal form coefficients at one Hopf point.
struct HopfCoefficients {
    /// Converged when the Hopf point converged and every linear solve was regular; otherwise no
    /// coefficient below is meaningful (criticality Degenerate, side 0) and message says why.
    Status status = Status::NumericalIssue;
    std::string message;
    std::string method = "first Lyapunov coefficient from the centre-manifold normal form (exact derivatives)";
    double par = 0.0;      ///< p_H
    Eigen::VectorXd x;     ///< x*
    double omega = 0.0;
    VectorXc q;            ///< ||q|| = 1
    Eigen::RowVectorXcd p; ///< p Delta'(i omega) q = 1
    cplx c1{0.0, 0.0};
    double l1 = 0.0;       ///< Re c1 / omega
    double l1_scale = 0.0; ///< the size of the terms of L1 (see the file comment)
    Criticality criticality = Criticality::Degenerate;
    cplx dlambda{0.0, 0.0};  ///< lambda'(p) along the equilibrium branch
    double dre_dpar = 0.0;   ///< Re lambda'(p)
    /// +1: the orbit exists for p > p_H, -1: for p < p_H, 0: not decided (degenerate or not transversal).
    int side = 0;
    /// max - min of x_j ~ amplitude_coefficient_j sqrt(|p - p_H|) on that side (empty when side = 0).
    Eigen::VectorXd amplitude_coefficient;
    double residual = std::numeric_limits<double>::infinity();       ///< of the Hopf point's defining system
    double null_residual = std::numeric_limits<double>::infinity();  ///< max(|Delta q|, |p Delta| / |p|)
};

/// The coefficients at a located Hopf point of the parameter p_j (the other parameters as held).
/// A Hopf point that did not converge gives its status. std::invalid_argument for a bad index or
/// options, or a system without second/third or delay derivatives.
HopfCoefficients hopf_coefficients(const NonlinearDDE& system, int parameter, const HopfPoint& point, const HopfCoefficientOptions& options = {});
/// The same at explicit parameter values (values[parameter] = p_H), equilibrium x and omega > 0.
HopfCoefficients hopf_coefficients(const NonlinearDDE& system, int parameter, const std::vector<double>& values, const Eigen::VectorXd& x,
                                   double omega, const HopfCoefficientOptions& options = {});

/// The Hopf points on an equilibrium branch with their coefficients.
struct HopfAnalysis {
    EquilibriumBranch branch;
    std::vector<HopfCoefficients> points;  ///< one per branch.hopf, in the same order
    /// Converged when the branch did and every point's coefficients did.
    Status status = Status::Converged;
    std::string message;
};

HopfAnalysis hopf_points(const NonlinearDDE& system, const Eigen::VectorXd& guess, const EquilibriumBranchOptions& branch,
                         const HopfCoefficientOptions& options = {});

/// Two-parameter continuation of Hopf curves: pseudo-arclength (solve/continuation.hpp) on the
/// Hopf system (hopf_system) in u = (x, p1, Re q, Im q, omega, p2), 3n + 2 equations in 3n + 3
/// unknowns, with the exact Jacobian (the p2 column from the Hopf system in p2). The normalisation
/// q0^H q = 1 is renewed (q0 = q / |q|) every `segment` points. Every curve starts at a Hopf point
/// of the equilibrium branch in p1 (at the held p2), is followed both ways until it leaves the box
/// [from, to] x [from2, to2] (or omega reaches 0, or the budget ends), with L1 at every point;
/// generalised Hopf points (L1 changes sign) are located by Illinois regula falsi along the curve.
struct HopfCurveOptions : TwoParameterOptions {
    HopfCoefficientOptions coefficients;
    /// Codimension-two points on the curves: at every point the characteristic roots
    /// (equilibrium_roots with branch.roots) and the count of roots right of the axis besides the
    /// curve's pair; where it changes in a step, the root that crossed is located: a complex pair
    /// gives a double Hopf point (DoubleHopfPoint), a real root a zero-Hopf point (ZeroHopfPoint).
    /// A change that the points located do not explain makes the curve's status NumericalIssue.
    bool codimension_two = true;
    /// TwoParameterOptions::is_valid and the coefficients' options.
    bool is_valid(std::string* why = nullptr) const;
};

struct HopfCurvePoint {
    double par = 0.0, par2 = 0.0, omega = 0.0;
    Eigen::VectorXd x;
    HopfCoefficients coefficients;
    /// The characteristic roots right of the axis besides the curve's pair +-i omega (-1: not
    /// computed, codimension_two off or the roots did not converge) and the roots themselves.
    int unstable = -1;
    std::vector<cplx> roots;
};

/// A double Hopf (Hopf-Hopf) point: two pairs +-i omega1, +-i omega2 (omega1 != omega2) at one
/// equilibrium, where two Hopf curves cross. Located by Newton on the stacked defining system in
/// (x, p1, q1, omega1, p2, q2, omega2), 5n + 4 real unknowns:
///     f(x; p) = 0,  Delta(i omega1) q1 = 0,  q01^H q1 = 1,  Delta(i omega2) q2 = 0,  q02^H q2 = 1,
/// with the exact Jacobian (hopf_system's blocks; the p2 column from hopf_system in p2).
struct DoubleHopfPoint {
    double par = 0.0, par2 = 0.0;
    double omega1 = 0.0;  ///< the frequency of the curve it was found on
    double omega2 = 0.0;  ///< the frequency of the pair that crossed the axis there
    Eigen::VectorXd x;
    VectorXc q2;          ///< the null vector of Delta(i omega2), ||q2|| = 1 (starts the other curve)
    Status status = Status::MaxIterations;
    std::string message;
    double residual = std::numeric_limits<double>::infinity();  ///< max |.| of the stacked system
    int after = 0;         ///< index of the curve point before it
    int other_curve = -1;  ///< index in HopfCurves::curves of the Hopf curve with omega2 through it (-1: none traced)
    /// omega1 = omega2 (to 1e-6): a 1:1 resonance, the pair +-i omega double (as at a21 = 0 of
    /// DDE-BIFTOOL's neuron demo, which calls it spurious); no second curve starts there.
    bool resonant = false;
    /// at a located, non-resonant point: the normal-form coefficients (normal_forms.hpp,
    /// DDE-BIFTOOL's nmfm_hoho; omega1 the first pair's)
    DoubleHopfNormalForm normal_form;
};

/// A zero-Hopf (fold-Hopf) point: a real root crosses 0 on the Hopf curve (det Delta(0) changes
/// sign). Located by Illinois regula falsi on det Delta(0) / ||Delta(0)||^n along the chord of
/// the step, every trial corrected onto the curve.
struct ZeroHopfPoint {
    double par = 0.0, par2 = 0.0, omega = 0.0;
    Eigen::VectorXd x;
    Status status = Status::MaxIterations;
    double residual = std::numeric_limits<double>::infinity();  ///< of the Hopf system
    double det = 0.0;  ///< the scaled det Delta(0) at the located point
    int after = 0;
    /// at a located point: the normal-form coefficients (normal_forms.hpp, DDE-BIFTOOL's nmfm_zeho)
    ZeroHopfNormalForm normal_form;
};

struct GeneralisedHopfPoint {
    double par = 0.0, par2 = 0.0, omega = 0.0;
    Eigen::VectorXd x;
    Status status = Status::MaxIterations;
    double l1 = 0.0;       ///< at the located point (|l1| <= 1e-13 of its scale, or the chord bracket at rounding, when converged)
    double residual = std::numeric_limits<double>::infinity();  ///< of the Hopf system
    int after = 0;         ///< index of the curve point before it
    /// at a located point: c1, c2 and the second Lyapunov coefficient L2 = Re c2 / omega
    /// (normal_forms.hpp, DDE-BIFTOOL's nmfm_genh)
    GeneralisedHopfNormalForm normal_form;
};

/// A Bogdanov-Takens point where a Hopf curve ends (omega -> 0: the pair +-i omega becomes a double
/// root 0). Located by Newton on the Jordan-chain system in (x, p1, p2, v0, v1), 3n + 2 unknowns:
///     f(x; p) = 0,  Delta(0) v0 = 0,  Delta(0) v1 + Delta'(0) v0 = 0,  c . v0 = 1,  c . v1 = 0
/// (c the first v0), its Jacobian by central differences, from the curve's last point; the
/// residual of the system at the result (exact) must be below 1e-10. With its normal form (a, b)
/// in DDE-BIFTOOL's normalisation (normal_forms.hpp), as on fold curves.
struct HopfCurveBogdanovTakens {
    double par = 0.0, par2 = 0.0;
    Eigen::VectorXd x;
    Status status = Status::MaxIterations;
    std::string message;
    double residual = std::numeric_limits<double>::infinity();
    bool forward = true;  ///< at the forward end of the curve (else the backward one)
    BogdanovTakensNormalForm normal_form;
};

struct HopfCurve {
    int start = 0;  ///< the index of the Hopf point of the branch it starts from (-1: from a double Hopf point of another curve)
    std::vector<HopfCurvePoint> points;  ///< in order along the curve
    std::vector<GeneralisedHopfPoint> generalised;
    std::vector<DoubleHopfPoint> double_hopf;  ///< where the count of roots right of the axis changed by 2
    std::vector<ZeroHopfPoint> zero_hopf;      ///< where it changed by 1
    /// where the curve ends as omega falls to 0 (below 1 % of its largest on the curve)
    std::vector<HopfCurveBogdanovTakens> bogdanov_takens;
    ContinuationStop stop_backward = ContinuationStop::MaxPoints, stop_forward = ContinuationStop::MaxPoints;
    Status status = Status::Converged;
    std::string message;
};

struct HopfCurves {
    HopfAnalysis start;  ///< the equilibrium branch in p1 and its Hopf points
    /// One per distinct curve through the converged Hopf points of the branch in p1, then one
    /// from every double Hopf point whose second pair lies on no traced curve (the second curve
    /// through it, started from (x, p1, p2, omega2, q2) with p1 free).
    std::vector<HopfCurve> curves;
    Status status = Status::Converged;
    std::string message;
};

HopfCurves hopf_curves(const NonlinearDDE& system, const Eigen::VectorXd& guess, const HopfCurveOptions& options);

/// One Hopf curve through the located Hopf point `start` of p1 at the held p2.
HopfCurve hopf_curve(const NonlinearDDE& system, const HopfPoint& start, const HopfCurveOptions& options);

}  // namespace ddemap
