#pragma once
/// \file penetration.hpp
/// Penetration-rate studies of two car types on a ring.

#include <vector>

#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/traffic/fleet.hpp"

namespace ddemap {

/// Penetration-rate study: the spectral abscissa of the mixed ring as a function of the fraction
/// p of X cars (k = round(p N)). With draws > 0 every p is solved for `draws` random
/// arrangements (and the spread one), reporting the range; for laws of the car ahead only the
/// order does not matter, so draws add nothing there.
struct MixOptions {
    int cars = 40;
    std::vector<double> fractions;  ///< p values in [0, 1]
    int draws = 0;
    unsigned seed = 1;
    MixedRingOptions ring;          ///< speed or length, solver, roots.count
    /// After every arrangement solved, on the caller's thread: (arrangements solved,
    /// fractions.size() * (draws + 1), its p). May be empty. Throwing ddemap::Cancelled
    /// (core/execution.hpp) stops the study, and so does a root search that
    /// ring.roots.progress cancels: penetration_study then returns every fraction, those whose
    /// arrangements were not all solved with status Status::Cancelled, stable = false and
    /// `arrangements` = the ones solved (their abscissae over those; 0 when none). Any other
    /// exception reaches the caller as it is.
    BranchProgress progress;
    void validate() const;
};

struct MixPoint {
    double fraction = 0.0;       ///< requested p
    int x_cars = 0;              ///< k = round(p N)
    double abscissa = 0.0;       ///< spread arrangement
    double abscissa_min = 0.0;   ///< over the arrangements solved
    double abscissa_max = 0.0;
    double speed = 0.0;          ///< equilibrium speed of the spread arrangement
    int arrangements = 0;
    bool stable = false;         ///< every arrangement stable
    int unstable_roots = 0;      ///< spread arrangement, among the listed roots
    double max_residual = 0.0;
    Status status = Status::Converged;  ///< worst over the arrangements
    std::string method_used;  ///< the root method of the spread arrangement (contour, dense or shift_invert)
};

/// The study, one MixPoint per fraction (in order). Cancellation: see MixOptions::progress.
std::vector<MixPoint> penetration_study(const FleetCar& x, const FleetCar& y, const MixOptions& options);

}  // namespace ddemap
