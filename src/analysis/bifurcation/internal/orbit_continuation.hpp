#pragma once
// The continuation of a branch of periodic orbits, the parts shared by the orbits of a nonlinear
// DDE (periodic_orbit.cpp) and the travelling waves of a ring in the reduced form
// (travelling_wave.cpp): the step control of the pseudo-arclength continuation and the
// detection and location of the special points of a step (folds, period doublings, tori; see
// analysis/periodic_orbit.hpp). The two differ in their equations, correctors and multipliers:
// those enter through the callbacks of Probe.
#include <functional>
#include <string>

#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/solve/step_control.hpp"

namespace ddemap::orbit_continuation {

/// The step control of the pseudo-arclength continuation of a branch (solve/step_control.hpp):
/// h in the weighted norm of the branch, the predictor u + h t; a corrected orbit farther than
/// 3 h from u is a jump (to another branch: rejected like a failed corrector); after a rejection
/// h is halved and the branch ends when it falls below min_step; after an easy corrector (the
/// caller's criterion) h grows by 1.5 up to max_step.
inline StepControlOptions step_control_options(const PeriodicOrbitOptions& o) {
    StepControlOptions s;
    s.initial_step = o.initial_step;
    s.min_step = o.min_step;
    s.max_step = o.max_step;
    s.shrink_factor = 0.5;
    s.grow_factor = 1.5;
    s.max_jump = 3.0;
    return s;
}

/// One accepted step of a branch: from orbit `after` of the branch (u, unit tangent t) to the new
/// orbit v (unit tangent tn, oriented along t). The special points are located on the line
/// u + s t, each trial orbit corrected on the hyperplane a . w = a . (u + s t), a = W t.
struct Step {
    int after = 0;            ///< index of the branch orbit u
    double length = 0.0;      ///< a . (v - u): s of the new orbit
    double h = 0.0;           ///< the step size (the location tolerances are relative to it)
    double t_par = 0.0;       ///< the parameter component of t
    double tn_par = 0.0;      ///< the parameter component of tn
    double par_scale = 1.0;   ///< |to - from| (the fold's tolerance on the tangent's component)
};

/// What the special points need of the problem, at arclength s along t from u.
struct Probe {
    /// corrects the orbit at s; g = the parameter component of its unit tangent oriented along t;
    /// it becomes the fold's orbit (fold_orbit). false when the corrector failed.
    std::function<bool(double s, double& g)> fold_trial;
    /// the orbit of the last successful fold_trial (the new orbit v when none succeeded)
    std::function<PeriodicOrbit()> fold_orbit;
    /// corrects the orbit at s and computes it with its multipliers; false when the corrector failed
    std::function<bool(double s, PeriodicOrbit& out)> orbit_at;
};

/// The accuracy check: trivial_distance > orbit_accuracy_limit makes the orbit undecided
/// (stable = false, `undecided` the reason).
void check_accuracy(PeriodicOrbit& o);

/// Detects and locates the special points of one step and appends them to b:
/// - a fold when the parameter component of the tangent changes sign (t_par tn_par < 0): Illinois
///   regula falsi in s on that component, until it is below 1e-11 par_scale or the bracket below
///   1e-12 h (40 trials at most; not located: status MaxIterations, the message
///   "a fold of <what> was detected but not located");
/// - with `multipliers` (and both orbits having some), every period doubling and torus
///   bifurcation of the step (circle crossings of the multipliers paired by distance, located
///   by regula falsi on |mu| - 1, see OrbitCrossing).
/// Returns whether a fold was appended (b.folds.back()).
bool special_points(const Step& step, const PeriodicOrbit& prev, const PeriodicOrbit& next, bool multipliers, const std::string& what,
                    const Probe& probe, OrbitBranch& b);

}  // namespace ddemap::orbit_continuation
