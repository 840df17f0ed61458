#pragma once
/// \file units.hpp
/// Units in column names: every CSV column that holds a quantity with a unit carries it as a
/// suffix (`gap_m`, `speed_mps`, `omega_peak_rad_per_s`); a column without one holds a number
/// without unit, a count, a flag or text.

#include <string>

namespace ddemap {

/// The suffix of a column in `unit`: "" for no unit ("", "1", "-"), "_s", "_m", "_mps" (m/s),
/// "_mps2" (m/s^2), "_per_s" (1/s), "_per_s2" (1/s^2), "_rad", "_rad_per_s" (rad/s); any other
/// unit spelled out with '/' as "_per_", '^' dropped and other signs as '_' (e.g. "kg m/s" ->
/// "_kg_m_per_s").
std::string unit_suffix(const std::string& unit);

/// name + unit_suffix(unit).
std::string column_name(const std::string& name, const std::string& unit);

/// The name without the suffix of `unit` when the column carries it (`k1_per_s2`, "1/s^2" ->
/// `k1`), else the column unchanged: what readers use to accept both spellings.
std::string strip_unit(const std::string& column, const std::string& unit);

}  // namespace ddemap
