#include "ddemap/core/status.hpp"

namespace ddemap {

std::string to_string(Status s) {
    switch (s) {
        case Status::Converged: return "converged";
        case Status::MaxIterations: return "max_iterations";
        case Status::MaxDegreeReached: return "max_degree_reached";
        case Status::NumericalIssue: return "numerical_issue";
        case Status::BudgetExhausted: return "budget_exhausted";
    }
    return "unknown";
}

}  // namespace ddemap
