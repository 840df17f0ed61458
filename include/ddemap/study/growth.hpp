#pragma once
/// \file growth.hpp
/// Disturbance growth along platoons of identical followers (the seed paper's growth figure).

#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// Disturbance growth along a platoon of identical followers (the paper's growth figure):
/// per position the speed drop, the amplification (drop / the lead's drop) and the minimum gap,
/// up to the first position whose car disengages or collides (where the platoon fails).
struct GrowthResult {
    std::string name;
    std::vector<double> speed_drop, amplification, min_gap;  ///< positions 1 .. (failed_at - 1) or all
    int failed_at = 0;            ///< first failing position (0: none)
    std::string failure;          ///< "disengage" or "collision"
    double failure_time = 0.0;
    double failure_amplification = 0.0;  ///< (v0 - lowest speed up to the event) / lead drop
    double failure_gap = 0.0;
    /// Converged; NumericalIssue when the platoon's simulation diverged (SimResult::status; the
    /// positions are then from the run up to the divergence, not a result: undecided, and
    /// `message` says where); or Cancelled when the progress callback stopped the study before
    /// this vehicle was simulated (then only `name` is set).
    Status status = Status::Converged;
    std::string message;  ///< why, when status is not Converged
};

/// One GrowthResult per vehicle (in order), the platoons simulated in parallel under `policy`.
/// policy.progress is called after every vehicle simulated, (vehicles done, vehicles), one call
/// at a time. Throwing ddemap::Cancelled from it stops the study: vehicles not yet started are
/// skipped, the running ones end, and the result has Status::Cancelled for every vehicle not
/// simulated (the exception never crosses the parallel region; core/execution.hpp). Any other
/// exception reaches the caller as it is.
std::vector<GrowthResult> disturbance_growth(const std::vector<CalibratedVehicle>& vehicles, const LeadProfile& lead,
                                             int followers, const SimOptions& options = {},
                                             const ExecutionPolicy& policy = {});

}  // namespace ddemap
