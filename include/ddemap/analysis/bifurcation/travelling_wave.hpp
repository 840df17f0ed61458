#pragma once
/// \file travelling_wave.hpp
/// Discrete travelling waves on a ring of N identical cars (the built-in rings "ov" and "idm",
/// traffic/ring_car.hpp), continued in one parameter at a cost that does not depend on N.
///
/// A travelling wave of wave number k (1 <= k <= N - 1) and period T is an orbit of the ring on
/// which every car repeats its follower shifted in time by k T / N:
///     x_{i+1}(t) = x_i(t + k T / N),  so  x_i(t) = x(t + i k T / N)
/// (x = (h, v) of car 0; car i + 1 is car i's leader). Car 0's law then reads with its leader
/// replaced by itself, shifted ahead by a fraction kappa = k / N of the period. In the time
/// s = t / T in [0, 1] of periodic_orbit.hpp:
///     x'(s) = T [ g(x(s), x(s - tau/T), x(s + kappa), x(s + kappa - tau/T); p) + mu e_h ],
/// positions taken mod 1: the leader is a delay proportional to the period, and its composition
/// with the reaction delay tau is the position s + kappa - tau / T. The ring length is the
/// integral condition  int_0^1 h(s) ds = headway  (the mean headway L / N; it takes the place
/// of the headway that the full ring eliminates). Without it the one-car equations would have a
/// family of waves (one per mean headway); with it one more equation than unknowns, so an
/// unfolding unknown mu is added to the headway equation (mu = 0 for an exact wave: integrating
/// h' over a period gives mu = mean(v_lead - v) = 0; the discretisation leaves |mu| at the size
/// of its error, reported as max_drift). Unknowns: car 0's mesh values (periodic_mesh.hpp, the
/// collocation of periodic_orbit.hpp), T, the parameter p and mu; equations: collocation at the
/// Gauss points, the integral phase condition against the previous orbit, the length condition
/// and the pseudo-arclength condition. Newton's Jacobian is exact (dual numbers for g); since
/// kappa is a constant fraction of the period, the shift's dependence on T is exact in this time:
///     dF/dT = -(g + mu e_h) - sum_k A_k x'(s_k) tau_k / T   (the leader shift contributes 0),
///     dF/dp = -T dg/dp + sum_k A_k x'(s_k) d tau_k / dp,   dF/dmu = -T e_h,
/// and the length row's derivative in p is -1 when p is the headway (gap). The size is
/// 2 L d + 3 whatever N is.
///
/// Continuation: the step control and the special points of periodic_orbit.hpp's branches (the
/// same code): pseudo-arclength in the weighted norm (the profile, T / T_H, p / |to - from|; mu not
/// weighted) with the step halved after a failed corrector and grown by 1.5 after an easy one
/// up to orbit.max_step; folds in the parameter located by regula falsi on the tangent's
/// parameter component; with the full ring's multipliers (below) period doublings and tori
/// (OrbitCrossing: the multipliers of consecutive waves paired by distance, each crossing located
/// on |mu| - 1 with a verified bracket).
///
/// Start: the Hopf point of ring mode k on the uniform flow, i.e. of the 2 x 2 characteristic
/// matrix  Delta_k(lambda) = lambda I - A_0 - A_1 e^{-lambda tau} - z (A_2 + A_3 e^{-lambda tau}),
/// z = exp(2 pi i k / N) (the leader of a wave x e^{i omega t} is z times the car at omega T = 2 pi):
/// the 8 rightmost roots of this complex DDE at p = from (solve/roots.hpp, certified), those with
/// Im(lambda) > 0 followed by Newton on det Delta_k over 200 equal steps of p towards `to`; the
/// first sign change of Re(lambda) of one of them is located by Illinois regula falsi (a root
/// that enters from left of these 8 is not followed). A Hopf point of modes k and N - k is one pair
/// of roots: one of the two wave numbers has it at +i omega, the other at -i omega (no wave with
/// omega > 0), so one of k and N - k is the wave born there.
///
/// Long waves (K / N < 0.1; their harmonics are nearly resonant at the Hopf point, so the first
/// wave from it may not converge): when it does not, the wave of K / N = 0.1 is started from its
/// own Hopf point, the largest wave of its branch inside the range (5 % from its faces) is taken,
/// K / N is lowered to the requested value at that parameter (natural continuation in log K / N,
/// the period scaled so that T K / N is kept in the predictor, the mesh re-equidistributed after
/// every step, orbit_mesh.hpp), and the branch is continued both ways in the parameter on a mesh
/// re-equidistributed after every wave (profile weight lowered 1000 times in the arclength norm),
/// the side ending at the smaller amplitude first (reversed). The Hopf point reported is still
/// the requested mode's; the branch need not reach it. The K / N = 0.1 branch is followed for at
/// least 1000 waves so that it passes its fold when it has one: the IDM ring's (th = 1.2, tau =
/// 0.6) folds at gap 19.29, and a homotopy started short of it (gap 19.54) meets a fold in K / N
/// (the K / N = 0.086 branch folds at gap 22.30: no such wave at gap 19.54) and fails.
///
/// Resolution. Every wave's relative defect between the collocation points (the reduced
/// equations at the d + 1 representation points of every interval, where collocation does not
/// hold them; O(h^d), TravellingWaveBranch::defects) is reported. Long waves (homotopy path) keep
/// it below TravellingWaveOptions::defect_tolerance: the intervals are doubled until the wave
/// reached by the homotopy is resolved, and a wave of the branch above it is corrected again on a
/// mesh equidistributed on itself (or with every interval split once the step is small), else with
/// a shorter step (stop "unresolved" below the minimum step). Waves from their own Hopf point (a
/// fixed uniform mesh) stop as "unresolved" above unresolved_defect. On 40 intervals the
/// uncontrolled 1000-car ov wave (K = 1) had period jumps of 2e-3 and spurious folds at defects of
/// 1e-2 to 1e-1; with the control the intervals go to 80 and 160 and the periods agree with the
/// 100-interval branch at the same headway to 5e-6.
///
/// Stability. The reduced form does not give the ring's stability: perturbations of the ring
/// need not keep the wave structure (they split into N Fourier families; the one-car
/// variational problem of family j has the leader term multiplied by a factor that depends on
/// the multiplier itself, so it is not a monodromy of the reduced equations). Here the
/// multipliers are those of the full ring (make_nonlinear_ring, one headway eliminated) along the
/// wave spread to all cars, x_i(s) = x(s + i k / N), by periodic_orbit's monodromy
/// (orbit_multipliers), for N <= full_ring_floquet_limit; for larger N with sparse_floquet by
/// the matrix-free path of wave_stability.hpp (Arnoldi on the monodromy applied by sparse
/// sweeps; a verdict per wave, undecided with a reason when not certain), else no multiplier is
/// computed and the stability is not decided (stable = false, multipliers empty,
/// full_ring_stability = false). The trivial multiplier's distance from 1 then also measures how
/// far the spread profile is from a collocation solution of the full ring (it is not one exactly).

#include <limits>
#include <string>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/bifurcation/wave_stability.hpp"
#include "ddemap/core/types.hpp"

namespace ddemap {

struct TravellingWaveOptions {
    std::string model = "ov";  ///< "ov" or "idm"
    int cars = 10;             ///< N >= 2 (any size: the cost does not depend on it)
    int wave = 1;              ///< k, 1..N-1
    /// the parameter, range, mesh (degree, intervals), steps and tolerances (adapt is not used:
    /// the mesh stays uniform; floquet: compute the full ring's multipliers when N is small;
    /// progress: after every wave added, (waves so far, max_points, p), as for orbits: it may
    /// throw to stop the branch and the exception reaches the caller, no partial branch. Long
    /// waves reached by the homotopy report the branch of K / N = 0.1 and then each side of the
    /// requested branch, each counted from 1)
    PeriodicOrbitOptions orbit;
    /// the full ring's multipliers are computed for N <= this (their cost grows like N^3)
    int full_ring_floquet_limit = 10;
    /// N > full_ring_floquet_limit (and floquet on): the full ring's multipliers of every wave
    /// by the matrix-free path of wave_stability.hpp, after the branch (off by default: on long
    /// rings it costs far more than the branch; `orbits --wave` turns it on)
    bool sparse_floquet = false;
    WaveStabilityOptions stability;  ///< its Arnoldi settings
    /// after every wave of that pass: (waves done, waves of the branch, p); it may throw to stop
    BranchProgress stability_progress;
    /// K / N < 0.1: start by the homotopy in K / N even when the first wave from the Hopf point
    /// converges (to check one path against the other)
    bool force_homotopy = false;
    /// Resolution of long waves (reduced_defect, see TravellingWaveBranch::defects): on the
    /// homotopy path the number of intervals is doubled (every interval split, then the mesh
    /// equidistributed) until the wave reached by the homotopy has a relative defect of at most
    /// defect_tolerance / 2, at most max_intervals intervals (otherwise the branch is empty with
    /// stop "unresolved"); along the branch a wave above defect_tolerance is corrected again on a
    /// mesh equidistributed on itself, then with a halved step (stop "unresolved" below the
    /// minimum step). 0: off (the given intervals are kept).
    double defect_tolerance = 1e-3;
    int max_intervals = 1600;
    /// On the fixed uniform mesh (waves from their own Hopf point) the branch stops as
    /// "unresolved" (Status::NumericalIssue) at the first wave whose relative defect is above
    /// this: the polynomial misses its equations by more than this fraction of |x'| between the
    /// collocation points, the profile is not resolved (0: off).
    double unresolved_defect = 0.1;
    bool is_valid(std::string* why = nullptr) const;
};

struct TravellingWaveBranch {
    int cars = 0, wave = 0;
    /// the Hopf point of ring mode `wave` where the branch starts: x = car 0's (h, v) on the
    /// uniform flow, q the null vector of Delta_k(i omega); status not Converged when none was
    /// found in the range (then the branch is empty with status and message saying so)
    HopfPoint hopf;
    /// the orbits: profile = car 0's (h, v) on the mesh (points() x 2), min/max of h and v;
    /// multipliers: the full ring's (see the file comment) or empty
    OrbitBranch branch;
    bool full_ring_stability = false;  ///< the multipliers are the full ring's (either path)
    /// "dense" (N <= full_ring_floquet_limit, periodic_orbit's monodromy of the ring),
    /// "matrix_free" (wave_stability.hpp) or "none"
    std::string stability_method = "none";
    /// matrix_free: per wave of branch.points its result (the wave's multipliers, stable and
    /// trivial_distance are copied from it; stable only for Verdict::Stable); Converged when
    /// every wave's verdict is decided, else the status of the first undecided one with a message
    std::vector<WaveStability> stability;
    Status stability_status = Status::Converged;
    std::string stability_message;
    double max_drift = 0.0;            ///< max |mu| over the orbits (0 for an exact wave)
    /// per wave of branch.points: the relative defect of the reduced equations between the
    /// collocation points, max_c max_s |x_c'(s) - T (g_c + mu e_h)| / max_s |x_c'(s)| over the d + 1
    /// representation points of every interval (O(h^d), the resolution indicator); its maximum
    std::vector<double> defects;
    double max_defect = 0.0;
    /// long waves (K / N < 0.1 whose first wave from the Hopf point fails): the parameter at
    /// which the homotopy in K / N ran and its number of steps (NaN and 0 otherwise)
    double homotopy_par = std::numeric_limits<double>::quiet_NaN();
    int homotopy_steps = 0;
};

/// The branch of travelling waves of wave number options.wave born at the mode's Hopf point in
/// [from, to] (the first met from `from`), with the other parameters as given (the defaults of
/// make_nonlinear_ring otherwise). std::invalid_argument for invalid options (a wave number
/// outside 1..N-1, an unknown model or parameter); no Hopf point or non-convergence is a status.
TravellingWaveBranch travelling_wave_branch(const ParameterMap& parameters, const TravellingWaveOptions& options);

/// Car i's state (h_i, v_i) of the wave at time s (of the period): car 0's at s + i k / N.
Eigen::VectorXd wave_car_state(const PeriodicMesh& mesh, const PeriodicOrbit& orbit, int cars, int wave, long car, double s);

/// A wave checked on the full ring (make_nonlinear_ring: 2 N - 1 equations, the last headway
/// eliminated through the ring length), independently of the reduced equations: the ring's
/// state is rebuilt from car 0's piecewise polynomial, X(t) = (h_0..h_{N-2}, v_0..v_{N-1})(t) with
/// car i at x(t + i k T / N) (wave_car_state), and the full ring's right-hand side F is
/// evaluated on it at the sample times t_m = (m + 0.5) T / M, m = 0..M-1:
///     defect_h = max |X_j'(t_m) - F_j(X(t_m), X(t_m - tau); p)| over the headway rows j < N - 1,
///     defect_v = the same over the N speed rows (the last car's uses the eliminated headway),
/// X' the derivative of the polynomials (/ T). For a continuous wave both vanish; for a
/// collocation solution they are the defect between the collocation points, O(h^d). scale_h,
/// scale_v: max |X_j'(t_m)| over the same rows; relative = max(defect_h / scale_h, defect_v /
/// scale_v). length_error = max_m |sum_i h_i(t_m) / (N headway) - 1| (h_{N-1} of car N - 1 taken
/// from the polynomial, not from the elimination). Cost O(N M).
struct WaveRingCheck {
    double defect_h = 0.0, defect_v = 0.0, scale_h = 0.0, scale_v = 0.0, relative = 0.0, length_error = 0.0;
    int samples = 0;
};
/// The check above for the wave `orbit` of wave number `wave` on a ring of `cars` cars (2..2000,
/// as make_nonlinear_ring) of `model` with `parameters` and the branch parameter `parameter` at
/// orbit.par; the orbit's mesh is PeriodicMesh(degree, orbit.breakpoints). std::invalid_argument
/// for a ring make_nonlinear_ring refuses, samples < 1 or an orbit without profile.
WaveRingCheck check_wave_on_full_ring(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars, int wave,
                                      int degree, const PeriodicOrbit& orbit, int samples);

}  // namespace ddemap
