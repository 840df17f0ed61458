#pragma once
/// \file vehicle_files.hpp
/// One format family for the vehicle and fleet CSV files that every command reads (classify,
/// simulate, roots --fleet, mix --x/--y), and one rule for telling a file from a pattern.

#include <string>
#include <vector>

#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// True when `spec` names a file rather than a pattern of built-in names ("A_min*3,C_max"):
/// it exists as a file or folder, or its name ends in ".csv".
bool names_a_file(const std::string& spec);

/// A vehicle or fleet CSV. The header decides which:
/// - a fleet table has a `vehicle` or a `model` column (read_fleet_csv: vehicle and/or model,
///   parameter columns, optional count);
/// - otherwise it is a vehicle table `name,k1,k2,th,tau[,eta][,min_acc_speed]`, other columns
///   ignored (read_vehicles_csv): what `calibrate` and `classify` write; every row one OVRV car.
Fleet read_fleet_table(const std::string& text, const std::string& source);

/// The same files as OVRV vehicles (for classification and simulation): a fleet table's rows
/// are expanded by their count; a built-in vehicle keeps its minimum ACC speed; a row of another
/// law is refused (std::invalid_argument naming the source and the car).
std::vector<CalibratedVehicle> read_vehicle_table(const std::string& text, const std::string& source);

/// One car: a built-in name ("E_min"), "MODEL:NAME=VALUE,..." (parse_fleet_car), a file
/// "FILE.csv" that holds one kind of car, or "FILE.csv:NAME", the car named NAME in the file.
FleetCar fleet_car_from_argument(const std::string& spec);

}  // namespace ddemap
