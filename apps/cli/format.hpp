#pragma once
// Formatting helpers of the command-line front's tables: rounded numbers for reading.
// Formatting only; the machine formats (JSON, CSV) come from the library's io/ layer.
#include <string>
#include <vector>

#include "ddemap/solve/roots.hpp"

namespace ddemap::cli {

/// %.*g for human tables.
std::string rounded(double v, int digits = 6);
/// Roots as a numbered human table (rounded).
std::string roots_table(const std::vector<Root>& roots);
/// N, or "inf" for 0.
inline std::string ring_name(int cars) { return cars == 0 ? "inf" : std::to_string(cars); }

}  // namespace ddemap::cli
