#pragma once
/// \file verdict_distance.hpp
/// The distance from a car to the other L2 string verdict (VerdictDistance in
/// analysis/stability/classify.hpp): how much its parameters may change before a string-stable
/// car turns string unstable, or must change before a string-unstable one turns stable.
///
/// With x the parameters `over` (default k1, k2, th, tau of the ovrv law), x0 the car's own and
/// the weighted relative metric d(x) = sqrt(sum_j ((x_j - x0_j) / x0_j)^2):
///  * a string-stable car: the string-unstable set is the union over w >= 0 of
///    {x : g(w; x) < 0}, g = attenuation_piece(lin(x), w, 0) (the sign of 1 - |Gamma(i w)|^2,
///    of c2 at w = 0), and of {x : the plant's abscissa alpha(x) >= 0}. The distance to a union
///    is the least distance to its members: for each w of a grid (0 and 12 per decade from 1e-4
///    to 1e3 rad/s) the nearest point of {g(w; .) = 0} by the iteration
///        x_{k+1} = x0 - M^-1 grad g (g(x_k) + grad g . (x0 - x_k)) / (grad g^T M^-1 grad g),
///    M = diag(1 / x0_j^2) (the projection onto the linearised level set, which converges to
///    the nearest point of a smooth level set), the least over the grid refined by golden
///    section in log w; the same iteration on alpha(x) = 0 (gradient from the root's
///    sensitivity -dD/dx_j / D'(lambda)) for the plant.
///  * a string-unstable car: design_gains with the nearest objective, these parameters free
///    and an attenuation margin of 1 ms (the nearest string-stable point: sequential QP on
///    the pieces of mu, design.hpp).
/// Both within the box [x0_j / 10, 10 x0_j]. The point found is then certified on the segment
/// from x0: bisection on the certified verdict (analyse_string) to 1e-6 of the distance, so
/// that the verdict is the car's at (1 - 1e-6) d and the other at d (the reported distance and
/// point). The search is local: the distance is that of a certified flip, the least over the
/// pieces searched, not a proof that no nearer flip exists.

#include <string>
#include <vector>

#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/core/parameters.hpp"

namespace ddemap {

struct VerdictDistanceOptions {
    /// The parameters changed (law parameters of the model, each nonzero at the car).
    std::vector<std::string> over = {"k1", "k2", "th", "tau"};
    /// std::invalid_argument naming the first bad option.
    void validate() const;
};

/// The distance of the car `model` with `parameters` (as make_model takes them) to its other
/// L2 string verdict. Status Converged with a certified flip; otherwise the reason (no flip
/// found within the box, the car's own verdict undecided, a search that did not converge).
/// std::invalid_argument for a parameter `over` that the law lacks or that is 0 at the car.
VerdictDistance verdict_distance(const std::string& model, const ParameterMap& parameters, const VerdictDistanceOptions& options = {});

/// verdict_distance of every row's vehicle (ovrv), in parallel under `policy` (progress per car);
/// sets has_distance and distance.
void add_verdict_distances(std::vector<Classification>& rows, const VerdictDistanceOptions& options = {}, const ExecutionPolicy& policy = {});

}  // namespace ddemap
