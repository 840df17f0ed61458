#pragma once
/// \file string_stability.hpp
/// Head-to-tail transfer function and string stability of a linearised car-following law:
///     Gamma(s) = N(s) / D(s),  N(s) = gap(s) + s lead(s),  D(s) = s^2 - s own(s) + gap(s)
/// (for OVRV: Gamma = (k1 + k2 s) e^{-s tau} / (s^2 + (k1 th + k2) s + k1 e^{-s tau})).
/// Plant stable: every root of D has Re < 0. String stable: plant stable and
/// |Gamma(i w)| <= 1 for every w > 0.

#include <complex>
#include <optional>
#include <vector>

#include "ddemap/analysis/stability/peak_stability.hpp"
#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/solve/roots.hpp"
#include <complex>
#include <vector>

#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

/// Expansion |D(i w)|^2 - |N(i w)|^2 = c2 w^2 + c4 w^4 + c6 w^6 + c8 w^8 + O(w^10), with the
/// coefficients from the exact Taylor series of D and N at 0 (for OVRV,
/// c2 = f_v^2 + 2 f_v f_s tau - 2 f_s - f_l^2 = 2 k1 [k1 th^2 / 2 + k2 th - 1 - tau (k1 th + k2)]).
struct LowFrequency {
    double c2 = 0.0, c4 = 0.0, c6 = 0.0, c8 = 0.0;
    int decisive_order = 0;  ///< 2, 4, 6 or 8: the first coefficient not zero to rounding; 0 if none
    bool attenuates = false; ///< |Gamma(i w)| < 1 for all small w > 0 (decisive coefficient > 0)
    double d0 = 0.0;         ///< D(0) = N(0)
    double gamma_prime0 = 0.0;  ///< Gamma'(0) (real), needed for the small-wave-number ring branch
};

LowFrequency low_frequency_expansion(const Linearisation& lin);

/// The computable range of the analyses of identical cars (analyse_string, analyse_ring; README
/// "Computable range"). With c = the sum of the absolute coefficients of gap, own and lead
/// (for OVRV c = k1 (1 + th) + 2 k2) and tau_max the largest delay:
///     c <= kMaxCoefficientSum   and   c tau_max <= kMaxScaledDelay.
/// Every root with Re >= sigma has |lambda| <= R(sigma) ~ c, and the collocation degree that
/// resolves it grows like R tau_max (rescaling time by tau_max leaves c tau_max unchanged), so
/// this product, not c or tau alone, bounds the work.
constexpr double kMaxCoefficientSum = 1e8;
constexpr double kMaxScaledDelay = 10.0;
/// c tau_max of the range above (c alone when there is no delay).
double scaled_delay(const Linearisation& lin);
/// True when `lin` is inside the range above (the test require_computable makes; cheap).
bool is_computable(const Linearisation& lin);
/// Throws std::invalid_argument stating the range when `lin` is outside it; a non-empty `what`
/// (e.g. "car 3 (A_min)", "the corner k1 = 1, k2 = 2 of the window") starts the message. The one
/// check of the range: rings of mixed cars (every car), penetration studies, sweep windows (their
/// corners before any work, and every point, since the range need not be largest at a corner)
/// and classifications of files call it too.
void require_computable(const Linearisation& lin, const std::string& what = std::string());

/// Integrator steps of one ||h||_1 run for a car already L2 string unstable (then peak unstable
/// whatever the norm): the norm is informative only, and a plant that settles slowly would need
/// millions of steps; beyond this it is "not computed" (PeakResult::finite false).
constexpr long kInformativePeakSteps = 200000;

struct StringOptions {
    RootOptions roots;            ///< for the plant roots (its count is replaced by plant_roots)
    int plant_roots = 2;          ///< rightmost roots of D computed (>= 1)
    int grid_points = 400;        ///< base samples of |Gamma(i w)| before refinement (>= 16)
    bool peak = false;            ///< also decide peak (L-infinity) string stability (StringResult::peak)
    PeakOptions peak_options;
    void validate() const;
};

/// A local maximum of |Gamma(i w)| at w > 0.
struct GainPeak {
    double omega = 0.0;
    double gain = 0.0;
};

struct StringResult {
    // plant
    bool plant_stable = false;
    double plant_abscissa = 0.0;       ///< rightmost real part of the roots of D
    RootResult plant_roots;
    // transfer function
    double sup_gamma = 1.0;            ///< sup over w > 0 of |Gamma(i w)| (>= 1: the limit w -> 0 is 1)
    double omega_peak = 0.0;           ///< where it is reached; 0 when only approached as w -> 0
    std::vector<GainPeak> peaks;       ///< every local maximum found, refined
    double peak_margin = 1.0;          ///< 1 - (highest local maximum at w > 0); 1 when there is none
                                       ///< (formed as (1 - |Gamma|^2) / (1 + |Gamma|): no cancellation)
    LowFrequency lowfreq;
    double lowfreq_margin = 0.0;       ///< the decisive low-frequency coefficient (c2 unless it vanishes)
    double omega_search_max = 0.0;     ///< beyond it |Gamma(i w)| < sup_gamma is proven by a bound
    int evaluations = 0;               ///< evaluations of Gamma
    bool string_stable = false;
    /// Stable, Marginal (a root of D on the axis to rounding), Unstable, or Undecided when the
    /// plant roots did not converge.
    Verdict plant_verdict = Verdict::Undecided;
    /// Undecided with the plant; Unstable when the plant is, or |Gamma(i w)| > 1 somewhere
    /// (a peak, or the low frequencies amplify); Stable when string_stable; Marginal otherwise
    /// (plant marginal, or |Gamma| = 1 to the order of the series at w -> 0).
    Verdict string_verdict = Verdict::Undecided;
    /// Peak (L-infinity) string stability, ||h||_1 <= 1 (peak_string_stability), when
    /// StringOptions::peak asked for it: undecided with the plant, unstable with it.
    std::optional<PeakResult> peak;
};

StringResult analyse_string(const Linearisation& lin, const StringOptions& options = {});
/// The same with the rightmost plant roots given (rightmost first; e.g. tracked in a sweep).
StringResult analyse_string(const Linearisation& lin, RootResult plant_roots, const StringOptions& options);

/// Continuation data of the string analysis along a sweep row: the previous point's maximiser of
/// |Gamma(i w)| (the highest local maximum at w > 0).
struct StringGuess {
    bool have = false;
    double omega = 0.0;
};

/// The relative slack of the exclusion bound of analyse_string_continued: sup |Gamma(i w)|^2 is
/// certified to lie in [g, g (1 + kStringExclusionSlack)], g = |Gamma(i w*)|^2 at the peak found.
constexpr double kStringExclusionSlack = 1e-12;

/// analyse_string with the plant roots given, from a neighbouring point's maximiser instead of
/// the scan of the axis (a sweep row's continuation). Newton on
///     psi(w) = d/dw log |Gamma(i w)|^2 = 2 Re(N_w / N - D_w / D) = 0
/// from guess.omega gives the peak w* (psi'(w*) < 0) and g = 1 - attenuation(w*) = |Gamma(i w*)|^2;
/// then a certified exclusion bound shows
///     phi(w) = g (1 + kStringExclusionSlack) |D(i w)|^2 - |N(i w)|^2 >= 0   for 0 <= w <= omega_search_max
/// (beyond it |Gamma| < 1 <= g by the bound of analyse_string): around w* by the cubic Taylor
/// bound from w* (|phi'''| bounded by the sums of the absolute values of the derivatives of the
/// terms c s^p e^{-s d}), elsewhere on pieces [a, b] by the quadratic Taylor bounds from both
/// ends with |phi''| bounded the same way, pieces halved until they pass; every bound less a
/// rounding allowance of 64 eps times the sizes of the terms. A sample with phi < 0 is a higher
/// point (the neighbour's maximiser was the wrong peak): Newton restarts from it (at most 4 times).
/// Applies only when the highest peak is the supremum (g >= 1) away from the low frequencies
/// (w* above the range where the series decides); returns std::nullopt when it does not apply or
/// cannot certify within `budget` evaluations: the caller then runs analyse_string. The result's
/// `peaks` holds the one certified peak (the highest local maximum); every other field is that of
/// analyse_string (sup_gamma, omega_peak, peak_margin and the verdicts, to the slack above).
std::optional<StringResult> analyse_string_continued(const Linearisation& lin, const RootResult& plant_roots,
                                                     const StringGuess& guess, int budget = 400);

}  // namespace ddemap
