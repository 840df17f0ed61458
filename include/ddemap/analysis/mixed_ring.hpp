#pragma once
/// \file mixed_ring.hpp
/// Rightmost roots and the stability verdict of a mixed ring (traffic/fleet.hpp), by the
/// product path for one-leader fleets, otherwise by collocation (dense or sparse).

#include <limits>

#include "ddemap/solve/shift_invert.hpp"
#include "ddemap/traffic/fleet.hpp"

namespace ddemap {

struct MixedRingOptions {
    SparseRootOptions roots;     ///< roots.count: how many rightmost non-trivial roots
    SolverMethod method = SolverMethod::Automatic;
    double speed = std::numeric_limits<double>::quiet_NaN();   ///< common speed, or
    double length = std::numeric_limits<double>::quiet_NaN();  ///< ring length (exactly one of the two)
    void validate() const;
};

struct MixedRingResult {
    RingEquilibrium equilibrium;
    SparseRootResult roots;          ///< the rightmost roots, trivial root removed
    bool trivial_found = false;      ///< the trivial root was among the computed ones
    double trivial_root = 0.0;       ///< |lambda| of it (0 up to rounding)
    double spectral_abscissa = 0.0;  ///< max Re over the listed roots
    int unstable_roots = 0;          ///< listed roots with Re > marginal band
    bool unstable_count_complete = false;  ///< the list reaches left of the axis, so the count is all of them
    bool stable = false;             ///< converged and the rightmost non-trivial root has Re < -band
    double product_residual = std::numeric_limits<double>::quiet_NaN();  ///< max |prod Gamma_i - 1| (predecessor laws)
    SolverMethod method_given = SolverMethod::Automatic;  ///< the path asked for
    SolverMethod method_used = SolverMethod::Product;     ///< the path taken (product, dense or sparse)
};

MixedRingResult analyse_mixed_ring(const Fleet& fleet, const MixedRingOptions& options);

}  // namespace ddemap
