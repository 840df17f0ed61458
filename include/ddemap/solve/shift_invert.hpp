#pragma once
/// \file sparse.hpp
/// Large real linear DDEs x' = A0 x + sum_k A_k x(t - tau_k) with sparse matrices: the rightmost
/// eigenvalues of their Chebyshev collocation matrix A_M (see collocation.hpp) by shift-and-invert
/// Arnoldi (Spectra) on a structured operator, each refined by Newton on the DDE itself.
///
/// Structured shift-invert. For a shift sigma, (A_M - sigma I) u = b splits: with
/// B = (2/tau) D[1:,1:] - sigma I (M x M) and g = B^{-1} (2/tau) D[1:,0], the history blocks are
/// U = B^{-1} b[1:] - g u0^T, and u0 solves the n x n sparse system
///     S u0 = b0 - sum_k A_k (l_k[1:]^T B^{-1} b[1:]),   S = A0 - sigma I + sum_k c_k A_k,
/// c_k = l_k[0] - l_k[1:] . g (l_k the Lagrange weights of the node theta = -tau_k;
/// c_k ~ e^{-sigma tau_k}, so S ~ -Delta(sigma)). One sparse LU of S per shift (UMFPACK, symbolic
/// analysis done once and reused for every shift) and O(M^2 n) dense work per application: the
/// (M+1) n matrix is never formed.
///
/// Shift strategy (completeness). Every root with Re(lambda) >= alpha satisfies
/// Re(lambda) <= beta and |Im(lambda)| <= R(alpha), with (detail::RootBounds)
///     beta:  the fixed point of x = mu(A0) + || sum_k |A_k| e^{-x tau_k} ||  (mu the log-norm),
///     R(a) = ||A0|| + || sum_k |A_k| e^{-a tau_k} ||.
/// The rectangle [alpha, beta] x [0, R(alpha)] (real problems: the lower half is its mirror) is
/// covered by discs: a shift sigma whose Arnoldi run returns the nev eigenvalues of largest
/// |nu(lambda)|, nu = (1/(lambda - sigma) + 1/(lambda - conj sigma)) / 2 (Spectra's operator
/// Re((A_M - sigma I)^{-1})), has found every eigenvalue with |nu| > nu_min; that set contains
/// the disc |z - sigma| < rho with (1/rho - 1/(2 Im sigma - rho)) / 2 = nu_min (rho = 1/nu_min
/// for a real shift). Cells of the rectangle not inside a disc get a shift at their centre and
/// are split until covered. alpha is lowered until `count` eigenvalues lie right of it.

#include <string>
#include <vector>

#include <Eigen/Sparse>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/roots.hpp"

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
    /// Delta(lambda) = lambda I - A0 - sum_k A_k e^{-lambda tau_k} (sparse, complex).
    Eigen::SparseMatrix<cplx> characteristic_matrix(cplx lambda) const;
    /// Delta'(lambda) = I + sum_k tau_k A_k e^{-lambda tau_k}.
    Eigen::SparseMatrix<cplx> characteristic_derivative(cplx lambda) const;
};

/// Merges equal delays, folds delay-0 terms into A0 (a LinearDDE-like normal form).
SparseDDE normalised(const SparseDDE& dde);

/// Eigenvalues of the degree-M collocation matrix nearest the given complex shifts (nev per
/// shift, by Spectra's complex shift-invert Arnoldi on the structured operator), merged.
/// The status is EigenFailure if any shift's Arnoldi iteration did not converge.
struct SparseEigenResult {
    std::vector<cplx> values;
    RootStatus status = RootStatus::Converged;
    int factorizations = 0;
};

SparseEigenResult sparse_collocation_eigenvalues(const SparseDDE& dde, int degree, const std::vector<cplx>& shifts, int nev);

/// Options of the sparse rightmost-root solver (validate() names the field).
struct SparseRootOptions {
    int count = 10;                  ///< rightmost roots wanted (a conjugate partner may be added)
    int degree = 0;                  ///< collocation degree M; 0 = automatic from the root bound
    int max_degree = 200;
    int eigenvalues_per_shift = 32;  ///< nev of each Arnoldi run (ncv = 5 nev / 2 + 20)
    int max_shifts = 5000;           ///< give up (status EigenFailure) after this many shifts
    int arnoldi_max_restarts = 400;
    double arnoldi_tolerance = 1e-10;  ///< Spectra: |residual| <= tol |Ritz value|
    bool refine = true;              ///< Newton refinement on Delta(lambda) (off: eigenvalues only)
    int newton_max_iterations = 30;
    double newton_tolerance = 1e-14;     ///< stop when |step| <= tol max(1, |lambda|)
    double residual_tolerance = 1e-9;    ///< accept a refined root below this relative residual
    double collocation_tolerance = 1e-8; ///< |eigenvalue - root| / max(1, |lambda|) accepted
    void validate() const;
};

/// Outcome of the sparse solver (cf. Ceres' Summary).
struct SparseRootResult {
    std::vector<Root> roots;         ///< rightmost first; conjugate pairs both listed
    std::vector<cplx> eigenvalues;   ///< the collocation eigenvalue each root was refined from
    int degree = 0;                  ///< collocation degree M
    double strip_floor = 0.0;        ///< alpha: every eigenvalue with Re >= alpha was found
    double right_bound = 0.0;        ///< beta: no root has Re > beta
    double height = 0.0;             ///< R(alpha): no root with Re >= alpha has |Im| > height
    double covered_radius = 0.0;     ///< |lambda| resolved by degree M
    int shifts = 0;                  ///< Arnoldi runs (one per shift)
    int factorizations = 0;          ///< sparse LU factorisations (shifts and Newton)
    int eigenvalues_found = 0;       ///< distinct eigenvalues met on the way
    double collocation_error = 0.0;  ///< max |eigenvalue - root| / max(1, |lambda|)
    double max_residual = 0.0;       ///< max relative residual ||Delta(lambda) v|| / (||v|| scale)
    RootStatus status = RootStatus::Converged;
    std::string reason;
    double spectral_abscissa() const;
};

/// Rightmost roots of a large sparse real DDE (see the file comment for the method and the
/// completeness argument). Throws std::invalid_argument for invalid input.
SparseRootResult sparse_rightmost_roots(const SparseDDE& dde, const SparseRootOptions& options = {});

/// Which eigen-solver path `system_rightmost_roots` takes.
/// Product: rings of one-leader cars only (ring_product.hpp); analyse_mixed_ring takes it
/// automatically for such rings.
enum class SolverMethod { Automatic, Dense, Sparse, Product };
SolverMethod parse_solver_method(const std::string& name);  ///< "auto", "dense", "sparse" or "product"
std::string to_string(SolverMethod m);

/// One interface for both paths: dense collocation (all eigenvalues, the core solver) for
/// dimension <= dense_limit, otherwise the sparse solver. The result has the sparse layout.
SparseRootResult system_rightmost_roots(const SparseDDE& dde, const SparseRootOptions& options,
                                        SolverMethod method = SolverMethod::Automatic, int dense_limit = 16);

namespace detail {
/// Where the roots of a DDE can lie: every root with Re(lambda) >= a has Re(lambda) <= beta and
/// |Im(lambda)| <= R(a) (see the file comment). For Re(lambda) >= a the delayed part is bounded
/// entrywise, |sum_k A_k e^{-lambda tau_k}| <= sum_k |A_k| e^{-a tau_k}, so with ||.|| the 2-norm
/// bound sqrt(||.||_1 ||.||_inf) and mu a bound of the log-norm mu_2(A0):
///     R(a) = ||A0|| + || sum_k |A_k| e^{-a tau_k} ||,   beta: x = mu + || sum_k |A_k| e^{-x tau_k} ||
/// (tighter than summing ||A_k|| over the delays when, as in a ring, each row has few delays).
struct RootBounds {
    struct Entry {
        int row, col;
        double value;  ///< |A_k(row, col)|
        double delay;  ///< tau_k
    };
    int n = 0;
    double n0 = 0.0;              ///< ||A0||
    double mu = 0.0;              ///< >= mu_2(A0)
    std::vector<Entry> entries;   ///< every nonzero of every delayed matrix
    /// || sum_k |A_k| e^{-a tau_k} ||
    double delayed_norm(double a) const;
    /// R(a) = ||A0|| + delayed_norm(a)
    double radius(double a) const;
    /// beta: the fixed point of x = mu + delayed_norm(x)
    double right_bound() const;
    /// |lambda| + R(Re lambda): the scale of Delta(lambda) in relative residuals
    double scale(cplx lambda) const { return std::abs(lambda) + radius(lambda.real()); }
};
RootBounds root_bounds(const SparseDDE& dde);
}  // namespace detail

}  // namespace ddemap
