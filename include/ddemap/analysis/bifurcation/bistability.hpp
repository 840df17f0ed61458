#pragma once
/// \file bistability.hpp
/// Where stable periodic orbits (stop-and-go waves) coexist with a stable equilibrium (uniform
/// flow), in two parameters (p1, p2) over a box [from, to] x [from2, to2].
///
/// The region is bounded by curves along which the number or the stability of equilibria and
/// orbits changes: the Hopf curves (hopf_curves, with their generalised Hopf points where the
/// criticality changes) and the curves of folds of periodic orbits (orbit_fold_curve). The chart:
///  1. the Hopf curves through the Hopf points of the equilibrium branch in p1 at the held p2;
///  2. the orbit branches in p1 from every Hopf point at the held p2, and the fold curve through
///     every fold on them (without the Floquet multipliers of its points: |g| certifies them; its
///     steps in units of max(1, max |guess|), the state's size); and the fold curves born at the
///     generalised Hopf points: where L2 != 0 a curve of folds of orbits starts at the point, on
///     the side of the Hopf curve where L1 L2 < 0, in a band along it as thin as L1^2 / (4 L2) that
///     slices rarely meet. From the Hopf curve's points on that side (nearest first, at least 1 %
///     of the box away, up to 3), the orbit branch from the Hopf point there (at most 150 orbits)
///     and the curves through its folds (its first fold must lie in the box); none found where
///     the Hopf curve goes on beyond the point: undecided;
///  3. the cells: the box cut by these curves. Each of `rows` horizontal lines p2 = const is cut at
///     the curves' crossings into intervals (linear between a fold curve's points; a Hopf curve's
///     crossing corrected onto the curve by Newton, since a chord is off it by more than such a
///     band is wide; a fold curve's end at a generalised Hopf point joined to the point);
///     intervals of neighbouring lines that overlap, or lie between the same two curves, belong
///     to one cell (union-find) when they lie on the same side of every curve (the parity of its
///     crossings left of them, a curve that leaves through the left face continued along its last
///     step: two curves crossing between the lines separate the pieces, and so does a curve's end
///     inside the box for the pieces right of it, which may cut a region into two cells, never
///     join two); a fold curve's end where its orbits shrink away from a located generalised
///     Hopf point: undecided;
///  4. one verdict per cell, at the middle of its widest interval, from a one-parameter slice at
///     that p2: the equilibrium branch in p1 (stable there: a piece of the branch over that p1
///     stable, between two branch points or a branch point and the Hopf point or fold next to it)
///     and the orbit branches from its Hopf points, followed in p1 beyond the box by half
///     its width on either side (a branch may leave the box and come back after a fold outside
///     it; a failure outside the box leaves the slice decided), a stable orbit there: a piece of a
///     branch over p1, between two orbits or an orbit and the Hopf point, fold, period doubling
///     or torus next to it, with its orbits stable. Inside a cell nothing
///     changes (no curve crosses it), so one point decides it; a fold or a Hopf point met on a
///     slice that lies on no traced curve (more than 1 % of the box from each) is traced too and
///     the cells are cut again (up to 4 rounds), so that a curve that misses the held p2 is found
///     when a slice meets it.
/// Orbits that are born at no Hopf point of a slice (isolas) are not seen; period doublings and
/// tori change the orbits' stability along curves that are not traced: a cell crossed by one
/// has orbits of two stabilities, seen only at its representative point.
/// The system's parameter p2 is changed during the call and restored before it returns.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

struct BistabilityOptions {
    std::string parameter;   ///< p1 (the slices' parameter)
    double from = 0.0, to = 1.0;
    std::string parameter2;  ///< p2; its value in the system must lie in [from2, to2]
    double from2 = 0.0, to2 = 1.0;
    int degree = 4, intervals = 40;  ///< the orbits' mesh
    /// orbits per branch; points of a Hopf or fold curve in each direction
    int max_points = 400;
    int rows = 200;          ///< horizontal lines that cut the box into cells (>= 4)
    /// After each stage (the Hopf curves, each orbit branch, fold curve and cell slice):
    /// (stages done, an upper bound of the stages, p1 of the stage). It may throw to stop.
    BranchProgress progress;
    /// The first equilibrium branch's EquilibriumBranchOptions::before_roots (the one at the held
    /// p2, before its roots; the slices' branches are like it): a size guard may throw there.
    std::function<void(long points, const RootWorkEstimate& one, int measured)> before_roots;
    bool is_valid(std::string* why = nullptr) const;
};

/// One cell of the box: its intervals (one or more per line), its representative point and the
/// verdict there.
struct BistabilityCell {
    struct Interval {
        double par2 = 0.0, lo = 0.0, hi = 0.0;
    };
    std::vector<Interval> intervals;  ///< by increasing par2
    double par = 0.0, par2 = 0.0;     ///< the representative point
    bool equilibrium_stable = false;
    bool stable_orbit = false;        ///< a stable periodic orbit exists at the representative point
    bool bistable = false;            ///< both
    Status status = Status::Converged;  ///< not converged: the slice there was undecided (message)
    std::string message;
};

struct BistabilityChart {
    std::string parameter, parameter2;
    double from = 0.0, to = 1.0, from2 = 0.0, to2 = 1.0;
    HopfCurves hopf;                    ///< the Hopf curves with their L1 and generalised Hopf points
    std::vector<OrbitFoldCurve> folds;  ///< the curves of folds of periodic orbits
    std::vector<BistabilityCell> cells;
    int slices = 0;                     ///< one-parameter slices computed (the held p2 included)
    int rounds = 0;                     ///< times the cells were cut (more than one: a slice found a new curve)
    /// Converged when every curve and every cell's verdict did
    Status status = Status::Converged;
    std::string message;
};

/// The chart (see the file comment). std::invalid_argument for invalid options, unknown or equal
/// parameters, p2 outside its range, or a system the Hopf and orbit computations refuse;
/// non-convergence is a status.
BistabilityChart bistability_chart(NonlinearDDE& system, const Eigen::VectorXd& guess, const BistabilityOptions& options);

}  // namespace ddemap
