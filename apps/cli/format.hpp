#pragma once
// Formatting helpers of the command-line front: round-trip numbers for machine output,
// rounded numbers for tables. Formatting only; no numerics here.
#include <string>
#include <vector>

#include "ddemap/solve/roots.hpp"

namespace ddemap::cli {

/// %.17g: round-trip exact. Non-finite values never reach output (callers check).
std::string exact(double v);
/// %.*g for human tables.
std::string rounded(double v, int digits = 6);
/// Quotes a CSV field if needed.
std::string csv_field(const std::string& s);
/// Roots as CSV: re,im,residual,newton_step (round-trip exact).
std::string roots_csv(const std::vector<Root>& roots);
/// Roots as a numbered human table (rounded).
std::string roots_table(const std::vector<Root>& roots);

}  // namespace ddemap::cli
