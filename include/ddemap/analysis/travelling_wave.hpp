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
/// the requested mode's; the branch need not reach it.
///
/// Stability. The reduced form does not give the ring's stability: perturbations of the ring
/// need not keep the wave structure (they split into N Fourier families; the one-car
/// variational problem of family j has the leader term multiplied by a factor that depends on
/// the multiplier itself, so it is not a monodromy of the reduced equations). Here the
/// multipliers are those of the full ring (make_nonlinear_ring, one headway eliminated) along the
/// wave spread to all cars, x_i(s) = x(s + i k / N), by periodic_orbit's monodromy
/// (orbit_multipliers), for N <= full_ring_floquet_limit; for larger N no multiplier is
/// computed and the stability is not decided (stable = false, multipliers empty,
/// full_ring_stability = false). The trivial multiplier's distance from 1 then also measures how
/// far the spread profile is from a collocation solution of the full ring (it is not one exactly).

#include <limits>
#include <string>

#include "ddemap/analysis/equilibrium_branch.hpp"
#include "ddemap/analysis/periodic_orbit.hpp"
#include "ddemap/core/types.hpp"

namespace ddemap {

struct TravellingWaveOptions {
    std::string model = "ov";  ///< "ov" or "idm"
    int cars = 10;             ///< N >= 2 (any size: the cost does not depend on it)
    int wave = 1;              ///< k, 1..N-1
    /// the parameter, range, mesh (degree, intervals), steps and tolerances (adapt is not used:
    /// the mesh stays uniform; floquet: compute the full ring's multipliers when N is small)
    PeriodicOrbitOptions orbit;
    /// the full ring's multipliers are computed for N <= this (their cost grows like N^3)
    int full_ring_floquet_limit = 10;
    /// K / N < 0.1: start by the homotopy in K / N even when the first wave from the Hopf point
    /// converges (to check one path against the other)
    bool force_homotopy = false;
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
    bool full_ring_stability = false;  ///< the multipliers are the full ring's (N <= limit)
    double max_drift = 0.0;            ///< max |mu| over the orbits (0 for an exact wave)
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

}  // namespace ddemap
