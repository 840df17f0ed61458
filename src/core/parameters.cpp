#include "ddemap/core/parameters.hpp"

#include "core/internal/text.hpp"

#include <cmath>
#include <stdexcept>

namespace ddemap {

namespace {
std::string number(double x) { return detail::format_number(x); }
}  // namespace

void validate_bounds(const ParameterBounds& bounds, const std::vector<std::string>& known) {
    for (std::size_t i = 0; i < bounds.size(); ++i) {
        const BoundedParameter& b = bounds[i];
        if (!known.empty()) {
            bool found = false;
            std::string list;
            for (const auto& k : known) {
                found = found || k == b.name;
                list += (list.empty() ? "" : ", ") + k;
            }
            if (!found) throw std::invalid_argument("bounds for '" + b.name + "': unknown parameter, expected one of " + list);
        }
        for (std::size_t j = 0; j < i; ++j)
            if (bounds[j].name == b.name) throw std::invalid_argument("bounds for '" + b.name + "' are given twice");
        if (!std::isfinite(b.lower) || !std::isfinite(b.upper))
            throw std::invalid_argument("bounds for '" + b.name + "' = " + number(b.lower) + ":" + number(b.upper) + ": expected finite bounds");
        if (b.lower > b.upper)
            throw std::invalid_argument("bounds for '" + b.name + "' = " + number(b.lower) + ":" + number(b.upper) + ": expected lower <= upper");
    }
}

const BoundedParameter* find_bound(const ParameterBounds& bounds, const std::string& name) {
    for (const auto& b : bounds)
        if (b.name == name) return &b;
    return nullptr;
}

BoundedParameter* find_bound(ParameterBounds& bounds, const std::string& name) {
    for (auto& b : bounds)
        if (b.name == name) return &b;
    return nullptr;
}

}  // namespace ddemap
