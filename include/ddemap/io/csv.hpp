#pragma once
/// \file writers.hpp
/// CSV writers (formatting only): every double in the shortest form that reads back exactly.

#include <string>

#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
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

/// The shortest decimal that reads back to the same double (std::to_chars: 0.45, not
/// 0.45000000000000001); a non-finite value is an internal error (std::logic_error): no NaN or inf is ever written
std::string format_exact(double v);

/// One row per grid point: the two axis parameters by name, spectral_abscissa, unstable_roots,
/// sup_gamma, omega_peak, plant_stable, ring_stable, string_stable, abscissa_mode,
/// plant_abscissa, lowfreq_margin, peak_gain, certified.
std::string sweep_csv(const SweepResult& sweep);

/// One row per curve point: branch, kind (hopf|string), subkind (plant|ring|lowfreq|peak),
/// mode (empty unless ring), the two parameters by name, omega.
std::string boundary_csv(const SweepSpec& spec, const BoundarySet& set);

/// Quotes a CSV field if needed.
std::string csv_field(const std::string& s);

/// An equilibrium branch, one row per point and per special point:
/// kind (point|fold|hopf),PARAMETER,<variables>,abscissa,unstable,stable,omega,status
/// (abscissa, unstable, stable empty on special rows; omega only on hopf rows).
std::string equilibrium_branch_csv(const EquilibriumBranch& b, const std::vector<std::string>& variables);

/// kind,PAR,period,stable,trivial_distance,max_nontrivial,min_VAR..,max_VAR..: one row per orbit
/// (kind "orbit"), fold ("fold"), period doubling ("period_doubling") and torus ("torus").
std::string orbit_branch_csv(const OrbitBranch& b, const std::vector<std::string>& variables);
/// Curves of folds of periodic orbits: one row per point, curve (index), the two parameters (named),
/// period, fold_test |g|, second_distance |mu_2 - 1| (empty without multipliers), min_ and max_
/// of every variable.
std::string orbit_fold_curves_csv(const std::vector<OrbitFoldCurve>& curves, const std::vector<std::string>& variables);

/// re,im,residual,newton_step
std::string roots_csv(const std::vector<Root>& roots);
/// mode,theta,re,im,residual,newton_step (mode empty for N = inf)
std::string ring_roots_csv(const RingResult& r);
/// plant_stable,plant_abscissa,sup_gamma,omega_peak,peak_margin,lowfreq_margin,string_stable
/// [,ring,ring_stable,spectral_abscissa]
std::string string_csv(const StringResult& s, const RingResult* ring);
/// Two rows, `car` and `design`: the free parameters, the objective, the attenuation margin,
/// sup |Gamma|, ||h||_1 and the verdicts (columns point, the free names, objective, ...).
std::string design_csv(const DesignResult& r);
/// name,k1,k2,th,tau,eta,plant_stable,ring_stable,string_stable,sup_gamma,omega_peak,
/// lowfreq_margin,spectral_abscissa,plant_abscissa
std::string classification_csv(const std::vector<Classification>& rows);
/// time_s,car,position_m,speed_mps,gap_m (car 0 = lead, no gap); calibrate and --lead read it back
/// (read_trace_csv with a follower, LeadProfile::from_csv with a car)
std::string simulation_csv(const SimResult& r);
/// name,position,speed_drop,amplification,min_gap,failure
std::string growth_csv(const std::vector<GrowthResult>& g);
/// name,k1,k2,th,tau,eta,rmse_speed,rmse_gap,train_rmse_speed,train_rmse_gap,test_rmse_speed,
/// test_rmse_gap,naive_rmse_speed,status, the 15 covariance columns cov_k1_k1 .. cov_eta_eta,
/// then the bounds of the fit, lo_k1,hi_k1 .. lo_eta,hi_eta (options.bound(NAME)); a vehicle
/// table for read_vehicles_csv, which reads the covariance and the bounds back.
std::string calibration_csv(const std::vector<std::string>& names, const std::vector<CalibrationResult>& fits,
                            const CalibrationOptions& options);
/// p,x_cars,spectral_abscissa,spectral_abscissa_min,spectral_abscissa_max,speed,ring_stable,
/// unstable_roots,arrangements,max_residual,status
std::string mix_csv(const std::vector<MixPoint>& points);

}  // namespace ddemap
