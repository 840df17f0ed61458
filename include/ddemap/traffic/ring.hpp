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

#include <vector>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/traffic/model.hpp"

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


/// Characteristic function of ring mode zeta as a quasi-polynomial:
///     f(lambda) = lambda^2 - lambda own + gap - zeta (gap + lambda lead) - sum_j zeta^{j+2} lambda further_j.
QuasiPolynomial ring_mode_characteristic(const Linearisation& lin, cplx zeta);
/// Mode 0 without the trivial root: lambda - own - lead - sum_j further_j.
QuasiPolynomial ring_mode0_characteristic(const Linearisation& lin);
/// The plant denominator D = lambda^2 - lambda own + gap (the mode with zeta = 0).
QuasiPolynomial plant_characteristic(const Linearisation& lin);

}  // namespace ddemap
