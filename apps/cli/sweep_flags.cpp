#include "sweep_flags.hpp"

#include "ddemap/analysis/stability/ring_fast.hpp"  // kModesMaxCars, kWindingMaxCars
#include "ddemap/io/svg.hpp"
#include "limits.hpp"

#include <algorithm>
#include <string>
#include <sstream>

namespace ddemap::cli {

SweepSpec sweep_spec(const ModelArgs& margs, const RingArg& ring, const std::string& x_name, bool counts, int grid) {
    SweepSpec spec;
    spec.model = margs.model;
    std::vector<std::pair<std::string, std::string>> axes;
    margs.split(spec.fixed, axes);
    if (axes.size() != 2) {
        throw BadInput(std::string("expected exactly two swept parameters given as ") + (counts ? "LO:HI:COUNT" : "LO:HI") + " (e.g. --k1 0.01:1" +
                       (counts ? ":200" : "") + " --k2 0.01:1" + (counts ? ":200" : "") + "), got " + std::to_string(axes.size()));
    }
    if (!x_name.empty()) {
        if (axes[1].first == x_name) std::swap(axes[0], axes[1]);
        if (axes[0].first != x_name) throw BadInput("--x = '" + x_name + "': expected one of the swept parameters");
    }
    for (int i = 0; i < 2; ++i) {
        if (!counts && std::count(axes[i].second.begin(), axes[i].second.end(), ':') != 1)
            throw BadInput("--" + axes[i].first + " = '" + axes[i].second + "': expected LO:HI with finite LO < HI");
        const std::string text = counts ? axes[i].second : axes[i].second + ":" + std::to_string(grid);
        try {
            (i == 0 ? spec.x : spec.y) = parse_axis(axes[i].first, text);
        } catch (const std::invalid_argument& e) {
            throw BadInput("--" + std::string(e.what()));  // the library names the parameter; the flag is --NAME
        }
    }
    // up to 10^9 cars: the winding tables cost the same at any N; the per-mode path (boundaries)
    // is held to kModesMaxCars by check_sweep_size once the caller has chosen the ring method
    spec.cars = ring.parse(true, kWindingMaxCars);
    spec.validate();
    return spec;
}

void check_sweep_size(const SweepSpec& spec, const std::string& command, bool writes_grid, std::size_t panels, bool ring_curves_all) {
    if (spec.cars > kModesMaxCars && sweep_ring_method(spec) == "modes")
        throw BadInput("--ring = " + std::to_string(spec.cars) + ": expected at most " + std::to_string(kModesMaxCars) + " cars for " +
                       (command == "boundary" ? std::string("boundary --ring-curves all (its seeds need every mode's root, one by one; --ring-curves envelope takes up to ") +
                                                    std::to_string(kWindingMaxCars) + ")"
                                              : command + " with every mode's ring curve (their seeds need every mode's root, one by one; the envelope or no boundaries take up to " +
                                                    std::to_string(kWindingMaxCars) + ")"));
    const double points = static_cast<double>(spec.x.count) * static_cast<double>(spec.y.count) * static_cast<double>(panels);
    // N = inf: a frequency scan, about 12 modes' work; the winding path: about that at any N
    const double modes = spec.cars == 0 || sweep_ring_method(spec) == "winding" ? 12.0 : spec.cars / 2 + 1.0;
    const std::string what = (panels > 1 ? std::to_string(panels) + " panels of " : std::string()) + "a " + std::to_string(spec.x.count) + " x " + std::to_string(spec.y.count) + " grid" +
                             (spec.cars > 0 ? " of a " + std::to_string(spec.cars) + "-car ring" : std::string());
    check_size(command, what, "memory", points * (600.0 + 16.0 * modes));
    if (writes_grid) check_size(command, what, "output", points * 180.0);
    // the peak notion: at most 0.03 s more per point (only L2-stable points need ||h||_1)
    const double seconds = points * (modes * 5e-5 + (spec.peak ? 0.03 : 0.0)) / std::max(1, thread_count()) +
                           (ring_curves_all && spec.cars > 0 ? 1e-3 * modes : 0.0);  // the curves are traced on one core
    check_size(command, what, "time", seconds);
    announce_estimate(command, what, seconds);
}

RingCurves parse_ring_curves_flag(const std::string& text, const SweepSpec& spec) {
    try {
        return resolve_ring_curves(parse_ring_curves(text), spec);
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        const std::size_t colon = what.find(": ");
        throw BadInput("--ring-curves = '" + text + "': " + (colon == std::string::npos ? what : what.substr(colon + 2)));
    }
}

JsonObject sweep_inputs(const SweepSpec& spec) {
    auto axis = [](const Axis& a) {
        return JsonObject().string("name", a.name).number("lo", a.lo).number("hi", a.hi).integer("count", a.count).str();
    };
    JsonObject o;
    o.string("model", spec.model).json("fixed", json_parameters(spec.fixed)).json("x", axis(spec.x)).json("y", axis(spec.y))
        .json("ring", json_ring(spec.cars));
    return o;
}

}  // namespace ddemap::cli
