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
/// When every matrix is given as triplets with real values the system is held sparse
/// (LinearDDE sparse storage), otherwise dense.

#include <memory>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "ddemap/problem/expression_system.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// The size of a system file, read without building the system (so the work can be sized
/// first): values below the top level's arrays are skipped. 0 for what the text lacks;
/// std::invalid_argument for text that is not JSON.
/// A file whose matrices are all real triplets is held sparse (`sparse`, with its number of
/// triplets in `nonzeros`); the others are held dense.
struct LinearDdeShape {
    long dimension = 0;
    std::size_t delays = 0;
    bool sparse = false;
    long nonzeros = 0;
};
LinearDdeShape peek_linear_dde_json(const std::string& text, const std::string& source);
/// The same by a text search only (no tokenisation: about 0.1 s for 500 MB), for a file with no
/// "triplets" (held dense): the first "dimension": N and the length of the first "delays": [...]
/// list. Empty when the text does not show them plainly (then peek_linear_dde_json decides).
std::optional<LinearDdeShape> quick_peek_linear_dde_json(const std::string& text);

/// Parses the JSON text; std::invalid_argument naming `source` and the field on error.
/// Coefficients are 0 or of magnitude 1e-100 to 1e100, delays from 0 to 1e100.
LinearDDE read_linear_dde_json(const std::string& text, const std::string& source);

/// A nonlinear DDE written with expressions (problem/expression.hpp):
///
///     { "variables": ["x1", "x2"],
///       "parameters": {"a": 0.5, "b": 0.6, "d": 0.05, "tau": 2.0},
///       "equations": ["x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"],
///       "equilibrium": [0, 0] }
///
/// "equations"[i] is dx_i/dt; a delayed value is NAME(t - DELAY) with DELAY an expression of
/// parameters and numbers. "equilibrium" (optional) is the starting guess of Newton (zeros when
/// not given). Parameters keep the file's order. "comment" is allowed.
struct NonlinearSystemFile {
    std::shared_ptr<ExpressionSystem> system;
    Eigen::VectorXd equilibrium;     ///< the guess (zeros when not given)
    bool equilibrium_given = false;
};

/// True when the text is a JSON object with "equations" (a nonlinear file); false otherwise
/// (invalid JSON included: read_linear_dde_json then says what is wrong).
bool is_nonlinear_system_json(const std::string& text);

/// Parses a nonlinear file; std::invalid_argument naming `source`, the field, and for an
/// expression the equation and character.
NonlinearSystemFile read_nonlinear_system_json(const std::string& text, const std::string& source);

}  // namespace ddemap
