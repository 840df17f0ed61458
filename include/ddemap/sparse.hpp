#pragma once
/// \file sparse.hpp
/// Large real linear DDEs x' = A0 x + sum_k A_k x(t - tau_k) with sparse matrices, and the
/// structured shift-invert of their Chebyshev collocation matrix (see collocation.hpp).
///
/// For a shift sigma, (A_M - sigma I) u = b splits: with B = (2/tau) D[1:,1:] - sigma I (M x M)
/// and g = B^{-1} (2/tau) D[1:,0], the history blocks are U = B^{-1} b[1:] - g u0^T, and u0
/// solves the n x n sparse system S u0 = b0 - sum_k A_k (l_k[1:]^T B^{-1} b[1:]) with
///     S = A0 - sigma I + sum_k c_k A_k,   c_k = l_k[0] - l_k[1:] . g
/// (l_k the Lagrange weights of the node theta = -tau_k; c_k ~ e^{-sigma tau_k}, so S ~ -Delta).
/// One sparse LU of S (UMFPACK, symbolic analysis reused across shifts) and O(M^2 n) dense work
/// per application: the (M+1) n matrix is never formed.

#include <vector>

#include <Eigen/Sparse>

#include "ddemap/linear_dde.hpp"
#include "ddemap/roots.hpp"

namespace ddemap {

struct SparseDDE {
    Eigen::SparseMatrix<double> a0;
    struct Term {
        Eigen::SparseMatrix<double> matrix;
        double delay = 0.0;
    };
    std::vector<Term> delayed;  ///< delays > 0
    int dimension() const { return static_cast<int>(a0.rows()); }
    double max_delay() const;
    /// Validates square matrices of one size, finite entries, finite delays > 0.
    void validate() const;
    /// The same problem with dense matrices (for small systems and tests).
    LinearDDE to_dense() const;
};

/// Eigenvalues of the degree-M collocation matrix nearest the given complex shifts (nev per
/// shift, by Spectra's complex shift-invert Arnoldi on the structured operator), merged.
/// The status is EigenFailure if any shift's Arnoldi iteration did not converge.
struct SparseEigenResult {
    std::vector<cplx> values;
    RootStatus status = RootStatus::Converged;
    int factorizations = 0;
};

SparseEigenResult sparse_collocation_eigenvalues(const SparseDDE& dde, int degree, const std::vector<cplx>& shifts, int nev);

}  // namespace ddemap
