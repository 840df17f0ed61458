#pragma once
/// \file parameters.hpp
/// Named parameters: values by name, and bounds lo <= p <= hi by name.

#include <map>
#include <string>
#include <vector>

#include "ddemap/core/types.hpp"

namespace ddemap {

/// One parameter with its admissible interval [lower, upper] (lower = upper fixes it).
struct BoundedParameter {
    std::string name;
    double lower = 0.0;
    double upper = 0.0;
};

/// An ordered list of bounded parameters.
using ParameterBounds = std::vector<BoundedParameter>;

/// Checks every entry: a name from `known` (when not empty), no repeats, finite bounds with
/// lower <= upper. std::invalid_argument names the parameter and what was expected.
void validate_bounds(const ParameterBounds& bounds, const std::vector<std::string>& known = {});

/// The entry for `name`, or nullptr.
const BoundedParameter* find_bound(const ParameterBounds& bounds, const std::string& name);
BoundedParameter* find_bound(ParameterBounds& bounds, const std::string& name);

}  // namespace ddemap
