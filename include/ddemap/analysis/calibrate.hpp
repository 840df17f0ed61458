#pragma once
/// \file calibrate.hpp
/// Calibration of OVRV with sensing delay from a measured car-following trace (the seed paper's
/// eq. 7): the follower is simulated from the measured history on [t_a, t_a + tau], driven by
/// the measured lead speed, and the mean squared speed error (plus, optionally, a weighted
/// mean squared gap error) is minimised over (k1, k2, th, tau, eta) within bounds; NLopt's
/// DIRECT-L does the global search, BOBYQA the local polish.

#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"
#include "ddemap/core/parameters.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

/// A measured trace: columns time_s, lead_speed_mps, follower_speed_mps, gap_m.
struct Trace {
    std::string source;
    std::vector<double> t, lead, speed, gap;
};

/// Reads a trace; errors name the source, the line and the column (non-finite values, unsorted
/// or repeated times, fewer than 100 rows or less than 20 s).
Trace read_trace_csv(const std::string& text, const std::string& source);

/// The calibrated parameters, in order: k1, k2, th, tau, eta.
const std::vector<std::string>& calibration_parameter_names();
/// The paper's bounds: k1, k2 in [0, 1], th in [0, 3], tau in [0, 1], eta in [5, 15].
ParameterBounds paper_calibration_bounds();

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
    int global_evaluations = 1200;
    int local_evaluations = 600;
    double step = 0.05;        ///< integration step [s]
    void validate() const;
};

struct FitErrors {
    double rmse_speed = 0.0;  ///< [m/s]
    double rmse_gap = 0.0;    ///< [m]
    int samples = 0;
};

struct CalibrationResult {
    ParameterMap parameters;     ///< k1, k2, th, tau, eta
    FitErrors train, test, all;  ///< test: the file outside the training window (samples 0 if none)
    FitErrors naive;             ///< v_follower(t) = v_lead(t - d) with the best constant d
    double naive_delay = 0.0;
    double objective = 0.0;
    int evaluations = 0;
    std::string status;          ///< NLopt's result of the local stage
    double seconds = 0.0;
    std::vector<double> sim_speed, sim_gap;  ///< whole-file simulation at the trace's times
};

CalibrationResult calibrate(const Trace& trace, const CalibrationOptions& options = {});

/// calibrate() for every trace, in parallel over the traces under `policy`; the results are in
/// the traces' order. The error of the lowest failing trace is rethrown after the loop.
std::vector<CalibrationResult> calibrate_many(const std::vector<Trace>& traces, const CalibrationOptions& options,
                                             const ExecutionPolicy& policy = {});

/// Simulates the follower over [t_a, t_b] of the trace (history from the data on
/// [t_a, t_a + tau]); speed and gap at the trace's sample times in the window (data values
/// before t_a + tau). A car at standstill does not roll backwards (v' = 0 when v <= 0 and
/// F < 0).
void simulate_follower(const Trace& trace, const ParameterMap& ovrv, double t_a, double t_b, double step,
                       std::vector<double>& speed, std::vector<double>& gap);

}  // namespace ddemap
