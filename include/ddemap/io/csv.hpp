#pragma once
/// \file writers.hpp
/// CSV writers (formatting only): every double in the shortest form that reads back exactly;
/// every column that holds a quantity with a unit carries it (core/units.hpp: `gap_m`,
/// `omega_peak_rad_per_s`; time in seconds, for a system of one's own its time unit).

#include <map>
#include <string>

#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/study/sweep.hpp"

namespace ddemap {

struct DesignResult;

/// The units of named quantities (variables and parameters of a nonlinear system, e.g.
/// {"headway", "m"}): the nonlinear writers add them to their column names; a name without an
/// entry gets no unit.
using ColumnUnits = std::map<std::string, std::string>;

/// The shortest decimal that reads back to the same double (std::to_chars: 0.45, not
/// 0.45000000000000001); a non-finite value is an internal error (std::logic_error): no NaN or inf is ever written
std::string format_exact(double v);

/// One row per grid point: the two axis parameters by name with unit (k1_per_s2),
/// spectral_abscissa_per_s, unstable_roots, sup_gamma, omega_peak_rad_per_s, plant_stable,
/// ring_stable, string_stable, abscissa_mode, plant_abscissa_per_s, lowfreq_margin, peak_gain,
/// certified.
std::string sweep_csv(const SweepResult& sweep);

/// One row per curve point: branch, kind (hopf|string), subkind (plant|ring|lowfreq|peak),
/// mode (empty unless ring), the two parameters by name with unit, omega_rad_per_s.
std::string boundary_csv(const SweepSpec& spec, const BoundarySet& set);

/// Quotes a CSV field if needed.
std::string csv_field(const std::string& s);
/// The CSV column of a named quantity: csv_field(name + the suffix of its unit), the unit looked
/// up in `units` under `key` (default: the name itself; `min_h0` takes the unit of `h0`).
std::string named_column(const std::string& name, const ColumnUnits& units, const std::string& key = "");

/// An equilibrium branch, one row per point and per special point:
/// kind (point|fold|hopf),PARAMETER,<variables>,abscissa_per_s,unstable,stable,omega_rad_per_s,status
/// (abscissa, unstable, stable empty on special rows; omega only on hopf rows); names with
/// their units from `units`.
std::string equilibrium_branch_csv(const EquilibriumBranch& b, const std::vector<std::string>& variables, const ColumnUnits& units = {});

/// Fold curves, one row per curve point, cusp, Bogdanov-Takens and zero-Hopf point:
/// curve,kind (point|cusp|bogdanov_takens|zero_hopf),PAR,PAR2,<variables>,cusp_test,bt_test,
/// unstable,omega_rad_per_s,residual,status (names with their units from `units`; the tests and
/// the count on points, omega on zero_hopf rows, status on special rows).
std::string fold_curves_csv(const FoldCurves& c, const std::string& parameter2, const std::vector<std::string>& variables,
                            const ColumnUnits& units = {});

/// kind,PAR,period_s,stable,trivial_distance,max_nontrivial,min_VAR..,max_VAR..: one row per orbit
/// (kind "orbit"), fold ("fold"), period doubling ("period_doubling") and torus ("torus"); names
/// with their units from `units`.
std::string orbit_branch_csv(const OrbitBranch& b, const std::vector<std::string>& variables, const ColumnUnits& units = {});
/// Curves of folds of periodic orbits: one row per point, curve (index), the two parameters (named),
/// period_s, fold_test |g|, second_distance |mu_2 - 1| (empty without multipliers), on torus
/// curves rotation_rad (phi of the multipliers e^{+-i phi}), min_ and max_ of every variable; names
/// with their units from `units`.
std::string orbit_fold_curves_csv(const std::vector<OrbitFoldCurve>& curves, const std::vector<std::string>& variables,
                                  const ColumnUnits& units = {});

/// re_per_s,im_rad_per_s,residual,newton_step_per_s
std::string roots_csv(const std::vector<Root>& roots);
/// mode,theta_rad,re_per_s,im_rad_per_s,residual,newton_step_per_s (mode empty for N = inf)
std::string ring_roots_csv(const RingResult& r);
/// plant_stable,plant_abscissa_per_s,sup_gamma,omega_peak_rad_per_s,peak_margin,lowfreq_margin,
/// string_stable[,ring,ring_stable,spectral_abscissa_per_s][,peak_verdict,peak_norm,peak_norm_error]
std::string string_csv(const StringResult& s, const RingResult* ring);
/// Two rows, `car` and `design`: the free parameters, the objective, the attenuation margin,
/// sup |Gamma|, ||h||_1 and the verdicts (columns point, the free names, objective, ...).
std::string design_csv(const DesignResult& r);
/// name,k1_per_s2,k2_per_s,th_s,tau_s,eta_m,plant_stable,ring_stable,string_stable,sup_gamma,
/// omega_peak_rad_per_s,lowfreq_margin,spectral_abscissa_per_s,plant_abscissa_per_s,
/// attenuation_margin_s (then the uncertainty and peak columns when there are any)
std::string classification_csv(const std::vector<Classification>& rows);
/// time_s,car,position_m,speed_mps,gap_m (car 0 = lead, no gap); calibrate and --lead read it back
/// (read_trace_csv with a follower, LeadProfile::from_csv with a car)
std::string simulation_csv(const SimResult& r);
/// name,position,speed_drop_mps,amplification,min_gap_m,failure
std::string growth_csv(const std::vector<GrowthResult>& g);
/// name,k1_per_s2,k2_per_s,th_s,tau_s,eta_m,rmse_speed_mps,rmse_gap_m,train_rmse_speed_mps,
/// train_rmse_gap_m,test_rmse_speed_mps,test_rmse_gap_m,naive_rmse_speed_mps,status, the 15
/// covariance columns cov_k1_k1 .. cov_eta_eta (in the products of the two parameters' units),
/// then the bounds of the fit, lo_k1_per_s2,hi_k1_per_s2 .. lo_eta_m,hi_eta_m
/// (options.bound(NAME)); a car table for read_car_table, which reads the parameters, the
/// covariance and the bounds back.
std::string calibration_csv(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits,
                            const CalibrationOptions& options);
/// p,x_cars,spectral_abscissa_per_s,spectral_abscissa_min_per_s,spectral_abscissa_max_per_s,
/// speed_mps,ring_stable,unstable_roots,arrangements,max_residual,status
std::string mix_csv(const std::vector<MixPoint>& points);

}  // namespace ddemap
