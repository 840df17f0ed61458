#pragma once
/// \file fold_curve.hpp
/// Two-parameter continuation of folds (saddle-nodes) of equilibria, with the cusp and
/// Bogdanov-Takens points on them.
///
/// A fold of the equilibria of x'(t) = f(x(t), x(t - tau_1), ...; p) is an equilibrium where
/// J = A_0 + ... + A_m (A_k = D_{u_k} f at the constant history) is singular: a characteristic
/// root at 0 (Delta(0) = -J). The fold curve in (p1, p2) is followed by pseudo-arclength
/// (solve/continuation.hpp) on the fold system (equilibrium_branch.hpp, fold_system) with p2 free,
/// u = (x, p1, v, p2): 2n + 1 equations
///     f(x, ..., x; p) = 0,   J v = 0,   v0 . v = 1,
/// in 2n + 2 unknowns, with the exact Jacobian (the p2 column from the fold system in p2); v0 is
/// renewed (v0 = v / |v|^2) every `segment` points. The delays do not enter (a constant history),
/// so the curve is that of the ODE x' = f(x, ..., x; p); the stability along it is the DDE's.
///
/// With w the left null vector (w^T J = 0, |w| = 1, |v| = 1, the sign of w carried along the
/// curve), two test functions are followed at every point:
///     cusp:              a = w . D^2 f[S v, S v]              (S: the constant stacking),
///     Bogdanov-Takens:   b = w . Delta'(0) v = w . (I + sum_k tau_k A_k) v.
/// a is the quadratic coefficient of the fold's normal form (up to the factor 1 / (2 b)): the
/// fold is non-degenerate where a != 0, a cusp where a = 0. b = 0 where the root at 0 is double
/// (Delta'(0) v lies in the range of J): a Bogdanov-Takens point, where a Hopf curve ends on the
/// fold curve. Each sign change between two points is located by Illinois regula falsi along the
/// chord, every trial corrected onto the curve (as the generalised Hopf points of Hopf curves).
/// At every point the characteristic roots are computed (equilibrium_roots with branch.roots) and
/// counted right of the axis, the fold's own root at 0 excepted; where the count changes in a
/// step, the change must be explained: +-1 by a Bogdanov-Takens point located in the step (a
/// real root through 0), +-2 by a zero-Hopf point (a pair through the axis at +-i omega, located
/// by bisection of the count along the chord, every trial corrected onto the curve); a change
/// that is not makes the curve's status NumericalIssue.
/// Cf. DDE-BIFTOOL's fold continuation (p_tofold, br_contn) and its normal-form tests.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/normal_forms.hpp"
#include "ddemap/core/types.hpp"

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/continuation.hpp"

namespace ddemap {

/// The box and continuation of the fold curves (TwoParameterOptions: the equilibrium branch in p1
/// whose folds start the curves, the second parameter and its box, the steps and the budget).
struct FoldCurveOptions : TwoParameterOptions {};

struct FoldCurvePoint {
    double par = 0.0, par2 = 0.0;
    Eigen::VectorXd x;
    double cusp_test = 0.0;  ///< a = w . D^2 f[S v, S v] (|v| = |w| = 1)
    double bt_test = 0.0;    ///< b = w . Delta'(0) v
    double residual = std::numeric_limits<double>::infinity();  ///< max |.| of the fold system
    /// The characteristic roots right of the axis besides the fold's root at 0 (-1: the roots did
    /// not converge) and the roots themselves (rightmost first).
    int unstable = -1;
    std::vector<cplx> roots;
};

/// A codimension-two point on a fold curve: kind "cusp" (a = 0), "bogdanov_takens" (b = 0) or
/// "zero_hopf" (a pair +-i omega on the axis besides the root at 0).
struct FoldCurveSpecialPoint {
    std::string kind;
    double omega = 0.0;     ///< zero_hopf: the pair's frequency
    double par = 0.0, par2 = 0.0;
    Eigen::VectorXd x;
    double test = 0.0;      ///< the test function at the located point
    double other = 0.0;     ///< the other test function there (b at a cusp, a at a Bogdanov-Takens point)
    /// Normal-form coefficients at the located point (normal_forms.hpp, DDE-BIFTOOL's
    /// normalisation): Bogdanov-Takens a (nf_a) and b (nf_b), w1' = a w0^2 + b w0 w1; cusp b (nf_b,
    /// ~0) and c (nf_c), w' = b w^2 + c w^3. NaN where not computed (zero-Hopf points; a point not
    /// located).
    double nf_a = std::numeric_limits<double>::quiet_NaN();
    double nf_b = std::numeric_limits<double>::quiet_NaN();
    double nf_c = std::numeric_limits<double>::quiet_NaN();
    /// zero_hopf: its normal form (status NumericalIssue where not formed)
    ZeroHopfNormalForm zero_hopf;
    Status status = Status::MaxIterations;
    double residual = std::numeric_limits<double>::infinity();  ///< of the fold system
    int after = 0;          ///< index of the curve point before it
};

struct FoldCurve {
    int start = 0;  ///< the index of the fold of the branch in p1 it starts from
    std::vector<FoldCurvePoint> points;  ///< in order along the curve
    std::vector<FoldCurveSpecialPoint> special;  ///< cusp, Bogdanov-Takens and zero-Hopf points, in order
    ContinuationStop stop_backward = ContinuationStop::MaxPoints, stop_forward = ContinuationStop::MaxPoints;
    Status status = Status::Converged;
    std::string message;
};

struct FoldCurves {
    EquilibriumBranch start;  ///< the equilibrium branch in p1 and its folds
    /// One per distinct curve through the located folds (kind "fold") of the branch in p1 (a fold
    /// that lies on a curve already traced starts none).
    std::vector<FoldCurve> curves;
    /// Converged when the branch in p1 did and every curve did (ended on the box, closed, or at a
    /// regular end) with every special point located.
    Status status = Status::Converged;
    std::string message;
};

/// The fold curves through the folds of the equilibrium branch in p1 (from `guess` at
/// branch.from, p2 as held). std::invalid_argument for invalid options, unknown parameters, a
/// held p2 outside [from2, to2], or a system without second derivatives.
FoldCurves fold_curves(const NonlinearDDE& system, const Eigen::VectorXd& guess, const FoldCurveOptions& options);

}  // namespace ddemap
