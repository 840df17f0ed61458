#pragma once
/// \file equilibrium.hpp
/// Equilibria of a nonlinear DDE (problem/nonlinear_dde.hpp): x* with
///     g(x) = f(x, x, ..., x; p) = 0,
/// by Newton (core/newton.hpp) with the exact Jacobian dg/dx = A_0 + A_1 + ... + A_m
/// (the blocks D_{u_k} f, dual numbers).

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/newton.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

struct EquilibriumOptions {
    NewtonOptions newton{50, 1e-13};
    /// Accept the result when max_i |g_i(x*)| is at most this (besides Newton's step test).
    double residual_tolerance = 1e-9;
    bool is_valid(std::string* why = nullptr) const;
};

struct EquilibriumResult {
    Eigen::VectorXd x;           ///< the equilibrium (Newton's last iterate when not converged)
    Status status = Status::MaxIterations;
    std::string message;
    int iterations = 0;
    double residual = std::numeric_limits<double>::infinity();  ///< max_i |g_i(x)|
};

/// Newton from `guess` at the parameter values p (the held ones when p is empty).
/// std::invalid_argument for a guess of the wrong size or with a non-finite entry, or invalid
/// options; non-convergence (a singular Jacobian, the iteration cap, a residual above the
/// tolerance) is a status.
EquilibriumResult find_equilibrium(const NonlinearDDE& system, const Eigen::VectorXd& guess, const EquilibriumOptions& options = {},
                                   const std::vector<double>& p = {});

}  // namespace ddemap
