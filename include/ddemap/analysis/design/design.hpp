#pragma once
/// \file design.hpp
/// Gain design: the parameters of a car's law (by default its gains k1, k2) that minimise a
/// stability objective within bounds, the others (delay, jam gap, speed) held, with the
/// verdicts at the result certified by the same analyses as every other verdict.
///
/// Objectives (x the free parameters, Gamma the head-to-tail transfer function, D the plant):
///   sup-gamma  the weighted H-infinity norm sup_w |Gamma(i w)| |1 + i m w|, m = `margin`
///              (seconds; attenuation_margin.hpp). It is at least 1 (its limit as w -> 0), and
///              exactly 1 where every wave is damped at least as by a first-order lag of m seconds
///              (the attenuation margin m* >= m). When a run reaches 1, every such gains are
///              optimal, and the result is the one nearest the car's own values (the nearest
///              objective below, run next). (With m -> 0 it is sup |Gamma(i w)|, 1 on the whole
///              string-stable set, whose boundary it approaches only quadratically: the weight
///              makes the result lie inside the set, by the margin asked.)
///   peak       ||h||_1, the peak (L-infinity) string-stability norm (peak_stability.hpp);
///   abscissa   the spectral abscissa of the plant (cars = -1) or of the ring of `cars` cars
///              (0: N = infinity);
///   nearest    the smallest weighted relative change sqrt(sum_j w_j^2 ((x_j - x0_j) / x0_j)^2)
///              from the car's own values x0 that makes the attenuation margin at least `margin`
///              (string stable, every wave damped at least as by a lag of `margin` seconds):
///              by sequential quadratic programming (up to four free parameters): mu is the least
///              of its pieces (the limit w -> 0 and each local minimum over w, attenuation_scan),
///              and each piece g = (q(w) - m^2 |N|^2) / |N| >= 0 at its fixed frequency is
///              linearised; each step solves the convex QP (distance in the weighted relative
///              metric, the bounds, the linearised pieces) exactly by its active sets, until the
///              step is below 1e-8 of the distance. (More free parameters: an exact penalty
///              d(x) + rho max(0, 1 - m*(x) / margin) minimised by BFGS, rho raised until the
///              result is feasible.) Then the crossing on the segment from x0 is located by
///              bisection, so that the result meets the margin and the point just before it does not.
/// sup-gamma, peak and nearest are +infinity where the plant is unstable; a start with an unstable
/// plant is first moved by minimising the plant's abscissa until it is below zero.
/// Gradients: where f is differentiable, the envelope (Danskin) formula at the maximising
/// frequency or the rightmost root: d|Gamma(i w*)|/dx_j, dmu/dx_j = d(q/|N|^2)(w*)/dx_j, and for a
/// root lambda of the characteristic function Delta, dlambda/dx_j = -(dDelta/dx_j) / Delta'(lambda);
/// the partials in x_j of N, D and Delta at the fixed w* or lambda by central differences of the
/// law's linearisation (step 1e-6 relative, error ~1e-12). The peak norm's gradient comes from
/// the sensitivity equations of the step response along those partials of the coefficients
/// (peak_stability.hpp; a difference of ||h||_1, step 1e-3 of the value, where a free parameter
/// moves a delay), the norm computed to 1e-6 with at most 200,000 integrator steps during the
/// search, at most 40 evaluations per run: `peak` is the slowest objective. sup-gamma and peak are at least 1: a run
/// that reaches 1 has found a global minimum, and the remaining starts are skipped. peak runs
/// its starts in the order of their norm (one norm each; the nearest L2 design among them), and
/// a point x it reaches with ||h||_1 = 1 is walked back toward the car: the result is a point
/// x0 + t (x - x0) of the segment's part inside the box at the edge of the certified peak
/// verdict, found by bisection (to 1e-4 in t; the nearest such point when the peak-stable points
/// of the segment form one interval), a stage of its own in `starts`.
/// The minimiser: solve/optimize/nonsmooth.hpp, in the coordinates z_j with
/// x_j = lo_j + (hi_j - lo_j)(1 - cos z_j)/2 (the bounds reached at z_j = 0, pi), from the car's
/// own values (moved a millionth of the box inside it when they lie outside or on a bound) and
/// `starts` - 1 points of a Halton sequence in the box; the best run wins, and among runs whose
/// objectives tie (to 1e-12 relative: the plateaus of sup-gamma and peak) the one that ended
/// nearest the car's own values.

#include <optional>
#include <string>
#include <vector>

#include "ddemap/analysis/stability/attenuation_margin.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/stability/peak_stability.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/core/parameters.hpp"
#include "ddemap/solve/optimize/nonsmooth.hpp"

namespace ddemap {

enum class DesignObjective { SupGamma, Peak, Abscissa, Nearest };

/// "sup-gamma", "peak", "abscissa", "nearest"
std::string to_string(DesignObjective o);
/// The objective named by one of those words; std::invalid_argument naming the word otherwise.
DesignObjective parse_design_objective(const std::string& name);

struct DesignOptions {
    DesignObjective objective = DesignObjective::SupGamma;
    /// The law parameters designed (names of CarModel::law_parameter_names(), no repeats).
    std::vector<std::string> free = {"k1", "k2"};
    /// Their bounds; a free parameter without one gets [x0 / 10, 10 x0] (x0 its value at the car),
    /// clipped to the law's domain. A bound on a parameter that is not free is an error.
    ParameterBounds bounds;
    /// sup-gamma and nearest: the attenuation margin asked for, in seconds (0.001 to 1000; below
    /// a millisecond mu = m^2 is lost in rounding); the other objectives report whether the
    /// result meets it.
    double margin = 0.1;
    /// nearest: w_j of the weighted relative change (empty: all 1; else one per free parameter, 0.001 to 1000).
    std::vector<double> weights;
    /// abscissa: -1 the plant; 0 the ring of infinitely many cars; N >= 2 a ring of N cars. The
    /// certified ring verdict at the result is reported for every objective when cars >= 0.
    int cars = -1;
    int starts = 4;  ///< the car's own values and starts - 1 Halton points (1 to 64)
    /// The minimiser's options; design locates kinks to 1e-6 of the box (the sampling radius in
    /// the coordinates z, whose range is [0, pi] for every parameter) in at most 500 iterations.
    NonsmoothOptions optimizer = [] {
        NonsmoothOptions o;
        o.final_radius = 1e-6;
        o.max_iterations = 500;
        return o;
    }();
    PeakOptions peak;  ///< of the peak objective and of the peak verdict at the result
    /// The covariance of the car's calibrated (k1, k2, th, tau, eta) (ovrv only; what `calibrate`
    /// writes): when given, the verdicts at the car and at the design are also judged under the
    /// uncertainty of the parameters the design holds (classify_with_uncertainty with the rows and
    /// columns of the free parameters set to zero: they are the engineer's choice, not estimates).
    bool has_covariance = false;
    Eigen::Matrix<double, 5, 5> covariance = Eigen::Matrix<double, 5, 5>::Zero();
    int uncertainty_samples = 1000;  ///< parameter draws for those probabilities (>= 1)
    /// Robust design (needs the covariance): the attenuation margin is asked of the worst point
    /// of the fit's 95 % ellipsoid of the held parameters, not of the car's values. Solved by an
    /// exchange method: each design asks the margin at the car's own held values and at every
    /// held values where an earlier design's margin was least (worst_attenuation_margin), the
    /// objective being its worst over them; the new design's worst point is added until the
    /// worst margin over the ellipsoid at the design meets `margin` (to 1e-6 relative), at most
    /// `robust_iterations` designs. When it stops with the margin met, the last design (the
    /// nearest gains meeting the margin at finitely many points, a relaxation of the robust problem)
    /// is robust, hence the least robust change (up to the local search and the worst-case
    /// search over the ellipsoid, which is sampled, not certified).
    bool robust = false;
    int robust_iterations = 8;  ///< 1 to 50
    /// After each evaluation of a search, and after each run: (work done, work in all), the work
    /// counted in evaluations with each run's budget as its share (an upper bound: a run that
    /// stops early adds the rest of its share). It may throw ddemap::Cancelled to stop.
    Progress progress;
    /// std::invalid_argument naming the first bad option (the names against the law in design_gains).
    void validate() const;
};

/// One run of the minimiser.
struct DesignStart {
    std::string objective;  ///< what this run minimised (sup-gamma runs are followed by nearest runs)
    ParameterMap start;   ///< the free parameters where it started
    ParameterMap end;     ///< where it ended
    /// the free parameters at start, at every iterate of every stage (plant stabilisation, the
    /// minimiser or the sequential QP) and at the end, in order
    std::vector<ParameterMap> path;
    double value = 0.0;   ///< the objective there (nearest: the change, plus the penalty rho (1 - m*/m) where the margin is not met)
    Status status = Status::Converged;
    std::string message;
    int iterations = 0, evaluations = 0;
};

/// The least attenuation margin m* (analysis/stability/attenuation_margin.hpp) over the 95 %
/// confidence ellipsoid of a fitted OVRV car's held parameters: {p : (p - p0)^T C_h^-1 (p - p0)
/// <= chi2_d(0.95)}, C_h the covariance of the d held parameters among k1, k2, th, tau (eta
/// moves no root of the linearisation) with a positive variance. Searched on the boundary and at
/// half its radius along 2 (d = 1), 72 (d = 2, then the least refined by golden section in the
/// angle) or 200 (d >= 3, Fibonacci or fixed-seed) directions; values of th, tau below 0 and of
/// k1, k2 below 1e-9 are taken at those limits. A point whose plant is unstable has m* = -inf.
struct WorstMargin {
    double margin = 0.0;             ///< s: the least m* found (-inf: a plant unstable in the ellipsoid)
    double nominal = 0.0;            ///< s: m* at the centre
    ParameterMap at;                 ///< the held parameters where it is reached
    std::vector<std::string> held;   ///< the parameters searched (empty: m* of the centre alone)
    double radius2 = 0.0;            ///< chi2_d(0.95)
    int evaluations = 0;
    bool plant_unstable = false;     ///< some point of the ellipsoid has an unstable plant
};
/// `parameters`: k1, k2, th, tau, eta of an OVRV car; `covariance`: order k1, k2, th, tau, eta,
/// the rows and columns of parameters that are not held set to 0.
WorstMargin worst_attenuation_margin(const ParameterMap& parameters, const Eigen::Matrix<double, 5, 5>& covariance);

struct DesignResult {
    /// Converged: the best run met the minimiser's stationarity test (or, for nearest, found the
    /// crossing) and the verdicts at the result are decided; otherwise the minimiser's status
    /// (the gains are the best found, not an optimum) or the undecided verdict's.
    Status status = Status::Converged;
    std::string message;
    std::string objective;       ///< to_string(options.objective)
    std::string method;          ///< the minimiser used (BFGS for the objectives, sequential QP for nearest)
    std::string model;           ///< the law (ovrv, idm, ...)
    std::vector<std::string> free;
    ParameterBounds bounds;      ///< the bounds used, one per free parameter
    ParameterMap initial;        ///< every parameter of the car as given (speed included)
    ParameterMap parameters;     ///< the same with the free ones designed
    ParameterMap gains;          ///< the free parameters at the result
    std::vector<std::string> at_bound;  ///< free parameters on a bound (to 1e-9 relative)
    /// The objective at the car's own values (+inf: plant unstable) and at the result; for
    /// nearest the relative change itself (0 at the car).
    double value_initial = 0.0;
    double value = 0.0;
    double change = 0.0;         ///< the weighted relative change from the car's own values
    AttenuationScan attenuation_initial, attenuation;  ///< sup |Gamma|, mu and m* (meaningful with a stable plant)
    bool margin_met = false;     ///< attenuation margin m* >= options.margin at the result (to 1e-9 relative)
    /// A proof that no gains within the bounds are string stable, when one is known (the ovrv law
    /// with th and tau held: its low-frequency coefficient is negative at every corner of the
    /// (k1, k2) box, and linear there); empty otherwise. Robust design: the proof at the held
    /// values of the last design (a point of the ellipsoid, named in the message), so that no
    /// gains of the box are robust.
    std::string infeasibility_proof;
    StringResult string_initial; ///< certified plant, L2 and peak verdicts at the car's own values
    StringResult string;         ///< the same at the result
    std::optional<RingResult> ring_initial, ring;  ///< when options.cars >= 0
    std::string ring_method;     ///< "winding" or "modes" when ring is set
    std::vector<DesignStart> starts;
    int evaluations = 0;         ///< objective evaluations over every run
    /// With DesignOptions::has_covariance: the verdicts at the car and at the design under the
    /// uncertainty of the held parameters (string_unstable is the probability of string
    /// instability, with its Wilson interval).
    bool has_uncertainty = false;
    VerdictUncertainty uncertainty_initial, uncertainty;
    /// With a covariance: the worst attenuation margin over the fit's 95 % ellipsoid of the held
    /// parameters, at the car and at the design (the design meets the margin robustly when
    /// worst.margin >= options.margin).
    WorstMargin worst_initial, worst;
    /// Robust design: each design of the exchange method, with the held values `scenario` it
    /// added (empty: the car's own; each design asks the margin at its own and every earlier
    /// step's), its gains and the worst margin over the ellipsoid at them.
    struct RobustStep {
        ParameterMap scenario, gains;
        double worst_margin = 0.0;
    };
    bool robust = false;
    bool robust_met = false;  ///< worst.margin >= options.margin (to 1e-6 relative)
    std::vector<RobustStep> robust_steps;
};

/// Designs the free parameters of the car `model` with `parameters` (every law parameter and
/// the operating speed, as make_model takes them). std::invalid_argument for bad options, a free
/// parameter or bound the law does not have, a car value outside its bounds, or a law with more
/// than one leader; the string objectives need a single leader.
DesignResult design_gains(const std::string& model, const ParameterMap& parameters, const DesignOptions& options = {});

}  // namespace ddemap
