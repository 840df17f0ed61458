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

/// Which ring Hopf curves a finite ring gets.
///  * All: every mode's Hopf curve through the window (seeded from every mode's rightmost root:
///    needs a sweep with ring method "modes", cost ~ N);
///  * Envelope: only the boundary of the ring-stable region, as arcs of the modes' Hopf curves,
///    seeded where the sweep's ring verdict changes between neighbouring grid points (any ring
///    method, so the winding sweep at any N). An arc of mode m is continued only while the ring
///    has no root right of the axis besides m's crossing pair (analyse_ring_winding at every
///    point: unstable_roots <= 2, all of them mode m's, Re < 1e-9 max(1, |lambda|)); where another
///    mode m' turns unstable the arc ends at the corner, located by bisection on the arclength
///    (terminal test function of the continuation engine, to its event tolerance), and m''s arc
///    is continued from that corner. Arcs shorter than 1e-3 grid cells are not chained further
///    (very large N: the envelope is then a scallop of modes whose arcs are far below a pixel).
///  * Auto: All for N <= kEnvelopeAutoCars (and for laws with more than one leader, where the
///    winding analysis does not apply), Envelope above.
/// N = infinity has no ring Hopf curves (its boundaries are the plant's and the string curves).
enum class RingCurves { All, Envelope, Auto };

/// Auto draws every mode's curve up to this ring size.
constexpr int kEnvelopeAutoCars = 64;

/// "all", "envelope", "auto".
std::string ring_curves_name(RingCurves r);
/// Parses "all", "envelope" or "auto" (std::invalid_argument otherwise).
RingCurves parse_ring_curves(const std::string& text);
/// All or Envelope: what `r` means for this sweep (Auto resolved as above; at N = inf, where
/// neither draws a ring curve nor needs the per-mode sweep, Auto is Envelope). std::invalid_argument
/// for Envelope on a finite ring of a law with more than one leader.
RingCurves resolve_ring_curves(RingCurves r, const SweepSpec& spec);

struct BoundaryOptions {
    RingCurves ring_curves = RingCurves::Auto;
    double initial_step = 0.01;  ///< in units of the window size
    double max_step = 0.02;
    double min_step = 1e-8;
    int max_points = 20000;      ///< per branch
    /// Before each seed is traced and at the end: (seeds done, seeds). May throw
    /// ddemap::Cancelled to stop.
    Progress progress;
    void validate() const;
};

struct BoundarySet {
    std::vector<BoundaryCurve> curves;
    int seeds = 0;      ///< seeds found on the grid
    int rejected = 0;   ///< seeds whose Newton correction failed
    /// Envelope: seeds whose corrected point is not on the envelope (another mode unstable
    /// there), and arcs started from corners.
    int off_envelope = 0;
    int corners = 0;
    RingCurves ring_curves = RingCurves::All;  ///< what was drawn (All or Envelope)
    double seconds = 0.0;
};

/// Traces every boundary branch that crosses the grid of `sweep` (whose spec gives the model,
/// the window and the ring size). Ring curves All: the seeds need every mode's root, so a sweep
/// made with ring method "winding" (no mode_roots) is run again with "modes" first; Envelope
/// uses the sweep as it is (its ring verdicts, abscissa modes and frequencies).
BoundarySet trace_boundaries(const SweepResult& sweep, const BoundaryOptions& options = {});

/// Envelope test at one point of the window: true when the ring of spec.cars cars has no root
/// right of the axis other than a crossing pair of mode `mode` (or its conjugate N - mode) with
/// Re < 1e-9 max(1, |lambda|), by analyse_ring_winding (finite N, one-leader laws); `omega` is
/// the pair's crossing frequency on mode `mode` (sign included; the abscissa's Newton guess).
bool on_ring_envelope(const SweepSpec& spec, int mode, double x, double y, double omega);

/// Residual of a boundary equation at a point (for checks): |F(x, y, omega)|.
double boundary_residual(const SweepSpec& spec, BoundaryKind kind, int mode, const BoundaryPoint& p);

}  // namespace ddemap
