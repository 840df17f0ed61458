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

struct CalibratedVehicle {
    std::string name;       ///< e.g. "A_min"
    std::string vehicle;    ///< "A".."G"
    std::string setting;    ///< "min" or "max" following distance
    int make = 1;           ///< 1 (vehicles A-D) or 2 (E-G)
    double min_acc_speed = 0.0;  ///< m/s below which ACC disengages (make 1: 25 mph = 11.2 m/s; make 2: 0)
    ParameterMap parameters;     ///< OVRV: k1 [1/s^2], k2 [1/s], th [s], tau [s], eta [m]
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

/// Reads vehicles from CSV text: a header with at least name, k1, k2, th, tau (eta optional,
/// default 10; min_acc_speed [m/s] optional, default 0 = the ACC never disengages; the 15
/// covariance columns cov_k1_k1 .. cov_eta_eta optional, all or none: a row with all of them
/// filled carries a covariance (symmetric, finite, non-negative diagonal), a row with all empty
/// none; the bounds columns lo_k1, hi_k1 .. lo_eta, hi_eta optional, for each parameter both or
/// neither in the header, a row's pair both filled (finite, lower <= upper) or both empty, into
/// `bounds`; other columns are ignored), one vehicle per line. Errors name `source`, the line
/// and the column (std::invalid_argument).
std::vector<CalibratedVehicle> read_vehicles_csv(const std::string& text, const std::string& source);

}  // namespace ddemap
