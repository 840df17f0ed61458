#pragma once
/// \file continuation.hpp
/// Pseudo-arclength continuation of a curve F(u) = 0, F: R^{n+1} -> R^n (n equations in n+1
/// unknowns: a state and one free parameter, or any implicitly defined curve).
///
/// One step from a point u_k with unit tangent t_k and step h:
///   predictor  v = u_k + h t_k,
///   corrector  Newton on  G(u) = [F(u); t_k . (u - v)] = 0, i.e. the bordered system
///              [J(u); t_k^T] du = [F(u); t_k . (u - v)],   u <- u - du   (ddemap::newton),
///   tangent    t_{k+1} = z / |z| with [J(u_{k+1}); t_k^T] z = [0; 1] (the null vector of J,
///              oriented so that t_{k+1} . t_k > 0).
/// A step is rejected and h halved when the corrector fails, when |u_{k+1} - u_k| > max_jump h
/// or when the angle between t_k and t_{k+1} exceeds max_angle; h grows by grow_factor (up to
/// max_step) after a corrector that took at most grow_iterations iterations (the rules of
/// StepControl, solve/step_control.hpp).
/// Events: a box lower <= u <= upper (the branch ends exactly on the face it crosses, located by
/// Newton on [F(u); u_i - bound] = 0) and scalar test functions g(u, t) whose sign changes
/// between consecutive points are located on the curve by Illinois regula falsi in the
/// arclength s (each trial point corrected from u_k + s t_k). A branch also ends when it leaves
/// the problem's domain, when it closes on its start, after max_points points, or when the step
/// falls below min_step.
/// With a scale vector c > 0 the engine works in the unknowns u_i / c_i (steps, tangents,
/// distances and tolerances are measured there); inputs and results are in u.
/// Cf. the continuation of knut and DDE-BIFTOOL (br_contn), which this follows in shape.

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/status.hpp"
#include "ddemap/core/newton.hpp"

namespace ddemap {

/// A curve F(u) = 0 with n = equations() equations in n + 1 unknowns.
class ContinuationProblem {
public:
    virtual ~ContinuationProblem() = default;
    /// n; the unknowns are n + 1.
    virtual int equations() const = 0;
    int unknowns() const { return equations() + 1; }
    /// F(u) (resized to n); false when F cannot be evaluated at u.
    virtual bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const = 0;
    /// J(u) = dF/du, n x (n+1); false when it cannot be evaluated at u.
    /// (central_difference_jacobian is a helper an implementation may call.)
    virtual bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const = 0;
    /// False where the curve is not to be followed (the branch ends before such a point).
    virtual bool in_domain(const Eigen::VectorXd& /*u*/) const { return true; }
};

/// Central differences: J(:, c) = (F(u + h e_c) - F(u - h e_c)) / (2 h),
/// h = relative_step * max(1, |u_c|). Where F fails on one side only (u within h of the edge of
/// the problem's domain), the one-sided second-order difference
/// (-3 F(u) + 4 F(u + s h e_c) - F(u + 2 s h e_c)) / (2 s h) towards the side s = +-1 where it
/// does not. False when F fails on both sides or at u.
bool central_difference_jacobian(const ContinuationProblem& problem, const Eigen::VectorXd& u, Eigen::MatrixXd& j,
                                 double relative_step = 1e-7);

/// A scalar test function g(u, t) of a point and its unit tangent (e.g. g = t_p, the parameter
/// component of the tangent, changes sign at a fold). Its zeros are located on the curve.
struct TestFunction {
    std::string name;
    std::function<double(const Eigen::VectorXd& u, const Eigen::VectorXd& t)> value;
    bool terminal = false;  ///< the branch ends at the zero (which becomes its last point)
};

struct ContinuationOptions {
    double initial_step = 0.01;  ///< h at the start
    double max_step = 0.1;
    double min_step = 1e-8;      ///< the branch ends when h falls below it
    int max_points = 1000;       ///< points of the branch, the start included
    double grow_factor = 1.5;    ///< h <- min(max_step, grow_factor h) after an easy corrector
    int grow_iterations = 3;     ///< "easy": at most this many Newton iterations
    double max_jump = 3.0;       ///< reject a step with |u_{k+1} - u_k| > max_jump h
    /// reject a step turning the tangent by more than this [rad], in (0, pi/2]; pi/2 disables
    /// the test (consecutive tangents have t_{k+1} . t_k > 0)
    double max_angle = 0.5;
    double event_tolerance = 1e-12;  ///< arclength width at which an event's location stops
    /// the corrector; it stops when |du| <= step_tolerance * max(1, |u|)
    NewtonOptions newton{12, 1e-13};
    /// Box of the unknowns (empty: none; else n + 1 entries each, +-infinity for no bound).
    Eigen::VectorXd lower, upper;
    /// Characteristic size c_i > 0 of each unknown (empty: all 1).
    Eigen::VectorXd scale;
    /// Called with the unknowns u of every point added to the branch after the start (in u, not
    /// scaled); may throw to stop the continuation (the exception reaches the caller of
    /// continue_branch). Empty: nothing is called.
    std::function<void(const Eigen::VectorXd& u)> on_point;
    /// True when the options are usable; otherwise `why` (if given) names the field.
    bool is_valid(std::string* why = nullptr) const;
};

/// Why a branch ended.
enum class ContinuationStop {
    MaxPoints,         ///< max_points points
    Bound,             ///< the branch reached a face of the box (its last point lies on it)
    TerminalEvent,     ///< a terminal test function vanished (its zero is the last point)
    ClosedLoop,        ///< the branch returned to its start
    LeftDomain,        ///< the next point is outside the problem's domain
    StepBelowMinimum,  ///< the step was halved below min_step
    TangentFailed      ///< the tangent could not be computed (J rank deficient or not evaluable)
};

/// "max_points", "bound", "terminal_event", "closed_loop", "left_domain", "step_below_minimum",
/// "tangent_failed"
std::string to_string(ContinuationStop s);

struct ContinuationEvent {
    enum class Kind { Bound, Test };
    Kind kind = Kind::Test;
    int index = -1;           ///< the unknown whose bound was reached, or the test function's index
    Eigen::VectorXd u, t;     ///< the point on the curve and its unit tangent
    double residual = std::numeric_limits<double>::infinity();  ///< |F(u)|
    int after = 0;            ///< index of the branch point before the event
    bool located = true;      ///< false when the location stopped early (u is then its best estimate)
};

struct ContinuationResult {
    /// points[0] is the start (points and tangents are empty when the start has no tangent)
    std::vector<Eigen::VectorXd> points;
    std::vector<Eigen::VectorXd> tangents;  ///< unit tangent at every point
    std::vector<ContinuationEvent> events;  ///< in the order met
    ContinuationStop stop = ContinuationStop::MaxPoints;
    /// Converged when the branch ended at a bound, a terminal event, a closed loop or the
    /// domain's edge; BudgetExhausted at max_points; NumericalIssue when a tangent failed;
    /// below min_step, the last rejection's: the corrector's status (MaxIterations,
    /// NumericalIssue), or NumericalIssue for a jump or an angle.
    Status status = Status::Converged;
    std::string message;
    int newton_iterations = 0;  ///< over all corrector and event-location solves
    int rejected_steps = 0;
    double max_residual = 0.0;  ///< largest |F| at the branch points
};

/// What a correction did.
struct CorrectorResult {
    Status status = Status::MaxIterations;
    int iterations = 0;
    double residual = std::numeric_limits<double>::infinity();  ///< |F(u)| at the result
};

/// Newton on [F(u); a . u - b] = 0 from u (updated in place): the bordered system
/// [J(u); a^T] du = [F(u); a . u - b]. Pseudo-arclength: a = t, b = t . v.
CorrectorResult correct(const ContinuationProblem& problem, Eigen::VectorXd& u, const Eigen::VectorXd& a, double b,
                        const NewtonOptions& options = {12, 1e-13});

/// Unit tangent at u: the null vector of J(u). With a reference r (non-empty) it solves
/// [J; r^T] z = [0; 1] and returns z / |z| (so t . r > 0); without one it takes the null vector
/// from a QR factorisation of J^T, oriented so that det [J; t^T] > 0. False when J cannot be
/// evaluated or has rank < n.
bool tangent(const ContinuationProblem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& reference,
             Eigen::VectorXd& t);

/// Traces the branch through u0 (assumed on the curve) in the direction of the tangent that has
/// a positive component along `direction`, locating the zeros of `tests` on the way.
/// Throws std::invalid_argument on invalid options or sizes.
ContinuationResult continue_branch(const ContinuationProblem& problem, const Eigen::VectorXd& u0,
                                   const Eigen::VectorXd& direction, const ContinuationOptions& options,
                                   const std::vector<TestFunction>& tests = {});

}  // namespace ddemap
