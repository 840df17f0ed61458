#pragma once
/// \file classify.hpp
/// Plant, ring and string verdicts of calibrated vehicles (the seed paper's classification).

#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/analysis/ring_stability.hpp"
#include "ddemap/analysis/string_stability.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// Verdicts of one vehicle setting.
struct Classification {
    CalibratedVehicle vehicle;
    StringResult string;
    RingResult ring;
};

/// Plant, ring (N cars, 0 = infinity) and string verdicts of every vehicle (OVRV).
/// Vehicles run in parallel under `policy`.
std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars,
                                     const ExecutionPolicy& policy = {});

}  // namespace ddemap
