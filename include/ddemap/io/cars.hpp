#pragma once
/// \file cars.hpp
/// One way to name cars, for every command and for Python. A car list is items joined by commas:
///
///   A_min                        a setting of the paper's calibration table (A_min .. G_max)
///   mycars.csv                   every car of a car table (traffic/vehicles.hpp read_car_table),
///                                or of what `calibrate` writes (its CSV, or its JSON output)
///   mycars.csv:Sedan             the car named Sedan in that file (fits.json:NAME likewise)
///   ovrv:k1=0.12,k2=0.45,th=1.2,tau=0.6
///                                one car of a built-in law (ovrv, idm, ccc) with its parameters
///                                (`name=Sedan` among them names it; otherwise the text names it)
///
/// each optionally followed by *K: K times in a row (a file: all of its cars, K times). A file is
/// an item that ends in .csv or .json (or names an existing file); in an inline car, the items
/// after MODEL: that hold an '=' are its parameters. A row's `count` column repeats it as *K does.
/// The list is returned in order, expanded: a platoon or a ring takes it as it is, a command
/// that draws or classifies cars takes each distinct car once (distinct_cars).

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/vehicles.hpp"

namespace ddemap {

/// The most cars a car list expands to.
constexpr std::size_t kMaxCars = 1000000;

/// Reads a car list (see the file comment); files are read from disk, a relative path found
/// from the working folder or else from `base_dir` (e.g. the folder of the chart spec that names
/// it). std::invalid_argument naming the item (and the file, line and column) for anything it
/// cannot read; a list that would expand to more than `max_cars` cars is refused before it is
/// built.
/// `tables` (optional) holds tables in memory by name (e.g. a pandas DataFrame written as CSV
/// text by the Python module): an item equal to one of the names (with *K) reads that text, as
/// a file of that name would be read, before any file on disk.
using CarTables = std::map<std::string, std::string>;
std::vector<CalibratedVehicle> read_cars(const std::string& list, std::size_t max_cars = kMaxCars, const std::string& base_dir = "",
                                         const CarTables* tables = nullptr);

/// The cars of what `calibrate` writes as JSON (its envelope `{"command": "calibrate", ...}`):
/// one per fit, with the fit's parameters, covariance and bounds. A fit that did not converge
/// is refused (its parameters are not an estimate).
std::vector<CalibratedVehicle> read_calibration_json(const std::string& text, const std::string& source);

/// Each distinct car once, in the order of first appearance (cars are the same when their names
/// are; the same name with other values is an error naming it).
std::vector<CalibratedVehicle> distinct_cars(const std::vector<CalibratedVehicle>& cars);

/// The cars as a fleet (name, law and parameters of each).
Fleet to_fleet(const std::vector<CalibratedVehicle>& cars);

/// Refuses a car of another law than ovrv: "WHAT takes cars of the paper's law (ovrv); car NAME
/// has model MODEL".
void require_ovrv(const std::vector<CalibratedVehicle>& cars, const std::string& what);

/// True when `item` names a file rather than a built-in or inline car: it ends in .csv or .json,
/// or exists as a file or folder.
bool names_a_file(const std::string& item);

}  // namespace ddemap
