#pragma once
// Formatting helpers of the command-line front: round-trip numbers for machine output,
// rounded numbers for tables. Formatting only; no numerics here.
#include <string>

namespace ddemap::cli {

/// %.17g: round-trip exact. Non-finite values never reach output (callers check).
std::string exact(double v);
/// %.*g for human tables.
std::string rounded(double v, int digits = 6);
/// Quotes a CSV field if needed.
std::string csv_field(const std::string& s);

}  // namespace ddemap::cli
