#pragma once
/// \file sweep.hpp
/// Grid sweeps over two model parameters. Along each grid row the rightmost root of every ring
/// mode (and of the plant) is continued by Newton on its quasi-polynomial from the previous
/// point, and certified at every point by the argument principle: no zero lies right of
/// Re(lambda) + 1e-10 max(1, |lambda|). A failed certificate falls back to collocation. Rows are
/// independent (each starts with collocation), so the output does not depend on the number of
/// threads.

#include <memory>
#include <string>
#include <vector>

#include "ddemap/analysis/stability/ring_winding.hpp"  // kWindingFallbackCars
#include "ddemap/core/execution.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/solve/roots.hpp"

namespace ddemap {

/// One axis: `count` values from `lo` to `hi` inclusive (count >= 2, lo < hi), or a single value.
struct Axis {
    std::string name;
    double lo = 0.0, hi = 0.0;
    int count = 1;
    double value(int i) const { return count == 1 ? lo : lo + (hi - lo) * i / (count - 1); }
};

/// Parses "LO:HI:COUNT" (std::invalid_argument naming the flag on error).
Axis parse_axis(const std::string& name, const std::string& text);

struct SweepSpec {
    std::string model = "ovrv";
    ParameterMap fixed;  ///< the other parameters
    Axis x, y;           ///< the two swept parameters (count >= 2 each)
    int cars = 22;       ///< ring size, 0 = infinity
    /// The ring certificate: "winding" (every mode at once from winding tables along vertical
    /// lines, analysis/ring_winding.hpp: cost independent of N; one-leader models), "modes"
    /// (each mode's rightmost root continued and certified on its own: cost ~ N, fills
    /// SweepResult::mode_roots, which the boundary continuation needs), or "auto" (winding
    /// when it applies).
    std::string ring_method = "auto";
    /// Also decide peak (L-infinity) string stability at every point: ||h||_1 <= 1
    /// (peak_string_stability) where the point is L2 string stable (elsewhere ||h||_1 >=
    /// sup |Gamma(iw)| > 1); about 0.03 s more per L2-stable point. Region class 4.
    bool peak = false;
    void validate() const;  ///< builds the model at the four corners
};


/// "winding" or "modes": the ring method spec.ring_method resolves to (std::invalid_argument for
/// an unknown name, or "winding" for a law that uses more than one car ahead).
std::string sweep_ring_method(const SweepSpec& spec);

struct SweepPoint {
    double x = 0.0, y = 0.0;
    double spectral_abscissa = 0.0;
    long long unstable_roots = 0;  ///< over all modes (-1 for N = infinity)
    int abscissa_mode = 0;
    double abscissa_omega = 0.0;  ///< finite N: |Im| of that mode's rightmost root (the boundary seeds' frequency)
    double sup_gamma = 1.0, omega_peak = 0.0;
    double lowfreq_margin = 0.0;
    double peak_gain = 0.0;   ///< highest local maximum of |Gamma(iw)| at w > 0 (0 if none)
    double peak_omega = 0.0;  ///< its frequency
    double plant_abscissa = 0.0;
    cplx plant_root;          ///< rightmost root of the plant (Im >= 0)
    bool plant_stable = false, ring_stable = false, string_stable = false;
    bool certified = true;
    /// With SweepSpec::peak: ||h||_1 (0 when not computed: an L2-unstable point, where it is
    /// above sup |Gamma| > 1; inf with an unstable plant), its verdict (a point whose norm is
    /// undecided counts as not certified and not peak stable).
    bool has_peak = false, peak_stable = false;
    double peak_norm = 0.0;
};

struct SweepResult {
    SweepSpec spec;
    std::vector<SweepPoint> points;  ///< row-major: y outer, x inner
    int modes = 0;                   ///< finite N and method "modes": N/2 + 1 modes per point (else 0)
    std::vector<cplx> mode_roots;    ///< finite N and method "modes": rightmost root of each mode, point-major
    std::string ring_method;         ///< the method used: "winding" or "modes"
    /// Method "winding": points whose tables could not be certified and that the per-mode path
    /// decided instead (N <= kWindingFallbackCars; larger rings count them as uncertified).
    int winding_fallbacks = 0;
    long winding_tables = 0;         ///< winding passes made in all
    int fallbacks = 0;               ///< points x modes that needed collocation
    int uncertified = 0;             ///< points whose certificate failed even after collocation
    int degree_max = 0;              ///< largest collocation degree any fallback used
    double seconds = 0.0;
    int threads = 1;
    const SweepPoint& at(int ix, int iy) const { return points[static_cast<std::size_t>(iy) * spec.x.count + ix]; }
};

/// Rows run in parallel under `policy` (its progress: rows done, rows in all); the result is
/// the same for any number of threads.
SweepResult run_sweep(const SweepSpec& spec, const ExecutionPolicy& policy = {});

/// The model at one grid point.
std::unique_ptr<CarModel> model_at(const SweepSpec& spec, double x, double y);

}  // namespace ddemap
