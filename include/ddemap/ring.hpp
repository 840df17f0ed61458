#pragma once
/// \file ring.hpp
/// A ring road of N identical cars (car 1 follows car N). Perturbations decouple into Fourier
/// modes m = 0..N-1 with zeta_m = exp(-2 pi i m / N); mode m is the 2-dimensional complex DDE
///     s' = (zeta - 1) v,   v' = gap*s + own*v + zeta lead*v,
/// with characteristic function f_m(lambda) = lambda^2 - lambda own + gap - zeta (gap + lambda lead)
/// (OVRV: lambda^2 + (k1 th + k2) lambda + k1 e^{-lambda tau} - zeta e^{-lambda tau} (k1 + k2 lambda)).
/// Modes m and N-m have conjugate roots and are computed once. Mode 0 factors as
/// lambda (lambda - own - lead): its root 0 (the ring-length invariance) is reported as the
/// trivial root and left out of every verdict; the rest of mode 0 is the scalar DDE
/// v' = (own + lead) * v. N = infinity: zeta = e^{-i theta} for every wave number theta.

#include <string>
#include <vector>

#include "ddemap/linear_dde.hpp"
#include "ddemap/model.hpp"
#include "ddemap/roots.hpp"

namespace ddemap {

/// zeta_m = exp(-2 pi i m / N), exact at the quarter turns (1, -i, -1, i) so that the real modes
/// m = 0 and m = N/2 have real coefficients.
cplx ring_zeta(int m, int cars);

/// Mode DDE for a given zeta (|zeta| = 1).
LinearDDE ring_mode_dde(const Linearisation& lin, cplx zeta);
/// Mode 0 with the trivial factor lambda removed: v' = (own + lead) * v.
LinearDDE ring_mode0_dde(const Linearisation& lin);
/// The whole 2N-dimensional ring, state (s_1, v_1, ..., s_N, v_N), assembled directly from one
/// car's Linearisation; for the car's law at its equilibrium it equals
/// linearise(RingSystem(model, N), equilibrium) entrywise (traffic/ring_system.hpp, tests).
LinearDDE full_ring_dde(const Linearisation& lin, int cars);


struct RingOptions {
    RootOptions roots;      ///< per-mode options; roots.count is the number of roots reported
    int theta_grid = 64;    ///< N = infinity: uniform wave numbers in (0, pi] before refinement
    void validate() const;
};

struct RingRoot {
    Root root;
    int mode = 0;         ///< m of zeta = exp(-2 pi i m / N); -1 for N = infinity
    double theta = 0.0;   ///< wave number 2 pi m / N (N = infinity: the theta of this root)
};

struct RingResult {
    int cars = 0;                    ///< N; 0 stands for infinity
    std::vector<RingRoot> roots;     ///< the rightmost roots over all modes, rightmost first
    double spectral_abscissa = 0.0;  ///< max Re over all roots, trivial zero excluded
    int abscissa_mode = 0;           ///< mode where it is reached (-1 for N = infinity)
    double abscissa_theta = 0.0;     ///< its wave number
    bool abscissa_is_limit = false;  ///< N = infinity: the sup 0 is only approached as theta -> 0
    int unstable_roots = 0;          ///< roots with Re > marginal band, all modes (-1 for N = infinity)
    int marginal_roots = 0;          ///< roots within the marginal band of the axis
    bool stable = false;             ///< every root (trivial one excluded) has Re < -marginal band
    bool trivial_branch_stable = false;  ///< N = infinity: the branch through the trivial root bends left
    int degree = 0;                  ///< the largest collocation degree used over the modes
    int modes_solved = 0;            ///< mode (or wave-number) problems solved
    RootStatus status = RootStatus::Converged;  ///< worst status over the modes
    std::string reason;              ///< how the degree was chosen and trusted
};

/// Rightmost roots and the stability verdict of the ring (cars >= 2, or 0 for infinity).
RingResult analyse_ring(const Linearisation& lin, int cars, const RingOptions& options = {});

}  // namespace ddemap
