#pragma once
/// \file equilibrium_branch.hpp
/// Branches of equilibria of a nonlinear DDE in one parameter p (problem/nonlinear_dde.hpp):
/// the curve g(x, p) = f(x, ..., x; p) = 0 in R^{n+1}, followed by pseudo-arclength continuation
/// (solve/continuation.hpp, through folds) with the exact Jacobian [A_0 + ... + A_m, df/dp]; at
/// every point the rightmost characteristic roots of the linearisation (solve/roots.hpp).
/// Special points:
///  - fold: the tangent's parameter component changes sign (a test function of the engine); then
///    Newton on the fold system  g(x, p) = 0,  (sum_k A_k) v = 0,  v0 . v = 1  (2n + 1 unknowns);
///  - branch point: det(A_0 + ... + A_m) = det Delta(0) changes sign in a step without a fold
///    (an odd number of real roots crosses 0); Newton on the fold system (FoldPoint::kind);
///  - Hopf: a root with Im > 0 and its nearest partner at the next point have real parts of
///    opposite signs (and, when these matched crossings do not account for the change in the
///    number of roots with Re > 0 and Im > 0, the root nearest the axis; two crossings of one
///    pair between two points are not seen); then Newton on
///    the Hopf system  g(x, p) = 0,  Delta(i omega; x, p) q = 0,  q0^H q = 1  (x, p, q in C^n,
///    omega > 0: 3n + 2 real unknowns), from the root nearest the imaginary axis. The residuals
///    use the exact characteristic matrix; Newton's Jacobian of these augmented systems is exact
///    (fold_system, hopf_system: blocks from second derivatives of f in nested dual numbers), so
///    Newton converges quadratically.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/continuation.hpp"
#include "ddemap/solve/equilibrium.hpp"
#include "ddemap/solve/roots.hpp"

namespace ddemap {

struct EquilibriumBranchOptions {
    std::string parameter;  ///< the free parameter (a name of the system)
    double from = 0.0;      ///< the branch starts at p = from (the equilibrium found from the guess there)
    double to = 1.0;        ///< and is followed towards p = to (it ends on the face p = to or min/max)
    /// Steps, box and budget; initial_step/max_step 0 = automatic (|to - from| / 100 and / 20);
    /// the box is set to p in [min(from, to), max(from, to)].
    ContinuationOptions continuation = [] {
        ContinuationOptions c;
        c.initial_step = 0.0;
        c.max_step = 0.0;
        c.min_step = 1e-10;
        c.max_points = 400;
        return c;
    }();
    /// At every point; count: the roots reported. More are computed for the detection of Hopf
    /// points: from count (at least 2; 8 when those do not converge), doubled (up to 256) until the result is certified complete in a strip
    /// Re >= strip_floor with strip_floor < 0, so that every unstable root and the stable ones
    /// nearest the axis are seen.
    RootOptions roots;
    EquilibriumOptions equilibrium;    ///< the first point
    NewtonOptions special{40, 1e-12};  ///< Newton on the fold and Hopf systems
    double special_residual = 1e-9;    ///< accept a fold/Hopf point with residual at most this
    /// After the roots of every point of the branch: (points done, points of the branch, p).
    /// The continuation (Newton only) runs first, then the roots point by point (most of the
    /// time: the pilot points of before_roots first, then the others in order); within a point's root search the last call is repeated (the points done so far,
    /// after every unit of that search's work: RootOptions::progress) so that a printer can show
    /// that a long point is still running and a Cancelled thrown there stops it. The callback may
    /// throw to stop, and that exception reaches the caller.
    BranchProgress progress;
    /// The size guard of the roots (the long part), called twice with the number of points whose
    /// roots are to be computed: after the continuation and before any root, with
    /// estimate_root_work's prediction for one root search at the first point (measured = 0;
    /// each point makes one to a few searches: equilibrium_roots), then after the roots of each of
    /// the pilot points, computed first (the ends, the middle and the quarters of the branch:
    /// min(5, points) of them), with the mean of their measured times as `one.seconds` (measured
    /// = the pilots done; the last call, measured = min(5, points), is the final prediction):
    /// points x one.seconds predicts the whole (the cost of a point changes along a branch with
    /// the roots near the axis). It may throw (a guard refusing the work; the exception reaches
    /// the caller). May be empty.
    std::function<void(long points, const RootWorkEstimate& one, int measured)> before_roots;
    bool is_valid(std::string* why = nullptr) const;
};

struct EquilibriumPoint {
    double par = 0.0;
    Eigen::VectorXd x;
    std::vector<cplx> roots;  ///< rightmost first (options.roots.count of them)
    double abscissa = 0.0;    ///< max Re over the roots
    int unstable = 0;         ///< roots with Re > 0 (counted with conjugates)
    bool stable = false;      ///< roots converged and every Re < -marginal band
    Status roots_status = Status::Converged;
};

/// A steady-state bifurcation: a real root of the characteristic equation at 0 (det(A_0 + ... +
/// A_m) = 0). kind "fold" where the branch turns back (the tangent's parameter component changes
/// sign), "branch_point" where det(A_0 + ... + A_m) changes sign between two points but the
/// branch goes on (a pitchfork or transcritical point: another branch of equilibria crosses).
/// Both are located by Newton on the fold system.
struct FoldPoint {
    std::string kind = "fold";  ///< "fold" or "branch_point"
    double par = 0.0;
    Eigen::VectorXd x;
    Status status = Status::MaxIterations;
    double residual = std::numeric_limits<double>::infinity();
    int iterations = 0;
    std::vector<double> residuals;  ///< max |F| of the fold system at every Newton iterate, the start first
    int after = 0;  ///< index of the branch point before it
};

struct HopfPoint {
    double par = 0.0;
    Eigen::VectorXd x;
    double omega = 0.0;  ///< the crossing pair is +-i omega
    VectorXc q;          ///< Delta(i omega) q = 0
    Status status = Status::MaxIterations;
    double residual = std::numeric_limits<double>::infinity();
    int iterations = 0;
    std::vector<double> residuals;  ///< max |F| of the Hopf system at every Newton iterate, the start first
    int after = 0;
};

struct EquilibriumBranch {
    std::string parameter;
    std::vector<EquilibriumPoint> points;
    std::vector<FoldPoint> folds;
    std::vector<HopfPoint> hopf;
    ContinuationStop stop = ContinuationStop::MaxPoints;
    /// Converged when the start converged, the branch reached the end of its range (or another
    /// regular end), every root computation converged and every special point was located.
    Status status = Status::Converged;
    std::string message;
};

/// The branch through the equilibrium found from `guess` at p = from. std::invalid_argument for
/// invalid options, an unknown parameter, a bad guess or a system without second derivatives or
/// delay derivatives (has_higher_derivatives(), has_delay_derivatives(): the exact Jacobians of the
/// fold and Hopf systems need them); non-convergence is a status. correct_hopf and correct_fold
/// check the same.
EquilibriumBranch equilibrium_branch(const NonlinearDDE& system, const Eigen::VectorXd& guess, const EquilibriumBranchOptions& options);

/// The other branch through a located branch point `bp` of `branch` (a point where a real root
/// crosses 0 without a fold: bp.kind == "branch_point"), in the same parameter and range. At the
/// point the kernel of [Delta(0) f_p] has two dimensions; the new branch leaves along the kernel
/// direction t2 orthogonal to the old branch's chord across the point (oriented towards
/// options.to in the parameter): its first point solves F(u) = 0, t2 . (u - u0) = h (h the first
/// step; that hyperplane meets a transversal new branch at a distance ~h and the old one only at
/// ~sqrt(h)), and the branch is followed from there as equilibrium_branch follows one, the branch
/// point its first point. One side of the new branch: the other side with from and to swapped.
/// std::invalid_argument for invalid options or a point that is not a located branch point of
/// `branch`; non-convergence is a status.
///
/// `side`: Towards (the default) follows the half described above; Away the opposite half (-t2:
/// at a transcritical point the part towards options.from, at a pitchfork, where both halves
/// leave towards the same side of the parameter, the other half, which swapping from and to
/// cannot reach); Both follows the two halves and joins them into one branch through the point:
/// the Away half reversed (its far end first, the branch point last), then the Towards half
/// after the point; special points keep their place (`after` renumbered), the status is the
/// worse of the two, `stop` the Towards half's and the message names both ends.
enum class BranchSide { Towards, Away, Both };
EquilibriumBranch equilibrium_branch_from_branch_point(const NonlinearDDE& system, const EquilibriumBranch& branch, const FoldPoint& bp,
                                                       const EquilibriumBranchOptions& options, BranchSide side = BranchSide::Towards);

/// The fold system F(z), z = (x, p_j, v) (2n + 1 unknowns):
///     F = (f(x, ..., x; p),  (A_0 + ... + A_m) v,  v0 . v - 1),
/// and, when J is given, its exact Jacobian: the x and p_j columns of (sum_k A_k) v are
/// D^2 f[(S v, 0), (S e_i, 0)] and D^2 f[(S v, 0), (0, e_j)] (S the constant stacking), one
/// evaluation in Dual<Dual<double>> each. False when F is not defined at z (a bad delay, a
/// non-finite value); std::invalid_argument for sizes that do not fit. `values` (optional, all
/// the parameter values) replaces the held values of the parameters other than p_j (fold curves,
/// analysis/bifurcation/fold_curve.hpp).
bool fold_system(const NonlinearDDE& system, int parameter, const Eigen::VectorXd& v0, const Eigen::VectorXd& z, Eigen::VectorXd& F,
                 Eigen::MatrixXd* J = nullptr, const std::vector<double>& values = {});

/// The Hopf system F(z), z = (x, p_j, Re q, Im q, omega) (3n + 2 unknowns):
///     F = (f(x, ..., x; p),  Re, Im of Delta(i omega; x, p) q,  Re, Im of q0^H q - 1),
/// Delta(lambda) = lambda I - sum_k A_k exp(-lambda tau_k) (tau_0 = 0), and, when J is given, its
/// exact Jacobian: with w_k = exp(-i omega tau_k) q, Delta q = i omega q - Df[w], so
///     d/dx_i = -D^2 f[w, S e_i],  d/dp_j = -D^2 f[w, e_pj] + i omega sum_k tau_k' A_k w_k,
///     d/dq = Delta(i omega),  d/domega = i (q + sum_k tau_k A_k w_k)
/// (second derivatives in Dual<Dual<double>>, tau_k' from delay_derivatives). False when F is not
/// defined at z; std::invalid_argument for sizes that do not fit. `values` (optional, all the
/// parameter values) replaces the held values of the parameters other than p_j (two-parameter
/// continuation of Hopf curves, analysis/hopf.hpp).
bool hopf_system(const NonlinearDDE& system, int parameter, const VectorXc& q0, const Eigen::VectorXd& z, Eigen::VectorXd& F,
                 Eigen::MatrixXd* J = nullptr, const std::vector<double>& values = {});

/// Newton on the Hopf system from (x0, p_j = par0, omega0), the other parameters as held;
/// q0 is the starting null vector (empty: the right singular vector of Delta(i omega0) for its
/// smallest singular value).
HopfPoint correct_hopf(const NonlinearDDE& system, int parameter, const Eigen::VectorXd& x0, double par0, double omega0,
                       const VectorXc& q0 = {}, const NewtonOptions& newton = {40, 1e-12}, double residual_tolerance = 1e-9);

/// The characteristic roots of the linearisation at the equilibrium x (all parameter values p):
/// requested from options.count (at least 2; 8 when those do not converge), doubled (up to 256)
/// until the result is certified complete in a strip Re >= strip_floor with strip_floor < 0, so
/// that every root with Re >= 0 is among them. unstable: the roots right of marginal_band (a root
/// on the axis is not counted); stable: every root left of it.
struct EquilibriumRoots {
    std::vector<cplx> roots;  ///< rightmost first
    int unstable = 0;
    double abscissa = std::numeric_limits<double>::quiet_NaN();
    bool stable = false;
    Status status = Status::NumericalIssue;
};
EquilibriumRoots equilibrium_roots(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, RootOptions options);
/// The same for a linearisation already formed (thread-safe: independent linearisations may be
/// processed in parallel).
EquilibriumRoots equilibrium_roots(const LinearDDE& linearisation, RootOptions options);

/// The box and the continuation of a curve of special points of the equilibria in two parameters
/// (Hopf curves, hopf.hpp; fold curves, fold_curve.hpp): every curve starts at a special point of
/// the equilibrium branch in p1 (at the held p2) and is followed both ways by pseudo-arclength until
/// it leaves the box [branch.from, branch.to] x [from2, to2] (or the budget ends); the
/// normalisation of its defining system is renewed every `segment` points.
struct TwoParameterOptions {
    EquilibriumBranchOptions branch;  ///< p1 = branch.parameter, the box [branch.from, branch.to]
    std::string parameter2;
    double from2 = 0.0, to2 = 1.0;    ///< the box in p2 (the held p2 must lie in it)
    /// Steps are measured with p1, p2 scaled by their box sides; initial/max step 0 = automatic
    /// (0.01 and 0.05 of the box).
    ContinuationOptions continuation = [] {
        ContinuationOptions c;
        c.initial_step = 0.0;
        c.max_step = 0.0;
        c.min_step = 1e-9;
        c.max_points = 400;  // per direction
        return c;
    }();
    int segment = 25;
    /// After every point traced on a curve (both directions; the equilibrium branch in p1
    /// reports through branch.progress): (points of this curve so far, at most
    /// 2 continuation.max_points - 1, p1). It may throw to stop; the exception reaches the caller.
    BranchProgress progress;
    bool is_valid(std::string* why = nullptr) const;
    /// The system's value of parameter2, checked to lie in [from2, to2] (std::invalid_argument
    /// naming it otherwise; also for an unknown name).
    double held_second(const NonlinearDDE& system) const;
};

/// Newton on the fold system from (x0, p_j = par0).
FoldPoint correct_fold(const NonlinearDDE& system, int parameter, const Eigen::VectorXd& x0, double par0,
                       const NewtonOptions& newton = {40, 1e-12}, double residual_tolerance = 1e-9);

}  // namespace ddemap
