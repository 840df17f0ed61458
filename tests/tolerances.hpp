#pragma once
// The one table of test tolerances. Each entry says what it bounds and why that size.
namespace ddemap::test::tol {

/// Refined characteristic roots against an analytic value (Lambert W, closed forms): Newton
/// converges to rounding, |lambda| <= ~20 in these tests, so 1e-12 absolute leaves a 100x margin.
constexpr double root_abs = 1e-12;
/// Rightmost roots against the 40-digit reference data (issue requirement: 1e-10).
constexpr double reference_root = 1e-10;
/// sup |Gamma(iw)| against the reference data, relative (issue requirement: 1e-8).
constexpr double reference_sup_rel = 1e-8;
/// omega of the peak against the reference, relative: the maximum is quadratic, so omega is
/// determined only to about sqrt of the value accuracy; 1e-6 is what the refinement achieves.
constexpr double reference_omega_rel = 1e-6;
/// Same root from two algorithms in double precision (dense full ring vs Fourier modes).
constexpr double same_root = 1e-10;
/// Collocation eigenvalues from the sparse shift-invert against a dense eigen-decomposition of
/// the same matrix (issue requirement: 1e-9; both are backward stable, |lambda| <= ~3 here).
constexpr double sparse_vs_dense = 1e-9;
/// A spectrum that must change when the cars are reordered (connected cruise control): the
/// abscissas differ by far more than this in the cases tested (~1e-2).
constexpr double order_matters = 1e-4;
/// |prod Gamma_i(lambda) - 1| at a refined root of a ring of N <= 60 cars: the sum of N
/// logarithms loses about N eps |d log Gamma / d lambda| ~ 1e-13.
constexpr double product_residual = 1e-10;
/// A sweep point's spectral abscissa against the per-point computation (README claim: exact to
/// 1e-8; both certify the same rightmost root, which agrees to ~1e-14 in practice).
constexpr double sweep_vs_point = 1e-8;
/// Continued ring Hopf curves against the closed-form D-subdivision curves (README claim: 1e-8;
/// points are corrected by Newton to 1e-13 relative in the unit window).
constexpr double boundary_closed_form = 1e-8;
/// Coefficients computed two ways in double precision (series vs closed form).
constexpr double coefficient_rel = 1e-13;
/// Linearisation against central finite differences with step 1e-5 (error O(h^2) ~ 1e-10).
constexpr double finite_difference = 1e-7;

/// A Monte Carlo estimate against its exact value, in units of the estimate's own standard
/// error: |estimate - exact| <= 4.5 SE fails by chance with probability 7e-6 (normal tails), so
/// a pass is not luck, while a bias of a few standard errors (a wrong sampler) fails.
constexpr double monte_carlo_sigmas = 4.5;
/// Fraction of independent seeds whose 95 % Wilson interval must cover the exact probability:
/// nominal 0.95; with 20 seeds the chance of fewer than 16 covering is 2.6e-3 for a correct
/// interval (binomial), while an interval half as wide as it should be covers ~68 % and then
/// fails with probability 0.82.
constexpr double wilson_coverage_min = 0.8;

}  // namespace ddemap::test::tol
