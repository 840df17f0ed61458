#pragma once
/// \file calibrate.hpp
/// Calibration of OVRV with sensing delay from a measured car-following trace (the seed paper's
/// eq. 7): the follower is simulated from the measured history on [t_a, t_a + tau], driven by
/// the measured lead speed, and the mean squared speed error (plus, optionally, a weighted
/// mean squared gap error) is minimised over (k1, k2, th, tau, eta) within bounds; NLopt's
/// DIRECT-L does the global search, BOBYQA the local polish.

#include <string>
#include <vector>

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

struct CalibrationOptions {
    /// bounds for k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]: the paper's by default
    double lower[5] = {0.0, 0.0, 0.0, 0.0, 5.0};
    double upper[5] = {1.0, 1.0, 3.0, 1.0, 15.0};
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

/// calibrate() for every trace, in parallel over the traces (OpenMP when built with it); the
/// results are in the traces' order. The first error (by trace index) is rethrown after all
/// traces ran.
std::vector<CalibrationResult> calibrate_many(const std::vector<Trace>& traces, const CalibrationOptions& options = {});

/// Simulates the follower over [t_a, t_b] of the trace (history from the data on
/// [t_a, t_a + tau]); speed and gap at the trace's sample times in the window (data values
/// before t_a + tau). A car at standstill does not roll backwards (v' = 0 when v <= 0 and
/// F < 0).
void simulate_follower(const Trace& trace, const ParameterMap& ovrv, double t_a, double t_b, double step,
                       std::vector<double>& speed, std::vector<double>& gap);

}  // namespace ddemap
