#pragma once
/// \file calibration_report.hpp
/// The calibration report of a study (the seed paper's Tables 1 and 2, and its Figures 3 and 4
/// for any fit): per car the fitted parameters with their 95 % intervals, the training error
/// and the test error per test type (speed and spacing RMSE of the simulated follower), as
/// CSV, JSON and Markdown; and per run a figure of the measured against the simulated speed
/// and gap over time.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"

namespace ddemap {

/// One line of a run list (CSV with columns car, file, role[, type]): a measured run of a car,
/// role "train" (fitted) or "test" (predicted), type the test type (default "test").
struct RunListEntry {
    std::string car, file, role, type;
};

/// Reads a run list; std::invalid_argument "SOURCE:LINE: ..." for an empty car or file, a role
/// other than train or test, a missing column; "SOURCE: ..." when no line is listed.
std::vector<RunListEntry> read_run_list_csv(const std::string& text, const std::string& source);

/// The cars of a run list, in order of first appearance, each with its train runs and its test
/// runs (and their types); `read(file)` reads the trace a line names. std::invalid_argument
/// "SOURCE: car 'X' has no run with role train" when a car has no train run.
std::vector<CarRuns> cars_from_run_list(const std::vector<RunListEntry>& entries, const std::function<Trace(const std::string& file)>& read,
                                        const std::string& source);

/// One row of the report: a car, its fit and its errors pooled per test type.
struct CalibrationReportRow {
    std::string car;
    std::vector<std::string> train_sources;
    const CalibrationResult* fit = nullptr;
    /// per test type of CalibrationReport::test_types: speed and gap RMSE over all the car's
    /// test runs of that type (samples 0: no run of that type)
    std::vector<FitErrors> test;
    std::vector<FitErrors> naive_test;  ///< the naive predictor on the same runs (speed only)
};

struct CalibrationReport {
    std::vector<std::string> test_types;  ///< in order of first appearance
    std::vector<CalibrationReportRow> rows;
};

/// The report of `cars` (which must outlive it). A car without test runs but with a held-out
/// part of its training file (CalibrationOptions::train_start/train_end) reports that part
/// under the test type "held out".
CalibrationReport calibration_report(const std::vector<CarCalibration>& cars);

/// One line per car: car, train_runs (sources joined by ';'), k1, k1_lo, k1_hi, ... eta_hi
/// (95 % intervals; empty where not finite), train_rmse_speed, train_rmse_gap,
/// naive_rmse_speed (the fitted runs, whole files), then per test type T
/// T_rmse_speed, T_rmse_gap, T_naive_rmse_speed, T_samples; warnings (count), status.
std::string calibration_report_csv(const CalibrationReport& report);
/// {"test_types": [...], "cars": [{"car", "train_runs", "parameters": {"k1": {"value",
/// "ci95": [lo, hi], "at_bound"}, ...}, "train": {"rmse_speed", "rmse_gap", "samples"},
/// "naive_rmse_speed", "test": {"T": {"rmse_speed", "rmse_gap", "naive_rmse_speed",
/// "samples"}, ...}, "warnings": [...], "status"}]}
std::string calibration_report_json(const CalibrationReport& report);
/// Two Markdown tables (rounded): parameters with intervals (bold: on a bound; "n.d.": the
/// interval is wider than the bounds), and speed and spacing RMSE, train and per test type
/// (the test speed RMSE next to the naive predictor's on the same runs).
std::string calibration_report_markdown(const CalibrationReport& report, const CalibrationOptions& options);

/// The fit figure of one run (the paper's Figures 3 and 4): measured lead and follower speed
/// and the simulated follower speed over time, and the measured and simulated gap; `note` one
/// line under the legend (e.g. the run's file).
std::string calibration_fit_svg(const std::string& title, const Trace& trace, const FitEvaluation& evaluation,
                                const std::string& note = {});

/// The files of a report folder (names relative to it, and contents): table.csv, table.json,
/// table.md, and one figure per training and test run, fit_CAR_FILE.svg (CAR with every
/// character but letters, digits, '-' and '.' replaced by '_'; FILE the run's file name
/// without folder and ".csv"; "CAR_" left out when `per_file`: one fit per file, named after
/// it). `results[i]` is the calibration of `cars[i]`.
std::vector<std::pair<std::string, std::string>> calibration_report_files(const std::vector<CarCalibration>& results, const std::vector<CarRuns>& cars,
                                                                          const CalibrationOptions& options, bool per_file);

}  // namespace ddemap
