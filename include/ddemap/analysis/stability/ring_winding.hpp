#pragma once
/// \file ring_winding.hpp
/// Every mode of a ring of N identical one-leader cars from one pass along a vertical line, at a
/// cost that does not depend on N (N up to 10^9, and N = infinity).
///
/// With P = lambda^2 - lambda own + gap, Q = gap + lambda lead and Gamma = Q / P
/// (traffic/transfer_function.hpp), ring mode zeta = e^{-i phi} (phi = 2 pi m / N) has the
/// characteristic function f_phi = P - zeta Q = P (1 - zeta Gamma), whose zeros are the points
/// where Gamma(lambda) = e^{i phi}. Let D be the half disc Re lambda > sigma, |lambda - sigma| < r,
/// with r so large that |P - (lambda - sigma)^2| + |Q| < r^2 / 2 on and outside its arc (the
/// bound of QuasiPolynomial::zeros_right_of with the coefficients of P and Q together); then every
/// zero of every f_phi and of P right of sigma lies in D, and |Gamma| < 1 on the arc. Counting
/// along the counter-clockwise boundary of D,
///     Z(phi) = N_P(sigma) + (1 / 2 pi) Delta arg (Gamma - e^{i phi})
///            = N_P(sigma) - W(phi),
/// where N_P(sigma) is the number of zeros of P right of sigma (the plant's; tracked in the same
/// pass) and W(phi) is the winding number about e^{i phi} of the closed curve C: Gamma(sigma + i s)
/// for s from -r to r, closed by the chord from Gamma(sigma + i r) back to Gamma(sigma - i r)
/// (the arc's image lies in the open unit disc, so it may be replaced by that chord, which never
/// meets the unit circle). W is piecewise constant in phi and jumps only where C crosses the unit
/// circle: a crossing at angle alpha in which |Gamma| grows through 1 as s increases raises W by
/// 1 for phi just above alpha (the unit circle's counter-clockwise direction is the left side of an
/// outward-going curve), one in which |Gamma| falls lowers it by 1. So one pass gives the table
///     W(phi) = W(phi_0) + sum_{crossings alpha in (phi_0, phi)} direction,
/// with W(phi_0) from the unwrapped arg (Gamma - e^{i phi_0}) at one angle phi_0 far from every
/// crossing, and every mode's count Z(2 pi m / N) is a lookup: the sum over m = 1..N-1 is one sum
/// over the intervals between crossing angles. Real coefficients make Gamma(sigma - i s) the
/// conjugate of Gamma(sigma + i s): only s >= 0 is sampled, a crossing (s, alpha, d) implying its
/// mirror (-s, -alpha, -d). Mode 0 (zeta = 1) carries the structural zero root (Gamma(0) = 1) and
/// is counted on its own, without that root (ring_mode0_characteristic).
///
/// Sampling: [0, r] is bisected (the recursion of bisect_phase, core/phase_tracking.hpp) until on
/// every piece the plant's phase passes the tracker's test (phase_piece_resolved), Gamma passes
/// the same test where |Gamma| >= 1/2 (|Gamma'/Gamma| h < pi/8, quarter turns), and l = log|Gamma|
/// is resolved: either its three samples lie on one side of 0 and the Taylor bounds
/// l(x + t) >= l(x) + t l'(x) - D t^2 from both ends of each half (D twice the second derivative
/// seen in the sampled l') keep that side, or it changes sign exactly once with l' of that sign
/// at the three samples and |l'| > 2 h |l''| (a single crossing, then located by Illinois steps
/// to rounding). On the imaginary axis 1 - |Gamma(i s)|^2 is formed from the cancellation-free
/// series w^2 q(w) / |D|^2 (TransferFunction::attenuation) near |Gamma| = 1, so the tangency of
/// C to the circle at s = 0 (Gamma(0) = 1, the trivial root) is decided by the sign of q, the
/// series that decides the low frequencies of |Gamma|. The plant's phase and W(phi_0) are
/// counted by crossings of rays by the sampled polygon, which winds like the curve because each
/// step stays within its reach h max|dGamma/ds| of its samples (steps passing closer to the
/// anchor are sampled finer). A budget of samples or a zero of P on the line
/// makes the table fail (ok = false): the result is then Undecided, never a guess.

#include <string>
#include <vector>

#include "ddemap/core/status.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

/// The largest ring whose undecided winding result falls back to the per-mode path (sweeps,
/// analyse_ring_fast).
constexpr int kWindingFallbackCars = 2000;

/// One crossing of the unit circle by Gamma(sigma + i s), s > 0 (its mirror at -s is implied).
struct WindingCrossing {
    double s = 0.0;        ///< Im lambda of the crossing
    double angle = 0.0;    ///< arg Gamma there, in [0, 2 pi)
    int direction = 0;     ///< +1: |Gamma| grows through 1 as s increases; -1: it falls
    /// Re d lambda / d phi of the roots Gamma(lambda) = e^{i phi} through this point:
    /// -Re(Gamma / (dGamma/ds)); a mode at angle phi has a root near sigma + (phi - angle) re_rate + i s.
    double re_rate = 0.0;
};

/// The winding table on the line Re lambda = sigma.
struct RingWindingTable {
    double sigma = 0.0;
    double radius = 0.0;         ///< r of the half disc
    bool ok = false;             ///< false: the pass could not be certified (message says why)
    std::string message;
    int plant_zeros = 0;         ///< N_P(sigma): zeros of P right of sigma
    long evaluations = 0;        ///< evaluations of P, Q and their derivatives
    std::vector<WindingCrossing> crossings;  ///< s > 0, in order of s
    /// Sorted angles in [0, 2 pi) of all crossings (mirrors included), each with its jump, the
    /// Im lambda (negative for mirrors) and the re_rate there.
    struct Jump {
        double angle, s, re_rate;
        int direction;
    };
    std::vector<Jump> jumps;
    int base = 0;                ///< W on (0, first jump angle)
    /// W(phi) for phi in (0, 2 pi) (at a jump angle: the value just above it).
    int winding(double phi) const;
    /// Z(phi) = plant_zeros - W(phi): zeros right of sigma of the mode zeta = e^{-i phi}.
    int zeros(double phi) const { return plant_zeros - winding(phi); }
    /// Sum over the modes m = 1..N-1 of Z(2 pi m / N) (one term per interval between jump
    /// angles; mode 0 is not included), or -1 when an interval holding a mode has Z < 0.
    long long mode_zeros(int cars) const;
};

/// The table on Re lambda = sigma for one car's transfer function (real coefficients, one leader).
RingWindingTable ring_winding_table(const TransferFunction& gamma, double sigma, int budget = 20000);

struct RingWindingOptions {
    int budget = 20000;  ///< samples per pass
    void validate() const;
};

/// Continuation data for a sweep row: the previous point's rightmost roots.
struct RingWindingGuess {
    bool have = false;
    cplx root;          ///< rightmost root of the modes m != 0 (Im >= 0)
    int mode = 0;       ///< its mode (finite N)
    cplx optimum;       ///< the maximum of Re on |Gamma(lambda)| = 1 (N = inf and large N)
    bool have_optimum = false;
    cplx mode0;         ///< rightmost root of mode 0 without its trivial root
    bool have_mode0 = false;
};

/// Counts and verdict of a ring of N identical cars (N >= 2, or 0 for infinity) from winding tables.
struct RingWindingResult {
    int cars = 0;
    /// Stable / Marginal / Unstable as in ring_stability.hpp (the trivial root of mode 0 excluded;
    /// a root within marginal_band of the axis is marginal); Undecided when a table failed.
    Verdict verdict = Verdict::Undecided;
    Status status = Status::NumericalIssue;
    std::string message;
    long long unstable_roots = 0;   ///< roots with Re > band over all modes (-1 for N = inf)
    long long marginal_roots = 0;   ///< roots within the band (N = inf: 1 when any)
    double spectral_abscissa = 0.0; ///< max Re over all modes (N = inf: the sup, >= 0)
    bool abscissa_is_limit = false; ///< N = inf: the sup 0 is only approached as theta -> 0
    int abscissa_mode = 0;          ///< finite N: mode with the rightmost root (m <= N/2); -1 for inf
    double abscissa_theta = 0.0;    ///< its wave number 2 pi m / N (N = inf: theta of the sup)
    cplx abscissa_root;             ///< that root (Im >= 0)
    /// The abscissa is certified: no zero of any mode right of spectral_abscissa + gap,
    /// gap = 1e-10 max(1, |root|), and abscissa_root is a zero (Newton to rounding), or the
    /// abscissa is bracketed by two tables to within that gap, or (`accounted`) every zero right of
    /// the axis is one of the Newton roots counted by the axis table.
    bool certified = false;
    int tables = 0;                 ///< winding passes made
    long evaluations = 0;
    bool bisected = false;          ///< continuation failed; the abscissa was bracketed by bisection in sigma
    /// N <= 64 only: every root right of the axis was accounted for (the axis table's count of each
    /// mode matched by as many distinct Newton roots right of it), so the abscissa is the rightmost of
    /// them and no table on the certificate line was needed.
    bool accounted = false;
    RingWindingGuess next;          ///< continuation data for the next point
};

/// True when the fast path applies: one leader (the ring's modes are P - zeta Q).
bool ring_winding_applies(const Linearisation& lin);

/// The ring's counts, verdict and spectral abscissa from winding tables (cost independent of N).
///
/// Verdict (sigma = 0, the axis table): finite N, unstable = sum over m = 1..N-1 of Z(2 pi m / N)
/// (one sum over the intervals between crossing angles) plus mode 0's count, which is
/// Z(0+) less the trivial branch when it bends right; roots within marginal_band of the axis are
/// marginal and not unstable, as on the per-mode path: a mode within band / |re_rate| of a
/// crossing angle, and the smallest wave numbers theta on the branch through the trivial root,
/// whose real part is c_k w^k / (2 D(0)^2 Gamma'(0)), w = theta / |Gamma'(0)| (the series of
/// string_stability.hpp). N = inf: unstable when an interval of angles wider than the marginal
/// windows at its ends has Z > 0, or the trivial branch bends right (c_k / Gamma'(0) > 0);
/// then the abscissa is the sup over theta, else 0 (approached as theta -> 0).
/// Abscissa: Newton from `guess` (a previous point's result.next) on the last mode and its
/// neighbours (N <= 64), or on the maximum of Re lambda on the level curve |Gamma(lambda)| = 1
/// (log|Gamma| = 0, Im Gamma'/Gamma = 0) and the two modes nearest its angle; certified by one
/// table on Re lambda = Re z + 1e-10 max(1, |z|) counting no root in any mode. Without a guess,
/// or when that count is not 0, the abscissa is bracketed by bisection on the counts (Newton
/// from the crossings once the bracket is narrow; the bracket itself, 1e-10 wide, otherwise).
/// When the certified line lies left of -1e-12 max(1, r(0)) the ring is stable without the axis
/// table. For N <= 64 with a candidate clearly right of the axis (Re z > 1e-6 max(1, |z|)) the axis
/// table comes first: when every mode's count Z_m(0) (mode 0 without its trivial root; no crossing
/// whose marginal window holds a mode) is matched by Z_m distinct Newton roots with
/// Re > 1e-6 max(1, |z|), seeded by the candidate and by the crossings whose branches move right
/// towards the mode's angle (and the branch through the trivial root when it bends right), those
/// are all the roots right of the axis and the rightmost of them
/// is the abscissa (RingWindingResult::accounted; one table instead of two); otherwise the
/// certificate table follows as above.
/// std::invalid_argument when cars is not >= 2 or 0, or the law has more than one leader.
RingWindingResult analyse_ring_winding(const Linearisation& lin, int cars, const RingWindingOptions& options = {},
                                       const RingWindingGuess& guess = {});

}  // namespace ddemap
