#pragma once
// Flags shared by the mixed-ring commands (roots --fleet/--fleet-pattern, mix).
#include <string>

#include "common.hpp"
#include "ddemap/analysis/stability/mixed_ring.hpp"

namespace ddemap::cli {

/// --speed / --length -> ring options (default: speed 20 m/s)
inline void set_equilibrium(MixedRingOptions& o, const std::string& speed, const std::string& length) {
    if (!speed.empty() && !length.empty()) throw BadInput("--speed and --length: expected only one of them");
    if (!length.empty()) o.length = parse_number("--length", length);
    else o.speed = speed.empty() ? 20.0 : parse_number("--speed", speed);
}

/// {"speed": v} or {"length": L}
inline void equilibrium_inputs(JsonObject& in, const MixedRingOptions& o) {
    if (std::isnan(o.length)) in.number("speed", o.speed);
    else in.number("length", o.length);
}

}  // namespace ddemap::cli
