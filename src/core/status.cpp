#include "ddemap/core/status.hpp"

namespace ddemap {

std::string to_string(Status s) {
    switch (s) {
        case Status::Converged: return "converged";
        case Status::MaxIterations: return "max_iterations";
        case Status::MaxDegreeReached: return "max_degree_reached";
        case Status::NumericalIssue: return "numerical_issue";
        case Status::BudgetExhausted: return "budget_exhausted";
        case Status::Cancelled: return "cancelled";
    }
    return "unknown";
}

std::string to_string(Verdict v) {
    switch (v) {
        case Verdict::Stable: return "stable";
        case Verdict::Marginal: return "marginal";
        case Verdict::Unstable: return "unstable";
        case Verdict::Undecided: return "undecided";
    }
    return "unknown";
}

}  // namespace ddemap
