#pragma once
/// \file shift_invert.hpp
/// The shift_invert backend of rightmost_roots (roots.hpp, implemented in shift_invert.cpp):
/// large real linear DDEs x' = A0 x + sum_k A_k x(t - tau_k) with sparse matrices. The rightmost
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
/// Re(lambda) <= beta and |Im(lambda)| <= H(alpha), with (RootBounds, problem/root_bounds.hpp)
///     beta:  the fixed point of x = mu(A0) + N(x)  (mu the log-norm),
///     H(a) = min(||A0||, ||(A0 - A0^T) / 2||) + N(a),   N(a) = min(|| sum_k |A_k| e^{-a tau_k} ||, sum_k ||A_k|| e^{-a tau_k})
/// (the numerical range of A0: a symmetric A0, a discretised diffusion, adds nothing to H however
/// large its norm). The rectangle [alpha, beta] x [0, H(alpha)] (real problems: the lower half is its mirror) is
/// covered by discs: a shift sigma whose Arnoldi run returns the nev eigenvalues of largest
/// |nu(lambda)|, nu = (1/(lambda - sigma) + 1/(lambda - conj sigma)) / 2 (Spectra's operator
/// Re((A_M - sigma I)^{-1})), has found every eigenvalue with |nu| > nu_min; that set contains
/// the disc |z - sigma| < rho with (1/rho - 1/(2 Im sigma - rho)) / 2 = nu_min (rho = 1/nu_min
/// for a real shift). Cells of the rectangle not inside the union of the discs are shrunk to
/// the part left, get a shift (or a resolvent test) at their centre and are split until
/// covered. alpha is lowered until `count` eigenvalues lie right of it.

#include <string>
#include <vector>

#include "ddemap/core/status.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// Eigenvalues of the degree-M collocation matrix nearest the given complex shifts (nev per
/// shift, by shift-invert Arnoldi on the structured operator), merged.
/// The status is NumericalIssue if any shift's Arnoldi iteration did not converge.
struct SparseEigenResult {
    std::vector<cplx> values;
    Status status = Status::Converged;
    int factorizations = 0;
    int restarts = 0;  ///< compact: Krylov-Schur restarts over all shifts
};

/// How each shift's Arnoldi run is made: "spectra" (Spectra's restarted Arnoldi on the full
/// (M+1) n vectors) or "compact" (the Krylov basis of rightmost_roots' shift_invert backend: one
/// n x r matrix and small coefficients, `basis` vectors at most, up to `restarts` Krylov-Schur
/// restarts keeping half of them; the nev values of largest |1 / (lambda - sigma)| converged to
/// |residual| <= tolerance |theta|).
struct SparseEigenOptions {
    std::string arnoldi = "spectra";
    int basis = 200;
    int restarts = 0;
    double tolerance = 1e-12;
};

/// For a real DDE with at least one delay (sparse storage, or dense storage made sparse).
SparseEigenResult sparse_collocation_eigenvalues(const LinearDDE& dde, int degree, const std::vector<cplx>& shifts, int nev,
                                                 const SparseEigenOptions& options = {});

/// The resolvent test of rightmost_roots' shift_invert covering: a radius r such that Delta has
/// no root in the disc |lambda - z| < r right of x0 (take x0 <= Re z - r for the whole disc),
/// the larger of two bounds (s = sigma_min(Delta(z)), E_k = e^{-z tau_k}):
///     r1 = max( s / L, 2 s / (L1 + sqrt(L1^2 + 2 M2 s)) ),
///         L = 1 + sum_k tau_k ||A_k|| e^{-x0 tau_k},  L1 >= ||Delta'(z)||,  M2 = sum_k tau_k^2 ||A_k|| e^{-x0 tau_k},
///     r2 = the largest r with  r a + sum_k |E_k| (e^{r tau_k} - 1 - r tau_k) ||A_k|| / s <= 1,
///         a = ||Delta(z)^{-1} Delta'(z)||  (valid in the whole disc, whatever x0),
/// s and a from Lanczos on Delta^{-H} Delta^{-1} and Delta'^H Delta^{-H} Delta^{-1} Delta' (one
/// sparse LU) settled to 1e-4, s taken 25% smaller and a 25% larger: estimates, not proven
/// bounds. 0 when Delta(z) is singular to working precision or the estimate of s did not
/// settle (r1 alone when that of a did not). A real DDE with at least one delay.
double root_free_radius(const LinearDDE& dde, cplx z, double x0);

}  // namespace ddemap
