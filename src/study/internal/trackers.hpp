#pragma once
// The sweep's per-point trackers (private to study/): along a grid row the rightmost root of
// every ring mode and of the plant is continued by Newton on its quasi-polynomial from the
// previous point and certified by the argument principle (a fast path of the one root facade
// for this hot loop: a result vector per point would allocate; collocation through the facade's
// dense eigenvalues is the fallback).
#include <functional>
#include <optional>
#include <vector>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"

namespace ddemap::detail {

/// Certified rightmost root of a quasi-polynomial: Newton from `guess`, certificate, fallback.
struct CertifiedRoot {
    cplx value;
    bool certified = false;  ///< no zero right of Re(value) + 1e-10 max(1, |value|)
    bool fell_back = false;  ///< collocation was needed
    int degree = 0;          ///< collocation degree used (0 if none)
};
/// `dde` builds the same problem as a LinearDDE for the collocation fallback. With `wide` (a
/// tracker's state along a row) the Newton root's certificate counts first on a line `*wide` times
/// max(1, |z|) left of it, which needs fewer samples than the line 1e-2 left, and adapts `*wide`
/// (halved when that line holds another zero, grown back to at most 0.25 when it certifies).
CertifiedRoot certified_rightmost(const QuasiPolynomial& f, const std::function<LinearDDE()>& dde,
                                  const std::optional<cplx>& guess, double* wide = nullptr);

/// Ring (N >= 2) or N = infinity summary at one point, continuing from the previous point.
struct RingSummary {
    double spectral_abscissa = 0.0;  ///< trivial zero excluded
    int abscissa_mode = 0;           ///< -1 for N = infinity
    double abscissa_theta = 0.0;
    double abscissa_omega = 0.0;     ///< |Im| of the rightmost root (finite N)
    int unstable_roots = 0;          ///< over all modes (-1 for N = infinity)
    bool stable = false;
    bool certified = true;           ///< every mode's rightmost root certified
    int fallbacks = 0;
    int degree = 0;                  ///< largest collocation degree used
};

class RingTracker {
public:
    explicit RingTracker(int cars);  ///< cars >= 2, or 0 for infinity
    RingSummary evaluate(const Linearisation& lin);
    void reset();
    /// The rightmost root of every mode (wave number) at the last point evaluated.
    const std::vector<std::optional<cplx>>& roots() const { return m_guess; }
    const std::vector<double>& thetas() const { return m_thetas; }

private:
    int m_cars;
    std::vector<double> m_thetas;            // wave numbers of the modes (or samples for N = inf)
    std::vector<std::optional<cplx>> m_guess;
};

/// The plant's rightmost root, continued the same way.
class PlantTracker {
public:
    RootResult evaluate(const Linearisation& lin, int& fallbacks);
    void reset() {
        m_guess.reset();
        m_wide = 0.25;
    }

private:
    std::optional<cplx> m_guess;
    double m_wide = 0.25;  // the first certificate line's distance (certified_rightmost)
};

/// The ring's summary at one point on the winding path (analyse_ring_winding, every mode from
/// winding tables, continued from `guess`, which it updates; sweeps and atlases): where the
/// tables are undecided, the per-mode path `reference` (made on first use) for
/// N <= kWindingFallbackCars (N = inf included), counted in `winding_fallbacks`; larger rings get an
/// uncertified summary. Adds the tables made to `tables`.
RingSummary winding_ring_summary(const Linearisation& lin, int cars, RingWindingGuess& guess, std::optional<RingTracker>& reference,
                                 long& tables, int& winding_fallbacks);

/// One point of a sweep (and of an atlas): the ring's and the plant's rightmost roots continued
/// from the trackers' previous point, then string stability (|Gamma(iw)| on 120 frequencies and
/// refined). Fills every field of `p` but x and y; adds the collocation fallbacks to `fallbacks`.
RingSummary evaluate_sweep_point(const Linearisation& lin, RingTracker& ring, PlantTracker& plant, SweepPoint& p, int& fallbacks);
/// The same with the ring's summary already computed (by the tracker or the winding path): the
/// plant and string stability, every field of `p` but x and y. With `string` (a sweep row's
/// continuation) the string analysis starts from the previous point's maximiser
/// (analyse_string_continued) and scans the axis only when that cannot certify; `string` is then
/// updated to this point's maximiser.
/// With `peak`, also the peak verdict (SweepPoint::has_peak).
void fill_sweep_point(const Linearisation& lin, const RingSummary& rs, PlantTracker& plant, SweepPoint& p, int& fallbacks,
                      StringGuess* string = nullptr, bool peak = false);

}  // namespace ddemap::detail
