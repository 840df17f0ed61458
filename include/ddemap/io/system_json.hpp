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

/// Parses the JSON text; std::invalid_argument naming `source` and the field on error.
LinearDDE read_linear_dde_json(const std::string& text, const std::string& source);

}  // namespace ddemap
