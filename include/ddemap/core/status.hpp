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
    BudgetExhausted,   ///< a work budget (cells, shifts, evaluations) ran out
    Cancelled          ///< the caller's progress callback stopped the work (threw ddemap::Cancelled)
};

/// "converged", "max_iterations", "max_degree_reached", "numerical_issue", "budget_exhausted",
/// "cancelled"
std::string to_string(Status s);

/// True for Status::Converged.
inline bool converged(Status s) { return s == Status::Converged; }

/// The answer of a stability analysis. Stable: every root (trivial ones excluded) has
/// Re < -marginal band; Marginal: none right of the band but some within it (on the imaginary
/// axis to rounding); Unstable: some root right of the band; Undecided: the computation did not
/// converge (its status says why), so no verdict is given.
enum class Verdict { Stable, Marginal, Unstable, Undecided };

/// "stable", "marginal", "unstable", "undecided"
std::string to_string(Verdict v);

/// The verdict from the counts of a converged computation (Undecided when not converged).
inline Verdict verdict_of(Status s, int unstable, int marginal) {
    if (s != Status::Converged) return Verdict::Undecided;
    return unstable > 0 ? Verdict::Unstable : marginal > 0 ? Verdict::Marginal : Verdict::Stable;
}

}  // namespace ddemap
