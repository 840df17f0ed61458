#pragma once
// The window of a chart command (sweep, boundary): two swept model parameters and the ring.
#include <string>

#include "common.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap::cli {

/// `counts`: axes given as LO:HI:COUNT (sweep), else LO:HI with `grid` points (boundary).
SweepSpec sweep_spec(const ModelArgs& model, const RingArg& ring, const std::string& x_name, bool counts, int grid);

/// "ovrv, th = 1.5, tau = 0.5, N = 22"
std::string fixed_title(const SweepSpec& spec);

/// {"model", "fixed", "x", "y", "ring"}
JsonObject sweep_inputs(const SweepSpec& spec);

}  // namespace ddemap::cli
