#pragma once
// Human tables shared by several commands (classify and paper; growth and paper).
#include <string>
#include <vector>

#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/study/growth.hpp"

namespace ddemap::cli {

/// "p > 0.999" (every sample unstable: the Wilson lower bound, rounded down), "p < 0.001"
/// (none: the upper bound, rounded up), else "p = 0.873 +- 0.005" (the Monte Carlo standard error).
std::string probability_text(const ProbabilityEstimate& e);
std::string classification_table(const std::vector<Classification>& rows, int cars, const std::string& source);
std::string growth_table(const std::vector<GrowthResult>& g);

}  // namespace ddemap::cli
