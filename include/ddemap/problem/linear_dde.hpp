#pragma once
/// \file linear_dde.hpp
/// The problem description: a linear delay differential equation with discrete delays,
///     x'(t) = A_0 x(t) + sum_k A_k x(t - tau_k),   x in C^n,
/// and its characteristic matrix
///     Delta(lambda) = lambda I - A_0 - sum_k A_k exp(-lambda tau_k).

#include <complex>
#include <vector>

#include <Eigen/Dense>

#include "ddemap/core/types.hpp"

namespace ddemap {

/// One delayed term A * x(t - delay).
struct DelayTerm {
    MatrixXc matrix;
    double delay = 0.0;
};

/// x'(t) = A0 x(t) + sum_k A_k x(t - tau_k). Validates on construction: square matrices of
/// one dimension, finite entries, finite delays >= 0 (std::invalid_argument otherwise).
/// Terms with delay 0 are folded into A0; terms with equal delays are merged.
class LinearDDE {
public:
    LinearDDE(MatrixXc a0, std::vector<DelayTerm> delayed);

    int dimension() const { return static_cast<int>(m_a0.rows()); }
    const MatrixXc& a0() const { return m_a0; }
    /// The delayed terms, sorted by increasing delay, all delays > 0.
    const std::vector<DelayTerm>& delayed() const { return m_delayed; }
    /// tau_max = max_k tau_k (0 for an ODE).
    double max_delay() const;
    bool is_ode() const { return m_delayed.empty(); }
    /// True when every coefficient is real (roots then come in conjugate pairs).
    bool is_real() const;

    /// Delta(lambda) = lambda I - A0 - sum_k A_k e^{-lambda tau_k}.
    MatrixXc characteristic_matrix(cplx lambda) const;
    /// Delta'(lambda) = I + sum_k tau_k A_k e^{-lambda tau_k}.
    MatrixXc characteristic_derivative(cplx lambda) const;
    /// A0 + sum_k A_k: the ODE obtained for tau -> 0.
    MatrixXc ode_limit() const;
    /// Radius R(sigma) such that every root with Re(lambda) >= sigma has |lambda| <= R:
    ///     |lambda| <= ||A0||_2 + sum_k ||A_k||_2 e^{-sigma tau_k}   (from Delta(lambda) v = 0).
    double root_bound(double sigma) const;

private:
    MatrixXc m_a0;
    std::vector<DelayTerm> m_delayed;
    std::vector<double> m_norms;  // ||A_k||_2 of the delayed terms
    double m_norm0 = 0.0;
};

}  // namespace ddemap
