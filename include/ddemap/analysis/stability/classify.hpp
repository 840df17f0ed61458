#pragma once
/// \file classify.hpp
/// Plant, ring and string verdicts of calibrated vehicles (the seed paper's classification),
/// and, for vehicles whose calibration carries a covariance, the same verdicts with the
/// parameter uncertainty propagated to them by sampling.

#include <limits>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// How the parameter uncertainty of a calibrated vehicle is propagated to its verdicts.
struct UncertaintyOptions {
    /// Parameter samples theta_j drawn from N(theta, C) restricted to `domain` (draws outside
    /// are rejected and redrawn). 4000 makes the Wilson bound of a sure verdict
    /// 1 - 1.92/n ~ 0.9995, so it reads "p > 0.999".
    int samples = 4000;
    /// The box the samples are restricted to, by name (k1, k2, th, tau, eta; a name not listed:
    /// [0, inf), the model's domain). Set it to the calibration's bounds (e.g.
    /// paper_calibration_bounds()) to sample the fit's own search space: a parameter the trace
    /// hardly determines then cannot send samples to delays or gains far outside it.
    ParameterBounds domain;
    /// The first `ring_samples` samples are classified as rings too (p_ring_unstable and the
    /// ring abscissa's interval); a ring verdict costs 30 (N = 22) to 400 (N = infinity) string
    /// verdicts, and 200 samples place the 2.5 % and 97.5 % quantiles of the abscissa well enough.
    /// 0 <= ring_samples; more than `samples` means `samples`.
    int ring_samples = 200;
    unsigned long long seed = 1;  ///< of the normal draws (results do not depend on the threads)
    double level = 0.95;          ///< of the margins' intervals and of the Wilson interval of p
    /// Draws allowed per sample before the domain restriction is reported as not met
    /// (Status::BudgetExhausted): the distribution lies mostly outside the domain.
    int max_draws_per_sample = 20;
    /// True when validate() would not throw.
    bool is_valid() const;
    /// Throws std::invalid_argument naming the option (samples >= 1, ring_samples >= 0,
    /// 0 < level < 1, max_draws_per_sample >= 1, domain: names k1, k2, th, tau, eta, finite
    /// bounds, 0 <= lower <= upper).
    void validate() const;
};

/// An interval of a margin over the parameter distribution: the empirical quantiles
/// (1 - level)/2 and (1 + level)/2 of the sampled margins, and their median.
struct MarginInterval {
    double lower = 0.0, median = 0.0, upper = 0.0;
};

/// A probability estimated from n Bernoulli samples with k successes: p = k / n, its standard
/// error sqrt(p (1 - p) / n), and the Wilson score interval
///     (p + z^2/(2n) -+ z sqrt(p (1 - p)/n + z^2/(4 n^2))) / (1 + z^2/n),
/// z the standard normal quantile of (1 + level)/2; never empty or degenerate at p = 0 or 1.
struct ProbabilityEstimate {
    int successes = 0, trials = 0;
    double p = 0.0, standard_error = 0.0, lower = 0.0, upper = 1.0;
};

/// ProbabilityEstimate of k successes in n trials (n >= 1, 0 <= k <= n, 0 < level < 1; else
/// std::invalid_argument).
ProbabilityEstimate probability_estimate(int successes, int trials, double level = 0.95);

/// One parameter sample and its verdicts (each from analyse_string and analyse_ring, exactly as
/// for a single vehicle).
struct VerdictSample {
    ParameterMap parameters;
    double c2 = 0.0;                ///< low-frequency coefficient of |D|^2 - |N|^2 (< 0: string unstable)
    double sup_gamma_excess = 0.0;  ///< sup_w |Gamma(i w)| - 1 (> 0: string unstable)
    double ring_abscissa = 0.0;     ///< spectral abscissa of the ring (> 0: ring unstable); only when has_ring
    bool plant_stable = false, string_stable = false, ring_stable = false;
    bool has_ring = false;          ///< among the first ring_samples samples
    bool decided = false;           ///< the plant roots converged (and the ring, when has_ring)
    bool computable = true;         ///< inside the computable range (require_computable); else not decided, no verdict
};

/// Verdicts of a vehicle under its parameter uncertainty.
struct VerdictUncertainty {
    int samples = 0;          ///< samples drawn inside the domain (= options.samples unless status says otherwise)
    int draws = 0;            ///< normal draws, including those rejected outside the domain
    int ring_samples = 0;     ///< of which also classified as rings
    int undecided = 0;        ///< samples whose plant or ring computation did not converge
    /// Probabilities over the decided samples that the car is string unstable (plant unstable
    /// or sup |Gamma| > 1 or c2 < 0, the analyse_string verdict) and plant unstable; over the
    /// decided ring samples that the ring is unstable (trials 0 when ring_samples = 0).
    ProbabilityEstimate string_unstable, ring_unstable, plant_unstable;
    MarginInterval c2, sup_gamma_excess;  ///< over the decided samples
    MarginInterval ring_abscissa;         ///< over the decided ring samples
    std::vector<VerdictSample> verdicts;  ///< every sample, in draw order
    ParameterBounds domain;   ///< the box the samples were restricted to (options.domain, or the fit's own bounds)
    bool domain_from_fit = false;  ///< domain holds the vehicle's calibration bounds (CalibratedVehicle::bounds)
    Status status = Status::Converged;
    std::string message;      ///< what was sampled, or why the status is not converged
};

/// Draws `options.samples` parameter vectors theta_j = theta + V sqrt(Lambda) z_j (C = V Lambda V^T,
/// z_j standard normal; eigenvalues below 1e-12 max|Lambda| in magnitude are zero: a fixed or
/// perfectly correlated parameter stays on its subspace), rejecting those outside options.domain,
/// and classifies each one exactly (OVRV, ring of `cars` cars, 0 = infinity), in parallel over
/// the samples. std::invalid_argument when the covariance is not finite, not symmetric or
/// has a negative eigenvalue beyond rounding, or when the options are invalid.
VerdictUncertainty classify_with_uncertainty(const ParameterMap& ovrv, const Eigen::Matrix<double, 5, 5>& covariance, int cars,
                                             const UncertaintyOptions& options = {}, const ExecutionPolicy& policy = {});

/// How far a car is from the other L2 string verdict: the smallest weighted relative change
///     d = sqrt(sum_j ((x_j - x0_j) / x0_j)^2)
/// of its parameters x = (k1, k2, th, tau) (x0 the car's own) that flips the verdict: for a
/// string-stable car the nearest point of the string-unstable set (|Gamma(i w)| reaches 1 at
/// some w >= 0, or a plant root reaches the axis), for a string-unstable one the nearest
/// string-stable point. Computed by analysis/design/verdict_distance.hpp (verdict_distance);
/// certified along the segment from x0 to `at`: the certified verdict (analyse_string) is the
/// car's own at (1 - 1e-6) d and the other at `at` itself or just beyond it. A distance is local
/// (each search converges to a nearest point of its own piece of the boundary); the smallest of
/// every piece searched is reported.
struct VerdictDistance {
    Status status = Status::NumericalIssue;
    std::string message;
    std::string method;
    bool from_stable = false;   ///< the car is string stable: the distance to instability (else to stability)
    double distance = std::numeric_limits<double>::quiet_NaN();  ///< d (0.25 = a change of 25 %)
    std::vector<std::string> over;  ///< the parameters changed
    ParameterMap at;            ///< every parameter at the flip (the others as the car's)
    /// The piece of the boundary reached: "low-frequency" (|Gamma| reaches 1 as w -> 0: c2 = 0),
    /// "frequency" (|Gamma(i omega)| = 1 at omega > 0) or "plant" (a root of the plant reaches
    /// the imaginary axis)
    std::string boundary;
    double omega = std::numeric_limits<double>::quiet_NaN();  ///< rad/s of the boundary (0: w -> 0)
};

/// Verdicts of one vehicle setting.
struct Classification {
    CalibratedVehicle vehicle;
    StringResult string;
    RingResult ring;
    /// The signed attenuation margin m* [s] (attenuation_margin.hpp): how far the car is inside
    /// (> 0) or outside (< 0) the string-stable set, as the time constant of the slowest lag that
    /// still bounds |Gamma(i w)|. NaN when the plant is not stable.
    double attenuation_margin = std::numeric_limits<double>::quiet_NaN();
    /// Only when asked (add_verdict_distances, analysis/design/verdict_distance.hpp).
    bool has_distance = false;
    VerdictDistance distance;
    /// Only when the vehicle carries a covariance (vehicle.has_covariance) and uncertainty was asked.
    bool has_uncertainty = false;
    VerdictUncertainty uncertainty;
};

/// Plant, ring (N cars, 0 = infinity) and string verdicts of every vehicle (OVRV).
/// Vehicles run in parallel under `policy`. `string_options` is given to analyse_string (e.g.
/// peak = true adds the peak (L-infinity) verdict of every vehicle, Classification::string.peak).
std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars,
                                     const ExecutionPolicy& policy = {}, const StringOptions& string_options = {});

/// The same, and for every vehicle with a covariance its verdicts under the parameter
/// uncertainty (classify_with_uncertainty, the samples in parallel under `policy`). A vehicle
/// that carries the bounds of its calibration (CalibratedVehicle::bounds, read from the file) is
/// sampled within them: each parameter `uncertainty.domain` restricts takes the vehicle's bound
/// instead when it has one (domain_from_fit); a parameter the domain leaves free stays free.
std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars,
                                     const UncertaintyOptions& uncertainty, const ExecutionPolicy& policy = {},
                                     const StringOptions& string_options = {});

/// The status of a classification as a whole: converged, or the last status of a vehicle's ring,
/// plant roots, uncertainty or peak verdict that is not (then its verdicts are undecided).
Status classification_status(const std::vector<Classification>& rows);

/// The sampling domain of classify's uncertainty when the vehicles carry no bounds: calibrate's
/// search space (paper_calibration_bounds()) without eta (no verdict depends on it, and fits often
/// sit on its lower bound).
ParameterBounds classification_domain();

}  // namespace ddemap
