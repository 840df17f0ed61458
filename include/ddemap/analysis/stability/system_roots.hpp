#pragma once
/// \file system_roots.hpp
/// Rightmost roots and the stability verdict of any linear DDE with discrete delays (a system
/// read from a file), through the root facade (solve/roots.hpp: the backend is chosen there).

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/roots.hpp"

namespace ddemap {

struct SystemRootResult {
    RootResult roots;               ///< with the method given and used, the status and the certificate
    double spectral_abscissa = 0.0;
    bool stable = false;            ///< converged and every root has Re < -marginal band
    /// Stable, Marginal (rightmost root within the band), Unstable, or Undecided (not converged
    /// or no root found).
    Verdict verdict = Verdict::Undecided;
};

/// options.progress reports the root work (solve/roots.hpp) and may throw ddemap::Cancelled to
/// stop it: the result then has roots.status Status::Cancelled, no roots and verdict Undecided.
/// Throws std::invalid_argument for invalid options or a method that does not fit the system
/// (contour needs a scalar characteristic function; shift_invert real coefficients and a delay).
SystemRootResult analyse_system(const LinearDDE& dde, const RootOptions& options = {});

}  // namespace ddemap
