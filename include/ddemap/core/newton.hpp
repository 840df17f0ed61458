#pragma once
/// \file newton.hpp (core: a header-only loop over Status, usable from every layer)
/// The one Newton iteration of ddemap. Every Newton method in the library (a characteristic
/// root, a root of a quasi-polynomial or a ring determinant, a point on a continuation branch,
/// an equilibrium, a Hopf point) is this loop with its own correction step:
///     x_{k+1} = x_k - dx_k,   dx_k = step(x_k)   (dx = J(x)^{-1} F(x), or f/f' for a scalar),
/// stopped when |dx_k| <= step_tolerance * max(1, |x_{k+1}|) (Converged), when a step is not
/// finite or the step function reports a singular system (NumericalIssue), or after
/// max_iterations steps (MaxIterations). The caller's step function may also end the iteration
/// as converged when it finds F(x) = 0 exactly (a zero step).

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <string>

#include <Eigen/Core>

#include "ddemap/core/status.hpp"

namespace ddemap {

struct NewtonOptions {
    int max_iterations = 60;
    /// relative step tolerance: stop when |dx| <= step_tolerance * max(1, |x|)
    double step_tolerance = 4.0 * std::numeric_limits<double>::epsilon();
    /// True when the options are usable; otherwise `message` (if given) names the field.
    bool is_valid(std::string* message = nullptr) const {
        const char* why = nullptr;
        if (max_iterations < 1) why = "max_iterations: expected an integer >= 1";
        else if (!(std::isfinite(step_tolerance) && step_tolerance > 0.0)) why = "step_tolerance: expected a finite value > 0";
        if (why && message) *message = why;
        return why == nullptr;
    }
};

/// What the iteration did.
struct NewtonSummary {
    Status status = Status::MaxIterations;
    int iterations = 0;                                          ///< steps taken
    double last_step = std::numeric_limits<double>::infinity();  ///< |dx| of the last step (an error estimate)
};

/// What a step function returns.
enum class NewtonStep {
    Ok,        ///< dx was computed
    Exact,     ///< F(x) = 0 exactly: x is converged as it is (dx is ignored)
    Singular   ///< the correction cannot be computed at x (a singular Jacobian, f' = 0)
};

namespace newton_detail {
inline double size(double x) { return std::abs(x); }
inline double size(const std::complex<double>& x) { return std::abs(x); }
template <class Derived>
double size(const Eigen::MatrixBase<Derived>& x) { return x.norm(); }
inline bool finite(double x) { return std::isfinite(x); }
inline bool finite(const std::complex<double>& x) { return std::isfinite(x.real()) && std::isfinite(x.imag()); }
template <class Derived>
bool finite(const Eigen::MatrixBase<Derived>& x) { return x.allFinite(); }
}  // namespace newton_detail

/// Runs Newton from x (updated in place). `step(const X& x, X& dx) -> NewtonStep` computes the
/// correction dx = J(x)^{-1} F(x); X is double, std::complex<double> or an Eigen vector.
template <class X, class StepFunction>
NewtonSummary newton(X& x, StepFunction&& step, const NewtonOptions& options = {}) {
    NewtonSummary summary;
    X dx = x;
    for (int it = 0; it < options.max_iterations; ++it) {
        const NewtonStep kind = step(static_cast<const X&>(x), dx);
        if (kind == NewtonStep::Exact) {
            summary.last_step = 0.0;
            summary.status = Status::Converged;
            return summary;
        }
        if (kind == NewtonStep::Singular) {
            summary.status = Status::NumericalIssue;
            return summary;
        }
        x -= dx;
        ++summary.iterations;
        summary.last_step = newton_detail::size(dx);
        if (!newton_detail::finite(x) || !std::isfinite(summary.last_step)) {
            summary.status = Status::NumericalIssue;
            return summary;
        }
        if (summary.last_step <= options.step_tolerance * std::max(1.0, newton_detail::size(x))) {
            summary.status = Status::Converged;
            return summary;
        }
    }
    summary.status = Status::MaxIterations;
    return summary;
}

}  // namespace ddemap
