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
/// "1 orbit", "3 orbits": the count and the noun, singular for exactly one (`plural`: the
/// noun's plural when it is not the singular with an "s").
inline std::string counted(long long n, const std::string& singular, const std::string& plural = {}) {
    return std::to_string(n) + " " + (n == 1 ? singular : plural.empty() ? singular + "s" : plural);
}
/// A column of a human table: s followed by spaces to width w, or by one space when it is wider.
inline std::string pad(std::string s, std::size_t w) {
    if (s.size() < w) s.resize(w, ' ');
    else s += ' ';
    return s;
}
/// N, or "inf" for 0.
inline std::string ring_name(int cars) { return cars == 0 ? "inf" : std::to_string(cars); }

}  // namespace ddemap::cli
