#pragma once
// orbits --wave K: the travelling waves of a built-in ring in the reduced form (one car, the
// leader the car itself shifted by K T / N; analysis/travelling_wave.hpp).
#include <string>

#include "common.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "nonlinear_flags.hpp"

namespace ddemap::cli {

struct OrbitsWaveArgs {
    const NonlinearProblemArgs& problem;
    std::string wave, degree, intervals, points, initial_step, svg, variable;
    bool adapt = false;
    bool hopf_given = false;
    const FormatArg& format;
    const OutArg& out;
    std::string max_step = {};  ///< --max-step (empty: the default of PeriodicOrbitOptions)
    bool no_stability = false;  ///< --no-stability: no multipliers for N > 10 (the matrix-free path)
    bool stability = false;     ///< --stability: the matrix-free multipliers also for N > wave_stability_default_cars
};

/// The table lines of the period doublings and tori of a branch (orbits and orbits --wave):
/// "doubling   p = .., period .., mu = .. (located: ||mu| - 1| = .., bracket .. in p)", or
/// "p ~ .. (not located: interpolated)".
std::string crossing_lines(const OrbitBranch& b);

/// Runs `orbits --wave` (exit code as the other commands).
int run_orbits_wave(const OrbitsWaveArgs& a);

}  // namespace ddemap::cli
