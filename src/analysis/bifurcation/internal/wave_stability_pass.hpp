#pragma once
// The matrix-free stability pass of a travelling-wave branch (analysis/wave_stability.hpp), run
// by travelling_wave_branch after the branch for N > full_ring_floquet_limit.
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"

namespace ddemap::wave_stability {

/// For every wave of res.branch.points: wave_ring_stability, its multipliers, trivial_distance,
/// max_nontrivial and stable (Verdict::Stable only) copied into the wave; res.stability,
/// stability_method = "matrix_free", stability_status / message (the first undecided wave's),
/// branch.max_trivial_distance. options.stability_progress after every wave.
void matrix_free_pass(const ParameterMap& parameters, const TravellingWaveOptions& options, TravellingWaveBranch& res);

}  // namespace ddemap::wave_stability
