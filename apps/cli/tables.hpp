#pragma once
// Human tables shared by several commands (classify and paper; growth and paper).
#include <string>
#include <vector>

#include "ddemap/analysis/classify.hpp"
#include "ddemap/study/growth.hpp"

namespace ddemap::cli {

std::string classification_table(const std::vector<Classification>& rows, int cars, const std::string& source);
std::string growth_table(const std::vector<GrowthResult>& g);

}  // namespace ddemap::cli
