#pragma once
/// \file mixed_ring.hpp
/// Rightmost roots and the stability verdict of a mixed ring (traffic/fleet.hpp) through the
/// rightmost_roots facade: "auto" takes the contour backend (the ring determinant) for
/// one-leader fleets, otherwise collocation (dense or shift_invert).

#include <limits>

#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/fleet.hpp"

namespace ddemap {

struct MixedRingOptions {
    /// roots.count: how many rightmost non-trivial roots; roots.method: the backend
    RootOptions roots = [] {
        RootOptions o;
        o.count = 10;
        return o;
    }();
    double speed = std::numeric_limits<double>::quiet_NaN();   ///< common speed, or
    double length = std::numeric_limits<double>::quiet_NaN();  ///< ring length (exactly one of the two)
    void validate() const;
};

struct MixedRingResult {
    RingEquilibrium equilibrium;
    RootResult roots;                ///< the rightmost roots, trivial root removed
    bool trivial_found = false;      ///< the trivial root was among the computed ones
    double trivial_root = 0.0;       ///< |lambda| of it (0 up to rounding)
    double spectral_abscissa = 0.0;  ///< max Re over the listed roots
    int unstable_roots = 0;          ///< listed roots with Re > marginal band
    bool unstable_count_complete = false;  ///< the list reaches left of the axis, so the count is all of them
    bool stable = false;             ///< converged and the rightmost non-trivial root has Re < -band
    /// Stable, Marginal (rightmost non-trivial root within the band), Unstable, or Undecided
    /// (not converged, or no root found).
    Verdict verdict = Verdict::Undecided;
    double product_residual = std::numeric_limits<double>::quiet_NaN();  ///< max |prod Gamma_i - 1| (predecessor laws)
};

/// Rightmost roots of the ring; options.roots.progress reports the root work (solve/roots.hpp)
/// and may throw ddemap::Cancelled to stop it: the result then has roots.status
/// Status::Cancelled, no roots and verdict Undecided. std::invalid_argument naming the car when a car's linearisation
/// at the equilibrium is outside the computable range (require_computable), before any root work.
MixedRingResult analyse_mixed_ring(const Fleet& fleet, const MixedRingOptions& options);

/// require_computable for every car of `fleet` linearised at the ring's equilibrium (options'
/// speed or length), the message naming the car (1-based position and label).
void require_computable(const Fleet& fleet, const MixedRingOptions& options);

}  // namespace ddemap
