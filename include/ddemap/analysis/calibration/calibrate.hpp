#pragma once
/// \file calibrate.hpp
/// Calibration of OVRV with sensing delay from a measured car-following trace (the seed paper's
/// eq. 7, docs/mathematics.md section 10): the follower is simulated from the measured history on
/// [t_a, t_a + tau_max] (tau_max: the upper bound of tau; a start that does not move with tau
/// keeps the objective smooth in tau; its speed and gap a quadratic least-squares fit to the data
/// on [t_a, t_a + tau_max + 2 s], so that their noise is not an initial error the parameters
/// bend to follow), driven by the measured lead speed, and the sum of
/// squares of the residuals at the samples after t_a + tau_max
///     r_j = ( v(t_j) - v_m(t_j),  sqrt(w_gap) (s(t_j) - s_m(t_j)) )
/// (objective = MSE(speed) + w_gap MSE(gap)) is minimised over theta = (k1, k2, th, tau, eta)
/// within bounds by a bounded Levenberg-Marquardt method with exact derivatives (the forward
/// sensitivity equations of the DDE, integrated alongside the state), started from the best
/// points of a Latin-hypercube design over the bounds. Every fit comes with a covariance
/// corrected for correlated residuals (Newey-West), 95 % intervals, correlations, optional
/// profile likelihoods and warnings.
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include <Eigen/Dense>

#include "ddemap/core/parameters.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

/// A measured trace: columns time_s, lead_speed_mps, follower_speed_mps, gap_m.
struct Trace {
    std::string source;
    std::vector<double> t, lead, speed, gap;
};

/// Reads a trace; errors name the source, the line and the column (non-finite values, unsorted
/// or repeated times, fewer than 100 rows or less than 20 s). The text may also be simulate's
/// platoon CSV (is_platoon_csv()): `follower` (1..N) picks the follower, car follower - 1 being its
/// lead; 0 takes the only follower of a platoon of one (a larger platoon asks for a follower).
Trace read_trace_csv(const std::string& text, const std::string& source, int follower = 0);
/// Every trace of a CSV text: the trace itself, or of simulate's platoon CSV every follower (or
/// only `follower`, 1..N, when it is not 0), each with source "SOURCE:K". `follower` != 0 with a
/// plain trace is an error.
std::vector<Trace> read_traces_csv(const std::string& text, const std::string& source, int follower = 0);
/// Follower `follower` (1..N) of a platoon read back from simulate's CSV, as a trace whose
/// source is "SOURCE:FOLLOWER" (the checks of read_trace_csv apply).
Trace platoon_trace(const PlatoonSeries& platoon, int follower);

/// The spread of white noise on the trace's lead speed [m/s] from the samples with times in
/// [t_a, t_b]: sigma = 1.4826 median_k |d_k| / sqrt(1 + a_k^2 + b_k^2), with d_k = v_k - a_k v_(k-1)
/// - b_k v_(k+1) the residual of linear interpolation between the neighbours (a_k + b_k = 1; for
/// white noise of spread sigma, d_k has spread sigma sqrt(1 + a_k^2 + b_k^2); the smooth signal
/// leaves h^2 v''/2 in it: 0.0005 m/s at 10 Hz and a jerk of 0.1 m/s^3). 0 when fewer than 10 samples.
double lead_noise_estimate(const Trace& trace, double t_a = -1e300, double t_b = 1e300);

/// The calibrated parameters, in order: k1, k2, th, tau, eta.
const std::vector<std::string>& calibration_parameter_names();
/// The paper's bounds: k1, k2 in [0, 1], th in [0, 3], tau in [0, 1], eta in [5, 15].
ParameterBounds paper_calibration_bounds();

/// theta = (k1, k2, th, tau, eta) as a vector (the order of calibration_parameter_names()).
using CalibrationVector = Eigen::Matrix<double, 5, 1>;
using CalibrationMatrix = Eigen::Matrix<double, 5, 5>;

struct CalibrationOptions {
    /// Bounds by name for k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]: the paper's by default
    /// (paper_calibration_bounds()). A parameter not listed keeps the paper's bounds; lower = upper
    /// fixes it. validate() rejects unknown names, repeats, non-finite bounds, lower > upper,
    /// lower < 0 and tau above 5 s, naming the parameter.
    ParameterBounds bounds = paper_calibration_bounds();
    /// The bounds in force for `name` (listed, else the paper's; std::invalid_argument for a name
    /// that is not an OVRV calibration parameter).
    BoundedParameter bound(const std::string& name) const;
    /// Sets the bounds of one parameter (replacing a listed entry or adding one); checked by validate().
    void set_bounds(const std::string& name, double lower, double upper);
    double train_start = -1.0, train_end = -1.0;  ///< training window [s]; negative: whole file
    /// objective = MSE(speed) + gap_weight * MSE(gap) [1/s^2]. 0 is the paper's speed-only
    /// objective; the default 0.02 lets the measured gap pin th and eta (see README).
    double gap_weight = 0.02;
    /// Space-filling design: `design_points` points of a Latin hypercube over the bounds (fixed
    /// `seed`) are scored by the objective; Levenberg-Marquardt starts from the best `starts`
    /// of them (the centre of the box is always one of the design points). 6 starts: on the 12
    /// OpenACC traces other seeds then reach the same objective to 1e-5 (with 2 starts they
    /// differed by up to 0.2 %); on synthetic traces one start usually suffices.
    /// Called after every design point and every Levenberg-Marquardt iteration (on any thread,
    /// may be empty) with (done, total) of that stage; a callback that throws stops the fit and
    /// its exception propagates (how a caller cancels a long fit, e.g. on Ctrl-C).
    Progress progress;
    int design_points = 64;
    int starts = 6;
    unsigned seed = 1;
    int max_iterations = 50;   ///< Levenberg-Marquardt iterations per start
    /// Convergence: the scaled projected gradient |P(z - g) - z|_inf <= gradient_tolerance, or a
    /// relative decrease of the objective below function_tolerance, or a scaled step below
    /// step_tolerance (z: parameters scaled to [0, 1] by their bounds).
    double gradient_tolerance = 1e-10, function_tolerance = 1e-9, step_tolerance = 1e-9;
    /// Profile likelihoods on request: for each name listed (e.g. "tau", "th") the objective
    /// minimised over the other free parameters at `profile_points` values of that one: an even
    /// grid over theta_i -+ 4 standard errors within the bounds (the whole bounds when the
    /// standard error is not finite), each point started from its neighbour's solution.
    std::vector<std::string> profile;
    int profile_points = 21;
    double step = 0.05;  ///< largest integration step [s]
    /// Noise on the measured lead speed [m/s] (errors in variables, docs/mathematics.md
    /// section 10): the lead speed drives the simulation, so its noise reaches the residuals
    /// filtered by the car, correlated over the car's time constants, and the gap integrates it.
    /// The covariance adds that part exactly under white lead noise of this level (a Monte
    /// Carlo over `lead_noise_draws` draws at the fit, fixed seed: the scores' covariance
    /// J^T B Sigma_e B^T J in place of what the Newey-West sum makes of it). Negative (the
    /// default): the level is estimated from the lead speed itself (its second differences,
    /// robustly); 0: the lead speed is taken as exact.
    double lead_noise = -1.0;
    int lead_noise_draws = 200;  ///< Monte Carlo draws of the lead noise (20 to 100000)
    /// Corrects the bias the lead speed's noise puts into the fit (corrected least squares,
    /// docs/mathematics.md section 10): the model is linear in the lead speed, so white lead
    /// noise of level sigma adds to the expected objective the penalty
    ///     P(theta) = sigma^2 sum_l N_l (g_v(l)^2 + w_gap g_s(l)^2)
    /// (g_v, g_s: the follower's speed and gap response to a unit change of one lead sample, at
    /// lag l samples; N_l: the residual samples l or more after the first), which grows with
    /// the car's responsiveness and pulls the least-squares fit towards sluggish gains (a car
    /// with k2 = 0.95, tau = 0.15 s fitted k2 = 0.73, tau = 0.05 s from 0.05 m/s of lead noise).
    /// The fit minimises |r|^2 - P(theta) instead (Gauss-Newton with the corrected normal
    /// matrix J^T J - J_P^T J_P), whose expectation is the objective of an exact lead. Needs
    /// evenly sampled runs (else a warning and no correction); no effect with lead_noise = 0.
    bool lead_noise_correction = true;
    /// True when validate() would not throw.
    bool is_valid() const;
    /// Throws std::invalid_argument naming the offending option.
    void validate() const;
};

struct FitErrors {
    double rmse_speed = 0.0;  ///< [m/s]
    double rmse_gap = 0.0;    ///< [m]
    int samples = 0;
};

/// One fitted run simulated over its whole file with given parameters (history on
/// [t_0, t_0 + tau]), and the naive predictor v(t) = v_lead(t - d) (best constant d in [0, 5] s
/// on a 0.1 s grid) on the same samples: a training run's fit, or a test run's prediction.
struct FitEvaluation {
    FitErrors errors;                        ///< the model's speed and gap RMSE [m/s, m]
    FitErrors naive;                         ///< the naive predictor's speed RMSE
    double naive_delay = 0.0;                ///< its d [s]
    std::vector<double> sim_speed, sim_gap;  ///< the simulation at the trace's times
};

/// One calibrated parameter with its uncertainty.
struct ParameterEstimate {
    std::string name;
    double value = 0.0;
    /// sqrt of the corrected covariance's diagonal (0 for a fixed parameter; inf when the
    /// trace does not determine it)
    double standard_error = 0.0;
    /// value -+ q standard_error, q = CalibrationResult::critical_value (not clipped to the bounds)
    double lower95 = 0.0, upper95 = 0.0;
    bool fixed = false;                    ///< lower bound = upper bound
    bool at_bound = false;                 ///< on (within 1e-6 of the width of) a bound
};

/// Objective minimised over the other free parameters with one parameter held at each value.
struct ProfileLikelihood {
    std::string parameter;
    std::vector<double> values, objective;
    /// {theta_i : n (objective - objective_min) <= q^2 sigma^2 c_i} where n = samples, q = the critical value,
    /// sigma^2 = the residual variance and c_i = the parameter's corrected over uncorrected
    /// variance; an end that reaches the profiled range is `open`.
    double lower95 = 0.0, upper95 = 0.0;
    bool lower_open = false, upper_open = false;
};

struct CalibrationResult {
    ParameterMap parameters;     ///< k1, k2, th, tau, eta
    double k1 = 0.0, k2 = 0.0, th = 0.0, tau = 0.0, eta = 0.0;  ///< the same values, direct
    /// per parameter, in the order k1, k2, th, tau, eta: value, standard error, 95 % interval
    std::array<ParameterEstimate, 5> estimates;
    /// Covariance of theta (order k1, k2, th, tau, eta) corrected for correlated residuals:
    ///     C = H^-1 Omega H^-1,  H = J^T J,  Omega = sum_{|l| <= L} (1 - |l|/(L+1)) sum_t g_t g_{t-l}^T
    /// with the scores g_t = J_t^T r_t of sample t (Newey-West, Bartlett weights), the bandwidth L
    /// from the residual autocorrelation. Rows and columns of fixed parameters are zero.
    CalibrationMatrix covariance = CalibrationMatrix::Zero();
    /// The textbook sigma^2 (J^T J)^-1, sigma^2 = SSR / (m - p): valid only for independent
    /// residuals (kept for comparison; too small for 10 Hz data).
    CalibrationMatrix covariance_independent = CalibrationMatrix::Zero();
    /// The covariance as it would be with the lead speed taken as exact (the Newey-West sandwich
    /// alone); `covariance` adds the lead noise's share (equal when lead_noise is 0).
    CalibrationMatrix covariance_exact_lead = CalibrationMatrix::Zero();
    /// The level of white noise on the lead speed that the covariance allows for [m/s], per run
    /// (given, or estimated from the run's lead speed: 1.4826 median |d_k| / sqrt(1 + a_k^2 + b_k^2)
    /// over the residuals d_k = v_k - a_k v_(k-1) - b_k v_(k+1) of linear interpolation between
    /// neighbours)
    std::vector<double> lead_noise;
    /// true when the fit corrected the lead noise's bias (CalibrationOptions::lead_noise_correction,
    /// some run with lead noise, all runs evenly sampled): the parameters minimise |r|^2 - P(theta),
    /// the covariance uses the corrected normal matrix
    bool lead_noise_corrected = false;
    CalibrationMatrix correlation = CalibrationMatrix::Identity();  ///< of `covariance`
    int bandwidth = 0;                ///< L [samples]: 5 times the lag where the residuals' autocorrelation falls below 0.05, at most n/4
    /// q of the 95 % intervals: the fixed-b critical value of the Bartlett-HAC t-statistic,
    /// q = 1.96 + 2.9694 b + 0.4160 b^2 - 0.5324 b^3, b = L / n (Kiefer & Vogelsang 2005)
    double critical_value = 1.96;
    double effective_samples = 0.0;   ///< n / (1 + 2 sum_l (1 - l/(L+1)) rho_l) of the speed residuals
    double condition_number = 0.0;    ///< of J^T J with unit-scaled columns (free parameters)
    std::vector<ProfileLikelihood> profiles;  ///< one per CalibrationOptions::profile name
    /// Plain-text warnings: a parameter on a bound, a parameter (or combination) the trace does
    /// not determine, a model no better than the naive delayed-lead predictor, non-convergence.
    std::vector<std::string> warnings;
    /// train: the fitted samples, simulated as the objective does (from t_a + tau_max); all: the
    /// whole file simulated from its start (history on [t_0, t_0 + tau]); test: the file outside
    /// the training window, each piece simulated from its own start (samples 0 if none)
    FitErrors train, test, all;
    FitErrors naive;             ///< v_follower(t) = v_lead(t - d) with the best constant d
    double naive_delay = 0.0;
    double rmse_speed = 0.0, rmse_gap = 0.0;  ///< = all: the whole-file simulation [m/s, m]
    double naive_rmse_speed = 0.0;            ///< = naive.rmse_speed, the same samples as all
    double objective = 0.0;      ///< MSE(speed) + gap_weight MSE(gap) on the training samples
    /// what the fit minimised, per sample: `objective`, less P(theta) / n when the lead noise's
    /// bias is corrected (lead_noise_corrected); the profiles are of this objective
    double minimised_objective = 0.0;
    int starts = 0;              ///< Levenberg-Marquardt starts
    int evaluations = 0;         ///< simulations (with or without sensitivities)
    int jacobian_evaluations = 0;  ///< of which with sensitivities
    Status status_code = Status::Converged;  ///< of the best start
    std::string status;          ///< to_string(status_code)
    std::string message;         ///< why the best start stopped
    double seconds = 0.0;
    std::vector<double> sim_speed, sim_gap;  ///< whole-file simulation at the trace's times (single-run fits)
    /// per fitted run (one for `calibrate`, one per run for `calibrate_joint`): its whole-file
    /// simulation, errors and naive predictor; `all` pools them (RMSE over all samples)
    std::vector<FitEvaluation> runs;
};

CalibrationResult calibrate(const Trace& trace, const CalibrationOptions& options = {});

/// One parameter set fitted to several runs of the same car: the residuals of every run
/// (each simulated from its own measured history and driven by its own lead, on the same
/// training window `train_start:train_end` if one is set) stacked into one least-squares
/// problem, objective = (sum over runs of the squared residuals) / (all samples). The
/// covariance is C = H^-1 (sum_runs Omega_run) H^-1 with each run's Newey-West Omega_run
/// computed on that run's own scores and bandwidth (no lags across runs: runs are independent),
/// the critical value from the largest b = L / n over the runs. train and all pool the runs;
/// test is empty (test runs are evaluated with evaluate_fit); naive uses one delay for all
/// runs. std::invalid_argument when `runs` is empty or a window does not fit a run.
CalibrationResult calibrate_joint(const std::vector<Trace>& runs, const CalibrationOptions& options = {});

/// calibrate() for every trace, in parallel over the traces under `policy`; the results are in
/// the traces' order. The error of the lowest failing trace is rethrown after the loop.
std::vector<CalibrationResult> calibrate_many(const std::vector<Trace>& traces, const CalibrationOptions& options,
                                             const ExecutionPolicy& policy = {});
/// A car of a calibration study (the seed paper's Tables 1 and 2): one parameter set fitted to
/// its training runs (calibrate for one run, calibrate_joint for several) and tested on its
/// other runs, each labelled with its test type (e.g. "oscillatory", "dips", "handling").
struct CarRuns {
    std::string car;
    std::vector<Trace> train, test;
    std::vector<std::string> test_types;  ///< one per test run
};

/// A test run simulated over its whole file with the car's fitted parameters.
struct TestRun {
    std::string source, type;
    FitEvaluation evaluation;
};

struct CarCalibration {
    std::string car;
    std::vector<std::string> train_sources;
    CalibrationResult fit;
    std::vector<TestRun> tests;  ///< in the order of CarRuns::test
};

/// Called after each car is done (one call at a time, in the order the cars finish): the car's
/// result, how many cars are done and how many there are.
using CarFinished = std::function<void(const CarCalibration& car, long done, long total)>;

/// Fits every car (in parallel over the cars under `policy`; `policy.progress` and `finished`
/// after each car) and evaluates its test runs. std::invalid_argument for a car without
/// training runs or with test_types not one per test run (naming the car); a fit's own errors
/// as in calibrate.
std::vector<CarCalibration> calibrate_cars(const std::vector<CarRuns>& cars, const CalibrationOptions& options,
                                           const ExecutionPolicy& policy = {}, const CarFinished& finished = {});

/// The objective `calibrate` minimises, at given parameters (k1, k2, th, tau, eta, each inside
/// or outside the bounds): MSE(speed) + gap_weight MSE(gap) over the training samples at or
/// after t_a + tau_max (tau_max: the upper bound of tau), so fits and other candidates (e.g.
/// the true parameters of a synthetic trace) compare on the same samples.
double calibration_objective(const Trace& trace, const ParameterMap& parameters, const CalibrationOptions& options = {});
/// The lead noise's expected share of calibration_objective at given parameters, P(theta) / n
/// (CalibrationOptions::lead_noise_correction): for white noise e of level sigma on the lead
/// speed, E[objective(lead + e)] = objective(lead) + P(theta) / n. sigma is options.lead_noise,
/// or estimated from the trace when negative; 0 when sigma is 0 or the samples are uneven.
double lead_noise_penalty(const Trace& trace, const ParameterMap& parameters, const CalibrationOptions& options = {});
/// The objective `calibrate_joint` minimises: the runs' squared residuals summed over all runs,
/// divided by the number of samples of all runs.
double calibration_objective(const std::vector<Trace>& runs, const ParameterMap& parameters, const CalibrationOptions& options = {});

/// The whole-file simulation of `trace` with `parameters` (k1, k2, th, tau, eta), its errors
/// and the naive predictor on the same samples (t >= t_0 + tau).
FitEvaluation evaluate_fit(const Trace& trace, const ParameterMap& parameters, double step = 0.05);

/// Simulates the follower over [t_a, t_b] of the trace (history from the data on
/// [t_a, t_a + tau]); speed and gap at the trace's sample times in the window (data values
/// before t_a + tau). A car at standstill does not roll backwards (v' = 0 when v <= 0 and
/// F < 0).
void simulate_follower(const Trace& trace, const ParameterMap& ovrv, double t_a, double t_b, double step,
                       std::vector<double>& speed, std::vector<double>& gap);

/// The simulated follower at the trace's samples in [t_a, t_b] and, on request, its exact
/// derivatives with respect to theta = (k1, k2, th, tau, eta): the forward sensitivities
/// S = d(s, v)/d theta, integrated with the state (RK4, Hermite history),
///     S_s' = -S_v,
///     S_v' = k1 (dsd - th S_v) - k2 S_v + dF/dtheta (explicit),
/// where sd = s(t - tau) and dsd = S_s(t - tau) (zero on the data history), plus for tau
///     d sd/d tau = S_s,tau(t - tau) - s'(t - tau),  d v_l(t - tau)/d tau = -v_l'(t - tau),
/// The simulation starts at t0 = max(t_start, t_a + tau) from the data (the data are the history
/// for t <= t0). With t_start >= t_a + tau_max (as `calibrate` does) t0 does not depend on theta;
/// otherwise t0 = t_a + tau moves with tau: S_tau(t0) = x_data'(t0) - x'(t0), and where t0 is a
/// sample time the trajectory has a kink in tau (the sensitivities give the right derivative).
struct FollowerTrajectory {
    std::vector<double> time, speed, gap;  ///< at the samples in [t_a, t_b]
    Eigen::MatrixXd dspeed, dgap;          ///< rows: samples, columns: theta (empty unless asked)
};
FollowerTrajectory simulate_follower(const Trace& trace, const CalibrationVector& theta, double t_a, double t_b, double step,
                                     bool sensitivities, double t_start = -1e300);

}  // namespace ddemap
