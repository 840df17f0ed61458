#pragma once
/// \file writers.hpp
/// CSV writers (formatting only): every double with %.17g, so that it reads back exactly.

#include <string>

#include "ddemap/study/boundary.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap {

/// %.17g
std::string format_exact(double v);

/// One row per grid point: the two axis parameters by name, spectral_abscissa, unstable_roots,
/// sup_gamma, omega_peak, plant_stable, ring_stable, string_stable, abscissa_mode,
/// plant_abscissa, lowfreq_margin, peak_gain, certified.
std::string sweep_csv(const SweepResult& sweep);

/// One row per curve point: branch, kind (hopf|string), subkind (plant|ring|lowfreq|peak),
/// mode (empty unless ring), the two parameters by name, omega.
std::string boundary_csv(const SweepSpec& spec, const BoundarySet& set);

}  // namespace ddemap
