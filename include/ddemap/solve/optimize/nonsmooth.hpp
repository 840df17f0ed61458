#pragma once
/// \file nonsmooth.hpp
/// Minimisation of a locally Lipschitz function that may be non-smooth on a set of measure zero
/// (a maximum over frequencies, the real part of whichever root is rightmost): BFGS with a
/// weak-Wolfe line search, as Lewis and Overton ("Nonsmooth optimization via quasi-Newton
/// methods", Math. Program. 141, 2013) and the HANSO package use it, with their stopping test:
/// the smallest vector in the convex hull of the gradients at the recent iterates near the
/// current one (an approximate Clarke stationarity measure). Where the line search cannot make
/// progress and that vector is not small, one gradient-sampling step (along minus it) is taken
/// and the quasi-Newton matrix is reset.

#include <functional>
#include <limits>
#include <string>

#include <Eigen/Dense>
#include <vector>

#include "ddemap/core/status.hpp"

namespace ddemap {

/// f(x), with its gradient written into `gradient` (resized by the callee to x.size()) where f is
/// differentiable (anywhere else: the gradient of a nearby piece). +infinity or NaN means "outside
/// the domain": the line search backtracks from it; the start must be inside.
using NonsmoothFunction = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& gradient)>;

struct NonsmoothOptions {
    int max_iterations = 200;        ///< quasi-Newton iterations at most (>= 1)
    int max_evaluations = 3000;      ///< evaluations of f at most, line searches included (>= 10)
    /// Converged when the smallest vector of the convex hull of the gradients at the iterates
    /// within `sampling_radius` of the current one (at most `bundle_size` of them, the current
    /// included) has a norm at most this (> 0) times max(1, the largest of their norms).
    double stationarity_tolerance = 1e-6;
    /// (> 0) in the units of x. When the test passes at a radius, the search continues with the
    /// radius divided by 10 until it is at most `final_radius` (as HANSO's sequence of sampling
    /// radii): a kink is then located to about final_radius.
    double sampling_radius = 1e-4;
    double final_radius = 1e-8;      ///< (0 < final_radius <= sampling_radius)
    int bundle_size = 12;            ///< (>= 2)
    /// Converged as soon as f <= target (default: -infinity, never): "reach a level" rather than
    /// "minimise".
    double target = -std::numeric_limits<double>::infinity();
    /// Converged when a line search ends with a step |t d| below this (>= 0) and the stationarity
    /// measure is below sqrt(stationarity_tolerance) (a non-smooth minimiser met to rounding).
    double step_tolerance = 1e-12;
    bool is_valid(std::string* why = nullptr) const;
    /// std::invalid_argument naming the first bad option.
    void validate() const;
};

struct NonsmoothResult {
    /// Converged (stationary to the tolerance, or the target reached), MaxIterations,
    /// BudgetExhausted (evaluations), NumericalIssue (f not finite at the start).
    Status status = Status::MaxIterations;
    std::string message;
    Eigen::VectorXd x;            ///< the best point found
    double value = 0.0;           ///< f(x)
    Eigen::VectorXd gradient;     ///< at x
    double stationarity = 0.0;    ///< norm of the smallest vector of the gradients' convex hull at x, relative (see the options)
    int iterations = 0;
    int evaluations = 0;
    int sampling_steps = 0;       ///< gradient-sampling steps taken where the line search failed
    /// the iterates: x0, then every accepted step (line search or gradient sampling), in order
    std::vector<Eigen::VectorXd> path;
};

/// Minimises f from x0 (f(x0) must be finite).
NonsmoothResult minimize_nonsmooth(const NonsmoothFunction& f, const Eigen::VectorXd& x0, const NonsmoothOptions& options = {});

/// The smallest-norm vector of the convex hull of the columns of G (min |G l| over l >= 0,
/// sum l = 1), by projected gradient iterations on the simplex to a relative change of 1e-14;
/// exact for one column. Used by the stopping test above.
Eigen::VectorXd min_norm_in_hull(const Eigen::MatrixXd& G);

}  // namespace ddemap
