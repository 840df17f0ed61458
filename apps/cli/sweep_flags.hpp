#pragma once
// The window of a chart command (sweep, boundary): two swept model parameters and the ring.
#include <string>

#include "common.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap::cli {

/// `counts`: axes given as LO:HI:COUNT (sweep), else LO:HI with `grid` points (boundary).
SweepSpec sweep_spec(const ModelArgs& model, const RingArg& ring, const std::string& x_name, bool counts, int grid);

/// Refuses a grid whose estimated memory, CSV or run time is above the limits of limits.hpp
/// (before any work): per point about 600 bytes + 16 per ring mode in memory, 180 bytes of CSV
/// (`writes_grid`) and 5e-5 s per mode on one core (measured, BENCHMARKS.md).
/// `panels`: that many grids of this size (a chart).
/// `ring_curves_all`: every mode's boundary curve is traced too (about 1 ms of one core per mode,
/// measured on a 10^5-car ring: 113,361 seeds in 44 s); the estimate above 10 s is announced.
void check_sweep_size(const SweepSpec& spec, const std::string& command, bool writes_grid, std::size_t panels = 1, bool ring_curves_all = false);

/// --ring-curves all|envelope|auto resolved for this window (All or Envelope; BadInput naming
/// the flag for an unknown name or envelope on a law with more than one leader).
RingCurves parse_ring_curves_flag(const std::string& text, const SweepSpec& spec);


/// {"model", "fixed", "x", "y", "ring"}
JsonObject sweep_inputs(const SweepSpec& spec);

}  // namespace ddemap::cli
