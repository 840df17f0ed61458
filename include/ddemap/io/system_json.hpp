#pragma once
/// \file system_io.hpp
/// A general linear DDE x'(t) = A0 x(t) + sum_k A_k x(t - tau_k) from JSON:
///
///     { "dimension": 2,
///       "delays": [0.5, 1.0],
///       "A0": [[-1, 0], [0, -2]],
///       "A":  [ [[0.3, 0], [0, 0]],  {"triplets": [[1, 1, -0.4]]} ] }
///
/// Each matrix is a dense array of rows or {"triplets": [[row, col, value], ...]} (0-based,
/// repeated entries add up); a value is a number or [re, im]. "A0" may be omitted (zero).

#include <string>

#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// The size of a system file, read without building the system (so the work can be sized
/// first): values below the top level's arrays are skipped. 0 for what the text lacks;
/// std::invalid_argument for text that is not JSON.
struct LinearDdeShape {
    long dimension = 0;
    std::size_t delays = 0;
};
LinearDdeShape peek_linear_dde_json(const std::string& text, const std::string& source);

/// Parses the JSON text; std::invalid_argument naming `source` and the field on error.
/// Coefficients are 0 or of magnitude 1e-100 to 1e100, delays from 0 to 1e100.
LinearDDE read_linear_dde_json(const std::string& text, const std::string& source);

}  // namespace ddemap
