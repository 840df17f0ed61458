#pragma once
/// \file vehicles.hpp
/// The built-in vehicle set: the seed paper's calibration table (Gunter et al., "Are
/// commercially implemented adaptive cruise control systems string stable?", table of
/// calibrated OVRV parameters; seven 2018 vehicles A-G, minimum and maximum following setting).

#include <string>
#include <vector>

#include <Eigen/Dense>

#include "ddemap/traffic/model.hpp"

namespace ddemap {

/// The largest magnitude of a covariance entry a car file may carry: a standard deviation of
/// 1000 in the parameter's units (1/s^2, 1/s, s, s, m) is far beyond any fit; larger entries
/// (1e308 once overflowed the 95 % ellipses into NaN) are refused.
constexpr double kMaxCovarianceEntry = 1e6;

/// A car with its law and parameters: a setting of the paper's table, a row of a user's table, a
/// fit that `calibrate` wrote, or a car given inline (io/cars.hpp reads every kind).
struct CalibratedVehicle {
    std::string name;       ///< e.g. "A_min"
    std::string model = "ovrv";  ///< the car-following law (a built-in model: ovrv, idm, ccc)
    std::string vehicle;    ///< "A".."G"
    std::string setting;    ///< "min" or "max" following distance
    int make = 1;           ///< 1 (vehicles A-D) or 2 (E-G)
    double min_acc_speed = 0.0;  ///< m/s below which ACC disengages (make 1: 25 mph = 11.2 m/s; make 2: 0)
    ParameterMap parameters;     ///< the model's parameters without speed; OVRV: k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]
    /// Covariance of the calibrated (k1, k2, th, tau, eta), in that order (as `calibrate` writes
    /// it); meaningful only when has_covariance.
    Eigen::Matrix<double, 5, 5> covariance = Eigen::Matrix<double, 5, 5>::Zero();
    bool has_covariance = false;
    /// The bounds the calibration searched within (columns lo_NAME, hi_NAME that `calibrate`
    /// writes); empty when the file carries none.
    ParameterBounds bounds;
};

/// CSV column names of the covariance: cov_A_B for the upper triangle (A before or equal to B
/// in the order k1, k2, th, tau, eta), 15 columns, row by row.
std::vector<std::string> covariance_column_names();

/// CSV column names of the calibration bounds: lo_NAME, hi_NAME for NAME in k1, k2, th, tau, eta
/// (10 columns, in that order).
std::vector<std::string> bounds_column_names();

/// The 14 settings of the paper's calibration table, in the paper's order.
const std::vector<CalibratedVehicle>& paper_calibration_table();

/// One setting of the built-in table by name ("A_min" .. "G_max"); std::invalid_argument
/// naming the name otherwise.
const CalibratedVehicle& builtin_vehicle(const std::string& name);

/// The one table of cars: a vehicle table and a fleet table are one format (CSV with a header,
/// columns in any order; blank lines and lines starting with '#' skipped):
///   name      the car's name (default: the vehicle's, else MODEL@SOURCE:LINE)
///   vehicle   a setting of the paper's table (A_min .. G_max) whose parameters the row starts from
///   model     the car-following law: ovrv, idm or ccc (default ovrv)
///   count     how many cars the row stands for, 1 to 1000000 (default 1)
///   the parameters of the models (k1, k2, th, tau, eta for ovrv; see model_parameters), blank =
///   the vehicle's value or the model's default (a required parameter must be given);
///   min_acc_speed [m/s] (ovrv: the ACC disengages below it; default 0 = never);
///   the 15 covariance columns cov_k1_k1 .. cov_eta_eta (all or none; a row with all filled
///   carries a covariance: symmetric, finite, non-negative diagonal) and the bounds lo_k1, hi_k1
///   .. lo_eta, hi_eta (per parameter both or neither; a row's pair both filled, lower <= upper)
///   of a fit; and the other columns `calibrate` writes (rmse_speed, rmse_gap, train_rmse_speed,
///   train_rmse_gap, test_rmse_speed, test_rmse_gap, naive_rmse_speed, status), not read.
/// Any other column is an error naming it; so is a name given to two rows with different
/// values (the same name on rows of the same car is one car). The rows are returned in order,
/// each repeated `count` times, at most 1000000 cars in all. Errors are std::invalid_argument
/// naming `source`, the line and the column.
std::vector<CalibratedVehicle> read_car_table(const std::string& text, const std::string& source);

/// A car's parameters completed with its law's defaults and checked against the law's ranges
/// (make_model at a valid speed, which is not kept): std::invalid_argument from the law otherwise.
ParameterMap complete_car_parameters(const std::string& model, const ParameterMap& parameters);

/// The same table, every car of the paper's law (ovrv): a car of another model is an error
/// naming it.
std::vector<CalibratedVehicle> read_vehicles_csv(const std::string& text, const std::string& source);

}  // namespace ddemap
