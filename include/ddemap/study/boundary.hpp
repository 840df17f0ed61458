#pragma once
/// \file continuation.hpp
/// Stability boundaries in a two-parameter window, traced by pseudo-arclength continuation.
///
/// * hopf (plant or ring mode m): a root crosses the imaginary axis, f(i w; p1, p2) = 0, two
///   real equations in (p1, p2, w) (f the plant denominator D or the mode's quasi-polynomial);
/// * string, low frequency: the coefficient c2(p1, p2) = 0 of |D(iw)|^2 - |N(iw)|^2;
/// * string, peak: a local maximum of |Gamma(iw)| at w > 0 touches 1:
///   |Gamma(iw)|^2 - 1 = 0 and d/dw |Gamma(iw)|^2 = 0 in (p1, p2, w).
/// Parameters are scaled to the unit window; the Jacobian is taken by central differences, so
/// any model works, linear in its parameters or not. Branches are seeded where the sweep's
/// verdicts change between neighbouring grid points, corrected by Newton, traced both ways
/// with step control through turning points, and clipped exactly at the window edges (by the
/// continuation engine of ddemap/solve/continuation.hpp, the window being its box).

#include <string>
#include <vector>

#include "ddemap/study/sweep.hpp"

namespace ddemap {

enum class BoundaryKind { PlantHopf, RingHopf, LowFrequency, Peak };

/// "hopf" for PlantHopf and RingHopf, "string" for LowFrequency and Peak.
std::string kind_name(BoundaryKind k);
/// "plant", "ring", "lowfreq", "peak".
std::string subkind_name(BoundaryKind k);

struct BoundaryPoint {
    double x = 0.0, y = 0.0;  ///< the two swept parameters
    double omega = 0.0;       ///< crossing (or peak) frequency; 0 for the low-frequency curve
};

struct BoundaryCurve {
    BoundaryKind kind = BoundaryKind::RingHopf;
    int mode = -1;            ///< ring mode m (zeta = exp(-2 pi i m / N)) for RingHopf, else -1
    std::vector<BoundaryPoint> points;
    bool closed = false;
    double max_residual = 0.0;  ///< largest |F| at the accepted points
};

struct BoundaryOptions {
    double initial_step = 0.01;  ///< in units of the window size
    double max_step = 0.02;
    double min_step = 1e-8;
    int max_points = 20000;      ///< per branch
    void validate() const;
};

struct BoundarySet {
    std::vector<BoundaryCurve> curves;
    int seeds = 0;      ///< seeds found on the grid
    int rejected = 0;   ///< seeds whose Newton correction failed
    double seconds = 0.0;
};

/// Traces every boundary branch that crosses the grid of `sweep` (whose spec gives the model,
/// the window and the ring size). The ring Hopf seeds need every mode's root: a sweep made with
/// ring method "winding" (no mode_roots) is run again with "modes" first.
BoundarySet trace_boundaries(const SweepResult& sweep, const BoundaryOptions& options = {});

/// Residual of a boundary equation at a point (for checks): |F(x, y, omega)|.
double boundary_residual(const SweepSpec& spec, BoundaryKind kind, int mode, const BoundaryPoint& p);

}  // namespace ddemap
