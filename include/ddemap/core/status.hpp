#pragma once
/// \file status.hpp
/// One status for every iterative computation in ddemap (cf. Spectra's CompInfo, Ceres'
/// TerminationType). A result whose status is not Converged is never a verdict: analyses report
/// it as undecided with the result's message.

#include <string>

namespace ddemap {

enum class Status {
    Converged,         ///< the method's own convergence test passed (and its certificate, if any)
    MaxIterations,     ///< an iteration cap was reached before the convergence test passed
    MaxDegreeReached,  ///< a discretisation cap (degree, mesh) was reached before the result settled
    NumericalIssue,    ///< a singular or non-finite intermediate (a failed factorisation, an overflow)
    BudgetExhausted    ///< a work budget (cells, shifts, evaluations) ran out
};

/// "converged", "max_iterations", "max_degree_reached", "numerical_issue", "budget_exhausted"
std::string to_string(Status s);

/// True for Status::Converged.
inline bool converged(Status s) { return s == Status::Converged; }

}  // namespace ddemap
