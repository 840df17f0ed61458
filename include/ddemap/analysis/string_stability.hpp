#pragma once
/// \file string_stability.hpp
/// Head-to-tail transfer function and string stability of a linearised car-following law:
///     Gamma(s) = N(s) / D(s),  N(s) = gap(s) + s lead(s),  D(s) = s^2 - s own(s) + gap(s)
/// (for OVRV: Gamma = (k1 + k2 s) e^{-s tau} / (s^2 + (k1 th + k2) s + k1 e^{-s tau})).
/// Plant stable: every root of D has Re < 0. String stable: plant stable and
/// |Gamma(i w)| <= 1 for every w > 0.

#include <complex>
#include <vector>

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

struct StringOptions {
    RootOptions roots;            ///< for the plant roots (its count is replaced by plant_roots)
    int plant_roots = 2;          ///< rightmost roots of D computed (>= 1)
    int grid_points = 400;        ///< base samples of |Gamma(i w)| before refinement (>= 16)
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
};

StringResult analyse_string(const Linearisation& lin, const StringOptions& options = {});
/// The same with the rightmost plant roots given (rightmost first; e.g. tracked in a sweep).
StringResult analyse_string(const Linearisation& lin, RootResult plant_roots, const StringOptions& options);

}  // namespace ddemap
