#pragma once
/// \file root_bounds.hpp
/// Where the characteristic roots of x' = A0 x + sum_k A_k x(t - tau_k) can lie, and the one
/// residual definition every root solver reports.
///
/// For Re(lambda) >= a the delayed part is bounded entrywise,
///     |sum_k A_k e^{-lambda tau_k}| <= sum_k |A_k| e^{-a tau_k},
/// and also termwise by sum_k ||A_k|| e^{-a tau_k}. From Delta(lambda) v = 0 every root with
/// Re(lambda) >= a satisfies
///     |lambda| <= R(a) = ||A0|| + min( || sum_k |A_k| e^{-a tau_k} ||, sum_k ||A_k|| e^{-a tau_k} ),
///     Re(lambda) <= beta, the fixed point of x = mu + (the same delayed norm at x),
/// with mu >= mu_2(A0) (the log-norm), and (numerical range: lambda = v^H A0 v + v^H (sum_k A_k
/// e^{-lambda tau_k}) v for the unit null vector v, and |Im v^H A0 v| = |v^H K v|)
///     |Im(lambda)| <= H(a) = min( R(a), ||K|| + (the same delayed norm at a) ),  K = (A0 - A0^H) / 2i,
/// which for a symmetric A0 (a discretised diffusion) does not grow with ||A0||. ||.|| is the 2-norm (dense storage) or its bound
/// sqrt(||.||_1 ||.||_inf) (sparse storage); the entrywise form is the tighter one when, as in
/// a ring, each row has few delays, the termwise one for a few dense matrices.
///
/// The residual of an approximate root lambda with vector v is the relative backward error
///     ||Delta(lambda) v|| / (||v|| (|lambda| + R(Re lambda))),
/// and without a vector (dense storage) its minimum over v, sigma_min(Delta(lambda)) / scale.

#include <algorithm>
#include <cmath>
#include <vector>

#include "ddemap/core/types.hpp"

namespace ddemap {

class LinearDDE;

/// ||A||_2 <= sqrt(||A||_1 ||A||_inf): the 2-norm bound of sparse storage (0 for an empty
/// matrix), for any Eigen sparse matrix, real or complex.
template <class Sparse>
double norm2_bound(const Sparse& a) {
    Eigen::VectorXd rows = Eigen::VectorXd::Zero(a.rows()), cols = Eigen::VectorXd::Zero(a.cols());
    for (Eigen::Index k = 0; k < a.outerSize(); ++k)
        for (typename Sparse::InnerIterator it(a, k); it; ++it) {
            rows(it.row()) += std::abs(it.value());
            cols(it.col()) += std::abs(it.value());
        }
    const double r = rows.size() ? rows.maxCoeff() : 0.0, c = cols.size() ? cols.maxCoeff() : 0.0;
    return std::sqrt(r * c);
}

/// The bounds above for one DDE (computed once, when the LinearDDE is built).
struct RootBounds {
    struct Entry {
        int row, col;
        double value;  ///< |A_k(row, col)|
        double delay;  ///< tau_k
    };
    struct Term {
        double norm;   ///< ||A_k|| (or its bound)
        double delay;  ///< tau_k
    };
    int n = 0;
    double n0 = 0.0;              ///< ||A0|| (or its bound)
    double mu = 0.0;              ///< >= mu_2(A0)
    double skew = 0.0;            ///< >= ||(A0 - A0^H) / 2i|| (0 for a symmetric A0)
    std::vector<Entry> entries;   ///< every nonzero of every delayed matrix
    std::vector<Term> terms;      ///< one per delayed matrix
    /// min( || sum_k |A_k| e^{-a tau_k} ||, sum_k ||A_k|| e^{-a tau_k} )
    double delayed_norm(double a) const;
    /// R(a) = ||A0|| + delayed_norm(a)
    double radius(double a) const { return n0 + delayed_norm(a); }
    /// H(a) = min(R(a), skew + delayed_norm(a)): no root with Re >= a has |Im| > H(a)
    double height(double a) const { return std::min(n0, skew) + delayed_norm(a); }
    /// True when no root z has Re z >= x and |Im z| >= y: a root's distance to the numerical
    /// range W(A0), which lies in (-inf, mu] x [-skew, skew], is at most N(Re z) <= N(x), so none
    /// lies where hypot(max(0, x - mu), max(0, y - skew)) > N(x).
    bool excludes(double x, double y) const;
    /// beta: the fixed point of x = mu + delayed_norm(x)
    double right_bound() const;
    /// |lambda| + R(Re lambda): the scale of Delta(lambda) in relative residuals
    double scale(cplx lambda) const { return std::abs(lambda) + radius(lambda.real()); }
};

/// The relative backward error ||Delta(lambda) v|| / (||v|| (|lambda| + R(Re lambda))) of an
/// approximate root lambda with approximate null vector v (either storage); infinity for v = 0.
double relative_residual(const LinearDDE& dde, cplx lambda, const VectorXc& v);

/// The same minimised over v: sigma_min(Delta(lambda)) / (|lambda| + R(Re lambda)), i.e. v the
/// smallest right singular vector (dense: an SVD of the n x n matrix; sparse storage is made
/// dense, so only for small systems).
double relative_residual(const LinearDDE& dde, cplx lambda);

}  // namespace ddemap
