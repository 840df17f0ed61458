#pragma once
/// \file roots.hpp
/// Rightmost characteristic roots of a linear DDE: eigenvalues of the Chebyshev collocation
/// of the infinitesimal generator, each refined by Newton on det Delta(lambda),
///     lambda <- lambda - 1 / trace( Delta(lambda)^{-1} Delta'(lambda) ),
/// with the degree M increased until the rightmost roots are unchanged between two degrees.

#include <string>
#include <vector>

#include "ddemap/solve/eigensolver.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// Options with validation (validate() throws std::invalid_argument naming the field).
struct RootOptions {
    int count = 6;                  ///< rightmost roots wanted (a conjugate partner may be added)
    int initial_degree = 0;         ///< first collocation degree M; 0 = from the root bound
    int max_degree = 400;           ///< never exceed this M
    int newton_max_iterations = 60;
    double newton_tolerance = 4e-16;   ///< stop when |step| <= tol * max(1, |lambda|)
    double residual_tolerance = 1e-9;  ///< accept a root when its relative residual is below
    double agreement_tolerance = 1e-11;  ///< roots equal between degrees (relative to max(1,|lambda|))
    double collocation_tolerance = 1e-5; ///< |eigenvalue - refined root| <= tol * max(1,|lambda|)
    /// One degree suffices when every eigenvalue is already this close (relative) to its refined
    /// root: the discretisation error at that M is below it for these roots.
    double spectral_tolerance = 1e-10;
    /// When fewer than `count` roots are found, the result is certified complete in the strip
    /// Re(lambda) >= alpha - depth (alpha the rightmost root). 0 = automatic: 2 / tau_max.
    double depth = 0.0;
    void validate() const;
};

/// One refined characteristic root.
struct Root {
    cplx value;                 ///< the root lambda
    double residual = 0.0;      ///< sigma_min(Delta(lambda)) / (|lambda| + ||A0|| + sum ||A_k|| e^{-Re(lambda) tau_k})
    double newton_step = 0.0;   ///< size of the last Newton step (an error estimate)
    double collocation_error = 0.0;  ///< |collocation eigenvalue - refined root|
};

enum class RootStatus {
    Converged,         ///< rightmost roots certified (spectral accuracy or two degrees), disc covered
    MaxDegreeReached,  ///< the degree cap was hit before the roots settled
    EigenFailure       ///< the eigen-solver backend failed
};

std::string to_string(RootStatus s);

struct RootResult {
    std::vector<Root> roots;  ///< rightmost first (ties: larger imaginary part first)
    int degree = 0;           ///< the collocation degree M used (0 for an ODE)
    int previous_degree = 0;  ///< the degree it was checked against (0 when one degree sufficed)
    double degree_change = 0.0;  ///< max relative change of the roots between the two degrees (inf if one degree)
    double collocation_error = 0.0;  ///< max |eigenvalue - refined root| / max(1, |lambda|) over the roots
    double covered_radius = 0.0; ///< |lambda| up to which the collocation resolves e^{lambda theta}
    double strip_floor = 0.0;    ///< every root with Re >= strip_floor is in `roots` or right of them
    int dropped = 0;          ///< candidates dropped (Newton failed, spurious or duplicate)
    RootStatus status = RootStatus::Converged;
    std::string reason;       ///< why the result is trusted (or why not)
    /// max Re(lambda) over roots (-inf if none)
    double spectral_abscissa() const;
};

/// Rightmost roots of `dde`. `backend` defaults to DenseEigenSolver.
RootResult rightmost_roots(const LinearDDE& dde, const RootOptions& options = {},
                           const EigenSolverBackend* backend = nullptr);

/// Newton refinement of one root estimate. Returns false when it did not converge.
bool refine_root(const LinearDDE& dde, cplx guess, const RootOptions& options, Root& out);

/// A root within this distance of the imaginary axis is marginal, neither stable nor
/// unstable: 1e-13 max(1, |lambda|) (roots are refined to about 1e-15).
double marginal_band(cplx lambda);

namespace detail {
/// Degree needed so that Chebyshev interpolation of e^{lambda theta} on [-tau, 0] is accurate
/// to rounding for |lambda| <= radius (interpolating e^{z x} on [-1, 1], |z| = radius tau / 2,
/// converges once M exceeds about e|z|/2 + 15): M = ceil(0.7 radius tau + 15).
int degree_for_radius(double radius, double tau);
/// The inverse: the radius resolved by degree M, (M - 15) / (0.7 tau).
double radius_for_degree(int degree, double tau);
/// The first `count` roots (sorted rightmost first), plus the conjugate partner of the last one
/// when the cut would separate a pair.
std::vector<Root> cut_rightmost(const std::vector<Root>& all, int count);
}  // namespace detail

/// Relative residual sigma_min(Delta(lambda)) / scale(lambda) (see Root::residual).
double relative_residual(const LinearDDE& dde, cplx lambda);

}  // namespace ddemap
