#pragma once
/// \file figures.hpp
/// The figures of the studies (SVG text; formatting only): platoon speeds, disturbance growth,
/// calibration fits, the penetration-rate study, and the classification chart's spec.

#include <string>
#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/bistability.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/study/penetration.hpp"

namespace ddemap {

/// Speeds of every car over time, events marked.
std::string simulation_svg(const SimResult& r, const std::string& lead);
/// Minimum gap and amplification by position, failures marked.
std::string growth_svg(const std::vector<GrowthResult>& g, const std::string& lead);
/// Measured and simulated follower speed and gap, one pair of panels per trace.
std::string calibration_svg(const std::vector<std::string>& names, const std::vector<Trace>& traces,
                            const std::vector<CalibrationResult>& fits);
/// Spectral abscissa against the fraction of X cars (min/max over arrangements when drawn).
std::string mix_svg(const std::vector<MixPoint>& points, const MixOptions& options, const std::string& x_label,
                    const std::string& y_label);
/// The classification figure's spec: `base` (maps/classification.toml) with one panel per
/// vehicle (its 95 % (k1, k2) confidence ellipse when it carries a covariance) and the ring size
/// `cars`. With a `source` (the user's vehicle file) the title names it and the (k1, k2) window
/// is fitted to the vehicles and their ellipses; without, the base window (the paper's table).
ChartSpec classification_chart(const ChartSpec& base, const std::vector<CalibratedVehicle>& vehicles, int cars,
                               const std::string& source = "");

/// The bifurcation diagram of one parameter: the amplitude max - min of variable `variable` of
/// every orbit against the parameter (stable solid, unstable dashed), the equilibria at
/// amplitude 0 (stable solid, unstable dashed; `equilibria` may be null), Hopf points and folds
/// of orbits marked. Labels: "NAME [UNIT]" when a unit is given.
/// With `doubled` (a branch of twice the period switched onto at a period doubling of `orbits`)
/// that branch too, orange, with its folds and period doublings.
std::string bifurcation_svg(const EquilibriumBranch* equilibria, const OrbitBranch& orbits, int variable, const std::string& variable_name,
                            const std::string& variable_unit, const std::string& parameter_unit, const std::string& title,
                            const OrbitBranch* doubled = nullptr);

/// The bistability chart (analysis/bifurcation/bistability.hpp) in (p1, p2) over its box: the
/// cells shaded by their verdict (orange: a stable periodic orbit and a stable equilibrium;
/// grey: the equilibrium unstable; dark grey: undecided), the Hopf curves (red; solid where L1 <
/// 0, supercritical, dashed where L1 > 0, subcritical), the fold curves of periodic orbits (green)
/// and the generalised Hopf points (marked GH). Units in the axis labels when given.
std::string bistability_svg(const BistabilityChart& chart, const std::string& unit, const std::string& unit2, const std::string& title);

/// The two-parameter bifurcation diagram over the box [from, to] x [from2, to2] of (p1, p2): the
/// Hopf curves (`hopf`, may be null; red, solid where supercritical, dashed where subcritical,
/// grey where L1 is not decided) with their generalised Hopf (GH), double Hopf (DH) and
/// zero-Hopf (ZH) points, and the fold curves of equilibria (`folds`, may be null; blue) with their
/// cusp (CP) and Bogdanov-Takens (BT) points, and the curves of periodic orbits' folds (green),
/// period doublings (purple) and tori (brown) (`orbit_curves`, may be null) with the points where
/// they end on the orbits' shrinking marked (GH: a fold curve at a generalised Hopf point, DH: a
/// torus curve at a double Hopf point). Units in the axis labels when given.
std::string two_parameter_svg(const HopfCurves* hopf, const FoldCurves* folds, const std::string& parameter, const std::string& parameter2,
                              double from, double to, double from2, double to2, const std::string& unit, const std::string& unit2,
                              const std::string& title, const OrbitBranchCurves* orbit_curves = nullptr);

}  // namespace ddemap
