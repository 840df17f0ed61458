#pragma once
/// \file wave_stability.hpp
/// Floquet stability of a discrete travelling wave (analysis/travelling_wave.hpp) on a long ring:
/// the full ring's variational problem along the wave spread to all N cars, solved matrix-free.
///
/// The ring (traffic/ring_car.hpp, all N headways kept, car i + 1 the leader of car i, cyclic)
/// linearised along x_i(s) = x(s + i k / N) (wave_car_state; the last headway taken as
/// N headway - sum_{i < N-1} h_i as make_nonlinear_ring eliminates it, so that the coefficients
/// are those of the dense path) reads in s = t / T in [0, 1]
///     y_i'(s) = T [ A_0 y_i(s) + A_1 y_i(s - tau/T) + A_2 y_{i+1}(s) + A_3 y_{i+1}(s - tau/T) ],
/// the blocks A_k the one-car Jacobians (dual numbers) at car i's arguments. It is collocated as
/// periodic_orbit.hpp does (the wave's mesh, degree d, Gauss points, the history window
/// [-tau/T, 0] of nh mesh points): unknowns the 2 N values at the points of one period, so that
/// the collocation matrix is block lower triangular by mesh intervals, and each diagonal block
/// (2 N d unknowns) is sparse: car i couples only to itself and its leader (a block-cyclic
/// bidiagonal matrix). The monodromy matrix M (size H = 2 N nh) is applied to a window y by one
/// forward sweep over the L intervals: a sparse product with the known values and one solve with
/// the interval's diagonal block (Eigen SparseLU, COLAMD, factorised once per wave). Its memory
/// and cost grow like N L d (no N^2 or N^3 term).
///
/// Conserved length. With all N headways, d/dt sum_i h_i = 0 exactly also for the collocation
/// (the derivative of a degree d - 1 polynomial vanishing at d Gauss points), so the functional
/// e(y) = sum_i h_i at s = 0 is a left eigenvector of M for the multiplier 1 and its kernel is
/// invariant: M restricted to it is the ring of fixed length that make_nonlinear_ring builds by
/// eliminating a headway (the same nonzero multipliers; the window values of sum h before s = 0
/// only add zero multipliers). The operator used is Q M Q with Q y = y - u e(y), u = 1 / N on
/// the headways at s = 0 (e(u) = 1): the length multiplier is moved to 0.
///
/// Eigenvalues: the largest in modulus by restarted Arnoldi (Spectra GenEigsSolver, tolerance
/// arnoldi_tolerance, a fixed start vector), nev = min_multipliers first, doubled up to
/// max_multipliers until the smallest found lies inside the circle by more than the error
/// estimate (then every multiplier not found is inside too); windows of at most dense_limit
/// values: all eigenvalues of M built column by column (dense QR). The trivial multiplier is the
/// one whose eigenvector is closest in angle to x' (the wave's derivative on the window; it is
/// exactly the eigenvector of 1 for a continuous wave), not the one nearest 1 (on long rings
/// many nontrivial multipliers lie near 1). Each nontrivial multiplier mu near or outside the
/// circle has its Ritz residual r = |M v - mu v| / |v| checked (below 1e-6 |M| else undecided).
///
/// Resolution: x' is the eigenvector of 1 of the continuous problem, so |M x' - x'| / |x'| (the
/// xdot_residual) measures how well the ring's mesh resolves the wave spread to all cars; above
/// resolution_tolerance nothing is decided. A wave on a non-uniform mesh (the long waves of the
/// homotopy, equidistributed on car 0 only) is first interpolated onto a uniform mesh.
/// Verdict (honest by construction): error = max(|mu_trivial - 1| (the discretisation's
/// accuracy, see periodic_orbit.hpp), xdot_residual) + the largest Ritz residual r checked;
///     Unstable  when a nontrivial |mu| > 1 + error (one converged, checked Ritz pair suffices,
///               also when Arnoldi stopped before all nev converged),
///     Stable    when Arnoldi converged, the trivial eigenvector was recognised (|cos| >= 0.99),
///               every nontrivial |mu| found is < 1 - error and so is the smallest found (or all
///               were found),
///     Undecided otherwise (status not Converged and a message saying why: Arnoldi did not
///               converge, a multiplier within the error of the circle, more than
///               max_multipliers multipliers outside the radius 1 - error, a singular block).

#include <limits>
#include <string>
#include <vector>

#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"

namespace ddemap {

struct WaveStabilityOptions {
    int min_multipliers = 16;    ///< nev of the first Arnoldi run (>= 1)
    int max_multipliers = 128;   ///< nev is doubled up to this (>= min_multipliers)
    double arnoldi_tolerance = 1e-10;  ///< Spectra's relative tolerance of the Ritz values (> 0)
    int max_restarts = 50;       ///< Spectra's maxit (restarts)
    /// windows (monodromy matrices) of at most this many values: all multipliers, dense QR of M
    /// applied to the columns of the identity (0: always Arnoldi)
    int dense_limit = 200;
    /// a wave on a non-uniform mesh (equidistributed on car 0, so it does not resolve the other
    /// cars) is interpolated onto a uniform mesh of max(its intervals, this) intervals
    int uniform_intervals = 160;
    /// resolution check: |M x' - x'| / |x'| (x' the spread wave's derivative on the window, the
    /// eigenvector of the trivial multiplier of the continuous problem) at most this, else the
    /// wave is not resolved on the ring's mesh and nothing is decided (Status::MaxDegreeReached)
    double resolution_tolerance = 0.05;
    bool is_valid(std::string* why = nullptr) const;
};

struct WaveStability {
    /// Converged when the verdict is Stable or Unstable; otherwise undecided and why in message
    Status status = Status::NumericalIssue;
    Verdict verdict = Verdict::Undecided;
    std::string message;
    std::string method;
    /// found multipliers by decreasing modulus, the trivial one included (the length one is not)
    std::vector<cplx> multipliers;
    double trivial_distance = std::numeric_limits<double>::quiet_NaN();  ///< |mu_trivial - 1|
    double trivial_alignment = 0.0;  ///< |cos| of the angle between its eigenvector and x'
    double max_nontrivial = std::numeric_limits<double>::quiet_NaN();    ///< max |mu| of the others found
    double max_residual = 0.0;       ///< the largest Ritz residual checked (relative to |M|)
    double error = std::numeric_limits<double>::quiet_NaN();  ///< trivial_distance + max_residual
    double xdot_residual = std::numeric_limits<double>::quiet_NaN();  ///< |M x' - x'| / |x'| (resolution check)
    bool complete = false;           ///< every multiplier of modulus > 1 - error was found
    int window = 0;                  ///< H, the size of the monodromy matrix
    int applications = 0;            ///< monodromy applications (sweeps)
    double seconds = 0.0;            ///< CPU time
};

/// The stability of the travelling wave `orbit` (car 0's profile on PeriodicMesh(degree,
/// orbit.breakpoints), its period and orbit.par the value of `parameter`) of wave number `wave`
/// on the ring of `cars` cars of `model` with `parameters` (see the file comment). Cars from 2 to
/// 2000 (as make_nonlinear_ring). std::invalid_argument for invalid options, an unknown model or
/// parameter, a wave number outside 1..N-1 or an orbit without a profile of 2 columns;
/// non-convergence and undecided verdicts are a status.
WaveStability wave_ring_stability(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars, int wave,
                                  int degree, const PeriodicOrbit& orbit, const WaveStabilityOptions& options = {});

}  // namespace ddemap
