#pragma once
/// \file roots.hpp
/// Rightmost characteristic roots of a linear DDE: ONE facade over registered backends.
///
///     RootResult r = rightmost_roots(problem, options);   // options.method = "auto" by default
///
/// Backends (each in its own file, registered in src/solve/roots.cpp):
///  - "dense": all eigenvalues of the Chebyshev collocation of the generator (docs/mathematics.md section 5), each
///    refined by Newton on det Delta, lambda <- lambda - 1 / trace(Delta^{-1} Delta'), with the
///    degree M increased until the rightmost roots are unchanged between two degrees (or equal
///    the eigenvalues to spectral accuracy). Any coefficients, ODEs included.
///  - "shift_invert": the rightmost eigenvalues of the collocation matrix by shift-and-invert
///    Arnoldi on a structured operator, every eigenvalue of a rectangle [alpha, beta] x
///    [-H(alpha), H(alpha)] found (discs of completeness), each refined by Newton on the DDE.
///    Large real systems with delays (shift_invert.hpp).
///  - "contour": the argument principle on a scalar characteristic function D = det Delta
///    (problem/characteristic_function.hpp): all zeros of the rectangle counted and located.
///
/// Dispatch of "auto": contour when the problem has a characteristic function and no
/// collocation degree is asked (degree = 0); otherwise dense for at most `dense_limit` states,
/// complex coefficients or an ODE; otherwise shift_invert. A forced method that does not apply
/// throws std::invalid_argument saying why.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/newton.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/problem/characteristic_function.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// Options of the dense backend.
struct DenseRootOptions {
    int max_degree = 400;                ///< never exceed this collocation degree M
    /// The degree grows only while the collocation matrix keeps at most this many rows, (M + 1) n
    /// (or those of the first degree, which is always computed: the given one, or an automatic
    /// one of at most this size unless M = 8 is larger). The dense eigen-solver's time grows
    /// like their cube (Eigen's real solver, one core: 2 s at 1,000 rows, 19 s at 2,000, about a
    /// minute at 3,000) and its memory like their square. The largest degree within the cap is
    /// tried; if its roots do not settle either, the run stops undecided (BudgetExhausted)
    /// instead of running for an hour (24 states and 120 roots climbed to M = 400, 9,624 rows,
    /// before this cap).
    int max_rows = 3000;
    double agreement_tolerance = 1e-11;  ///< roots equal between degrees (relative to max(1,|lambda|))
    double collocation_tolerance = 1e-5; ///< |eigenvalue - refined root| <= tol * max(1,|lambda|)
    /// One degree suffices when every eigenvalue is already this close (relative) to its refined
    /// root: the discretisation error at that M is below it for these roots.
    double spectral_tolerance = 1e-10;
    /// When fewer than `count` roots are found, the result is certified complete in the strip
    /// Re(lambda) >= alpha - depth (alpha the rightmost root). 0 = automatic: 2 / tau_max.
    double depth = 0.0;
    /// Newton on det Delta: stop when |step| <= step_tolerance max(1, |lambda|).
    NewtonOptions newton{60, 4e-16};
};

/// Options of the shift-invert backend.
struct ShiftInvertRootOptions {
    int max_degree = 200;
    int eigenvalues_per_shift = 32;    ///< nev of each Arnoldi run (ncv = 5 nev / 2 + 20)
    int max_shifts = 5000;             ///< give up (BudgetExhausted) after this many shifts
    /// "compact" (default): the Krylov basis stored as one n x r matrix and small coefficients
    /// (shift_invert.cpp CompactKrylov), Krylov-Schur restarted; "spectra": Spectra's
    /// restarted Arnoldi on the full (M+1) n vectors (the reference, slow for large n).
    std::string arnoldi = "compact";
    int compact_max_steps = 200;       ///< compact: basis vectors at most (without restarts: Arnoldi steps per shift at most)
    /// compact: Krylov-Schur restarts per shift at most (each keeps the half of the basis with the
    /// largest |Ritz values| and adds compact_max_steps / 2 steps); 0 = no restart (the basis
    /// grows to compact_max_steps and the run stops there; the default: on long rings written out
    /// the restarted runs measured slower, BENCHMARKS.md)
    int compact_restarts = 0;
    int arnoldi_max_restarts = 400;    ///< spectra: restarts per shift at most
    double arnoldi_tolerance = 1e-10;  ///< Spectra: |residual| <= tol |Ritz value|
    bool refine = true;                ///< Newton refinement on Delta(lambda) (off: eigenvalues only)
    double collocation_tolerance = 1e-8; ///< |eigenvalue - root| / max(1, |lambda|) accepted
    NewtonOptions newton{30, 1e-14};
    /// For estimate_root_work only: the shifts the search is expected to take; 0 = 6 (a system
    /// whose rightmost roots are few and apart: 3 to 5 shifts measured on random sparse systems).
    /// A ring sets 1.2 sqrt(n): its roots crowd the imaginary axis as it grows (measured).
    double expected_shifts = 0.0;
};

/// Options of the contour backend.
struct ContourRootOptions {
    double max_arg_step = 0.5;          ///< radians per step along a contour
    int max_cells = 200000;             ///< give up (BudgetExhausted) after this many cell counts
    double max_type_evaluations = 2e9;  ///< or after this many evaluations (times evaluation_cost)
    NewtonOptions newton{60, 1e-14};    ///< Newton on D; a root is accepted at |step| <= 1e-8 max(1,|lambda|)
};

/// The predicted cost of rightmost_roots(problem, options), computed before it runs so that a
/// caller can refuse work that would take too long (the CLI's size guard). Cheap: at most the symbolic
/// analysis of one sparse LU and one factorisation that the analysis promises short.
///  - dense: the eigenvalues of the first two collocation degrees, c r^3 seconds each for r =
///    (M+1) n rows (c = 2e-9 real, 8e-9 complex; Eigen's solver on one core, measured), memory
///    3 r^2 scalars;
///  - shift_invert: shift_invert.expected_shifts x (4 sparse LU factorisations + 100 solves + 30
///    Arnoldi steps); the LU's flops and nonzeros from one factorisation of Delta at the right
///    bound of the roots when UMFPACK's symbolic analysis (an upper bound, up to 30 times the
///    true flops) promises it in under 20 s with at most 2e6 nonzeros, else a third of that bound (the ratio on random
///    systems, the worst for fill); LUs at 4.5e9 flops per
///    second, the rest at 1e9; memory: two LUs, the compact Krylov basis and the (M+1) n blocks;
///  - contour: about 100 rectangle counts and 7e5 evaluations of D for 7 roots (more for more),
///    0.3 us per evaluation and unit of evaluation_cost (measured on rings; independent of N).
/// An estimate, not a bound: BENCHMARKS.md compares it with measured runs.
struct RootWorkEstimate {
    std::string method;      ///< the backend that would run (choose_root_method)
    double seconds = 0.0;    ///< predicted run time on one core
    double bytes = 0.0;      ///< predicted peak memory
    double units = 0.0;      ///< predicted units of work: degrees (dense), shifts (shift_invert), counts (contour)
    std::string basis;       ///< how the prediction was made, one clause ("about 170 shifts of 0.35 s each")
};

/// The options of rightmost_roots: what is asked (shared) and how each backend works.
struct RootOptions {
    std::string method = "auto";       ///< "auto", "dense", "shift_invert" or "contour"
    int count = 6;                     ///< rightmost roots wanted (a conjugate partner may be added)
    int degree = 0;                    ///< collocation degree M: 0 = automatic (dense: the first degree)
    double residual_tolerance = 1e-9;  ///< accept a root when its relative residual is below
    int dense_limit = 16;              ///< auto: dense up to this many states
    DenseRootOptions dense;
    ShiftInvertRootOptions shift_invert;
    ContourRootOptions contour;
    /// Called on the caller's thread after every unit of work: (units done, the budget of units,
    /// the current strip floor or shift's real part). dense: after each collocation degree,
    /// (M, max_degree, sigma); within a degree whose eigenvalue problem is complex with
    /// (M+1) n >= 200 states also between its stages (collocation_eigenvalues), the last call
    /// repeated (the previous degree and its sigma; 0 and NaN within the first degree) so that
    /// Cancelled stops it there (a real one is not interrupted); shift_invert:
    /// before each Arnoldi shift, (shifts done, max_shifts, Re sigma), repeated after each of its
    /// Arnoldi steps and before each resolvent test (Re of its centre); contour: after each
    /// rectangle count, (counts done, max_cells, its left edge). May be empty. Throwing ddemap::Cancelled
    /// (core/execution.hpp) stops the work: rightmost_roots then returns Status::Cancelled.
    BranchProgress progress;
    /// Called by rightmost_roots with estimate_root_work's prediction before any work starts,
    /// when set: it may throw (a size guard refusing the work; the exception leaves
    /// rightmost_roots) or announce the estimate. May be empty (then nothing is estimated).
    std::function<void(const RootWorkEstimate&)> before;
    /// True when the options are usable; otherwise `why` (if given) names the field, e.g.
    /// "count = 0: expected an integer >= 1", "dense.max_degree: ...".
    bool is_valid(std::string* why = nullptr) const;
    /// Throws std::invalid_argument with the is_valid message.
    void validate() const;
};

/// The problem: a linear DDE and, when det Delta has a factored scalar form, that function.
struct RootProblem {
    LinearDDE dde;
    std::shared_ptr<const CharacteristicFunction> characteristic;  ///< may be null
};

/// One refined characteristic root.
struct Root {
    cplx value;                 ///< the root lambda
    double residual = 0.0;      ///< relative backward error (root_bounds.hpp)
    double newton_step = 0.0;   ///< size of the last Newton step (an error estimate)
    double collocation_error = 0.0;  ///< |eigenvalue - refined root| (0 for the contour backend)
    cplx eigenvalue;            ///< the estimate it was refined from (a collocation eigenvalue; contour: the root)
    /// dense backend: how many roots were found at this value (within 1e-7 relative): 2 for a
    /// double root, which is located only to about sqrt(eps); listed once
    int multiplicity = 1;
};

/// What rightmost_roots did (cf. Ceres' Summary).
struct RootResult {
    std::vector<Root> roots;  ///< rightmost first (ties: larger imaginary part first)
    Status status = Status::Converged;
    std::string message;      ///< why the result is trusted (or why not)
    std::string method_given; ///< the method asked for ("auto", ...)
    std::string method_used;  ///< the backend that ran ("dense", "shift_invert", "contour")

    // the certificate
    int degree = 0;              ///< collocation degree M (0 for an ODE or the contour backend)
    int previous_degree = 0;     ///< dense: the degree it was checked against (0 when one degree sufficed)
    double degree_change = 0.0;  ///< dense: max relative change of the roots between the two degrees
    double collocation_error = 0.0;  ///< max |eigenvalue - refined root| / max(1, |lambda|)
    double covered_radius = 0.0; ///< |lambda| up to which the collocation resolves e^{lambda theta}
    double strip_floor = 0.0;    ///< alpha: every root with Re >= alpha is in `roots` or right of them
    double right_bound = 0.0;    ///< beta: no root has Re > beta (shift_invert, contour)
    double height = 0.0;         ///< no root with Re >= alpha has |Im| > height (shift_invert: H(alpha), contour: R(alpha); root_bounds.hpp)
    int eigenvalues_found = 0;   ///< shift_invert: distinct eigenvalues met; contour: zeros counted in the rectangle
    double max_residual = 0.0;   ///< max residual over the roots
    int dropped = 0;             ///< dense: candidates dropped (Newton failed, spurious or duplicate)

    // counters
    int shifts = 0;              ///< Arnoldi runs
    int arnoldi_steps = 0;       ///< shift_invert (compact): operator applications over all runs
    int arnoldi_restarts = 0;    ///< shift_invert (compact): Krylov-Schur restarts over all runs
    int factorizations = 0;      ///< sparse LU factorisations (shifts and Newton)
    long evaluations = 0;        ///< contour: evaluations of D along contours
    int contour_counts = 0;      ///< contour: rectangles counted
    int newton_iterations = 0;   ///< Newton steps over all refinements

    /// max Re(lambda) over roots (-inf if none)
    double spectral_abscissa() const;
};

/// Rightmost roots of `problem` by the backend options.method names (see the file comment).
/// Throws std::invalid_argument for invalid options or a forced method that does not apply.
/// When options.progress throws ddemap::Cancelled: a result with Status::Cancelled, no roots
/// and a message saying after how many units of work it stopped.
RootResult rightmost_roots(const RootProblem& problem, const RootOptions& options = {});
/// The same for a problem without a characteristic function.
RootResult rightmost_roots(const LinearDDE& dde, const RootOptions& options = {});

/// The backend "auto" would choose for this problem (or the forced one, checked); throws
/// std::invalid_argument when options.method does not apply to the problem.
std::string choose_root_method(const RootProblem& problem, const RootOptions& options);

/// The predicted cost of rightmost_roots(problem, options) (RootWorkEstimate); throws
/// std::invalid_argument as choose_root_method does.
RootWorkEstimate estimate_root_work(const RootProblem& problem, const RootOptions& options);

/// The registered backend names ("dense", "shift_invert", "contour").
std::vector<std::string> root_methods();

/// A root within this distance of the imaginary axis is marginal, neither stable nor
/// unstable: 1e-13 max(1, |lambda|) (roots are refined to about 1e-15).
double marginal_band(cplx lambda);

/// Degree needed so that Chebyshev interpolation of e^{lambda theta} on [-tau, 0] is accurate
/// to rounding for |lambda| <= radius (interpolating e^{z x} on [-1, 1], |z| = radius tau / 2,
/// converges once M exceeds about e|z|/2 + 15): M = ceil(0.7 radius tau + 15).
int degree_for_radius(double radius, double tau);
/// The inverse: the radius resolved by degree M, (M - 15) / (0.7 tau).
double radius_for_degree(int degree, double tau);
/// The first `count` roots (sorted rightmost first), plus the conjugate partner of the last one
/// when the cut would separate a pair.
std::vector<Root> cut_rightmost(const std::vector<Root>& all, int count);
/// All eigenvalues of the degree-M dense collocation matrix (real arithmetic for a real DDE);
/// false when the QR algorithm failed. (The dense backend's eigen-solver, also used for the
/// cheap guesses of the sweep's certified roots.) A complex matrix of 200 rows or more is done
/// in stages (Householder reduction to Hessenberg form, then chunks of QR steps) and `check`
/// (may be empty) is called between them, every 16 columns and every 32 steps: it may throw
/// (ddemap::Cancelled) to stop a long eigenvalue problem. A real matrix is one piece.
bool collocation_eigenvalues(const LinearDDE& dde, int degree, std::vector<cplx>& out, const std::function<void()>& check = {});
/// Rightmost first, ties: larger imaginary part first.
bool rightmost_first(const Root& a, const Root& b);

}  // namespace ddemap
