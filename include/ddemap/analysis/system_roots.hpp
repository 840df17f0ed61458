#pragma once
/// \file system_roots.hpp
/// Rightmost roots and the stability verdict of any linear DDE with discrete delays (a system
/// read from a file): the dense collocation solver or, for real systems with delays, the sparse
/// shift-invert solver; one result layout for both.

#include <string>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/solve/shift_invert.hpp"

namespace ddemap {

struct SystemRootOptions {
    int count = 6;                                 ///< how many rightmost roots
    int degree = 0;                                ///< sparse path: collocation degree (0 = automatic)
    SolverMethod method = SolverMethod::Automatic; ///< automatic: sparse for real systems with delays above dense_limit states
    int dense_limit = 16;
    /// std::invalid_argument in the API's words (count, degree, method)
    void validate() const;
};

struct SystemRootResult {
    RootResult roots;                               ///< the dense layout for both paths
    SolverMethod method_given = SolverMethod::Automatic;
    SolverMethod method_used = SolverMethod::Dense; ///< dense or sparse
    double spectral_abscissa = 0.0;
    bool stable = false;                            ///< converged and every root has Re < -marginal band
};

/// Throws std::invalid_argument when the method does not fit the system (product; sparse for a
/// complex system or an ODE).
SystemRootResult analyse_system(const LinearDDE& dde, const SystemRootOptions& options = {});

}  // namespace ddemap
