#pragma once
// orbits --wave K: the travelling waves of a built-in ring in the reduced form (one car, the
// leader the car itself shifted by K T / N; analysis/travelling_wave.hpp).
#include <string>

#include "common.hpp"
#include "nonlinear_flags.hpp"

namespace ddemap::cli {

struct OrbitsWaveArgs {
    const NonlinearProblemArgs& problem;
    std::string wave, degree, intervals, points, initial_step, svg, variable;
    bool adapt = false;
    bool hopf_given = false;
    const FormatArg& format;
    const OutArg& out;
    bool no_stability = false;  ///< --no-stability: no multipliers for N > 10 (the matrix-free path)
};

/// Runs `orbits --wave` (exit code as the other commands).
int run_orbits_wave(const OrbitsWaveArgs& a);

}  // namespace ddemap::cli
