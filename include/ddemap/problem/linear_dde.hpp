#pragma once
/// \file linear_dde.hpp
/// The problem description: a linear delay differential equation with discrete delays,
///     x'(t) = A_0 x(t) + sum_k A_k x(t - tau_k),   x in C^n,
/// and its characteristic matrix
///     Delta(lambda) = lambda I - A_0 - sum_k A_k exp(-lambda tau_k).
/// One type, two storages: dense complex matrices (small systems, any coefficients) or sparse
/// real matrices (large systems such as a ring of N cars, 2N states).

#include <complex>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "ddemap/core/types.hpp"
#include "ddemap/problem/root_bounds.hpp"

namespace ddemap {

using SparseMatrixXd = Eigen::SparseMatrix<double>;
using SparseMatrixXc = Eigen::SparseMatrix<cplx>;

/// One delayed term A * x(t - delay) (dense storage).
struct DelayTerm {
    MatrixXc matrix;
    double delay = 0.0;
};

/// One delayed term A * x(t - delay) (sparse real storage).
struct SparseDelayTerm {
    SparseMatrixXd matrix;
    double delay = 0.0;
};

/// x'(t) = A0 x(t) + sum_k A_k x(t - tau_k). Validates on construction: square matrices of
/// one dimension, finite entries, finite delays >= 0 (std::invalid_argument otherwise).
/// Terms with delay 0 are folded into A0; terms with equal delays are merged; the delayed terms
/// are sorted by increasing delay. Sparse storage also drops explicit zeros and empty terms.
/// The root bounds (root_bounds.hpp) are computed once here.
class LinearDDE {
public:
    /// Dense storage.
    LinearDDE(MatrixXc a0, std::vector<DelayTerm> delayed);
    /// Sparse real storage (cost O(nonzeros log nonzeros): a 2N-state ring is cheap to build).
    LinearDDE(SparseMatrixXd a0, std::vector<SparseDelayTerm> delayed);

    int dimension() const { return m_n; }
    bool is_sparse() const { return m_sparse; }
    /// A0 (dense storage; std::logic_error for sparse storage: use to_dense() on small systems).
    const MatrixXc& a0() const;
    /// The delayed terms (dense storage), sorted by increasing delay, all delays > 0.
    const std::vector<DelayTerm>& delayed() const;
    /// A0 (sparse storage; std::logic_error for dense storage: use to_sparse()).
    const SparseMatrixXd& sparse_a0() const;
    /// The delayed terms (sparse storage), sorted by increasing delay, all delays > 0.
    const std::vector<SparseDelayTerm>& sparse_delayed() const;
    /// The delays tau_k > 0, increasing (either storage).
    const std::vector<double>& delays() const { return m_delays; }
    /// tau_max = max_k tau_k (0 for an ODE).
    double max_delay() const { return m_delays.empty() ? 0.0 : m_delays.back(); }
    bool is_ode() const { return m_delays.empty(); }
    /// True when every coefficient is real (roots then come in conjugate pairs); always true
    /// for sparse storage.
    bool is_real() const { return m_real; }

    /// The same problem with dense storage (itself when dense).
    LinearDDE to_dense() const;
    /// The same problem with sparse real storage (std::invalid_argument for complex coefficients).
    LinearDDE to_sparse() const;

    /// Delta(lambda) = lambda I - A0 - sum_k A_k e^{-lambda tau_k} (dense; sparse storage is
    /// converted, so only for small systems).
    MatrixXc characteristic_matrix(cplx lambda) const;
    /// Delta'(lambda) = I + sum_k tau_k A_k e^{-lambda tau_k} (dense).
    MatrixXc characteristic_derivative(cplx lambda) const;
    /// Delta(lambda) as a sparse matrix (sparse storage).
    SparseMatrixXc sparse_characteristic_matrix(cplx lambda) const;
    /// Delta'(lambda) as a sparse matrix (sparse storage).
    SparseMatrixXc sparse_characteristic_derivative(cplx lambda) const;
    /// Delta(lambda) v (either storage).
    VectorXc apply_characteristic(cplx lambda, const VectorXc& v) const;
    /// A0 + sum_k A_k: the ODE obtained for tau -> 0 (dense).
    MatrixXc ode_limit() const;
    /// The root bounds (root_bounds.hpp).
    const RootBounds& bounds() const { return m_bounds; }
    /// R(sigma) = bounds().radius(sigma): every root with Re(lambda) >= sigma has |lambda| <= R.
    double root_bound(double sigma) const { return m_bounds.radius(sigma); }

private:
    bool m_sparse = false;
    bool m_real = true;
    int m_n = 0;
    MatrixXc m_a0;
    std::vector<DelayTerm> m_delayed;
    SparseMatrixXd m_sa0;
    std::vector<SparseDelayTerm> m_sdelayed;
    std::vector<double> m_delays;
    RootBounds m_bounds;
};

}  // namespace ddemap
