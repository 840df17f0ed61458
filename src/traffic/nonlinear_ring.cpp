#include "ddemap/traffic/nonlinear_ring.hpp"

#include <algorithm>
#include <stdexcept>
#include <cmath>

#include "ddemap/traffic/acc_ring.hpp"
#include "ddemap/traffic/idm_ring.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/ov_ring.hpp"
#include "core/internal/text.hpp"

namespace ddemap {

std::vector<std::string> nonlinear_ring_models() { return {"ov", "idm", "acc"}; }

std::vector<std::string> nonlinear_ring_parameters(const std::string& model) {
    if (model == "ov") return {"alpha", "tau", "v0", "h_st", "headway"};
    if (model == "idm") return {"a", "b", "v0", "delta", "th", "eta", "tau", "gap"};
    if (model == "acc") return {"k1", "k2", "th", "tau", "eta", "a_max", "a_min", "gap"};
    throw std::invalid_argument("model " + detail::quoted(model) + ": expected ov, idm or acc (other models: write a system file)");
}

NonlinearRing make_nonlinear_ring(const std::string& model, int cars, const ParameterMap& parameters) {
    const std::vector<std::string> names = nonlinear_ring_parameters(model);
    if (cars < 2 || cars > 2000) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected 2 to 2000");
    for (const auto& [name, value] : parameters) {
        bool known = false;
        for (const auto& n : names) known = known || n == name;
        if (!known) {
            std::string list;
            for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
            throw std::invalid_argument(name + " is not a parameter of the " + model + " ring (" + list + ")");
        }
        // a subnormal value (a delay of 1e-320) overflows 1 / tau in the analyses
        if (value != 0.0 && std::abs(value) < kMinParameterMagnitude)
            throw std::invalid_argument(name + " = " + detail::format_number(value) + ": expected 0 or a magnitude of at least 2.2e-308 (a subnormal number overflows 1 / x)");
    }
    auto get = [&](const std::string& name, double fallback) {
        const auto it = parameters.find(name);
        return it == parameters.end() ? fallback : it->second;
    };
    auto required = [&](const std::string& name) {
        const auto it = parameters.find(name);
        if (it == parameters.end()) throw std::invalid_argument("the " + model + " ring needs " + name + ": expected a number");
        return it->second;
    };
    NonlinearRing r;
    std::string state;
    if (model == "ov") {
        auto ov = std::make_unique<OvRing>(cars, get("alpha", 1.0), get("tau", 1.0), get("v0", 1.0), get("h_st", 1.0), get("headway", 2.0));
        r.uniform_flow = ov->uniform_flow();
        r.system = std::move(ov);
        state = "h";
        r.units = {{"alpha", "1/s"}, {"tau", "s"}, {"v0", "m/s"}, {"h_st", "m"}, {"headway", "m"}};
    } else if (model == "acc") {
        for (const char* name : {"k1", "k2", "th", "tau", "eta", "gap"}) required(name);  // named in this order, whatever the compiler's order of arguments
        auto acc = std::make_unique<AccRing>(cars, required("k1"), required("k2"), required("th"), required("tau"), required("eta"), get("a_max", 2.0),
                                             get("a_min", -3.0), required("gap"));
        r.uniform_flow = acc->uniform_flow();
        r.system = std::move(acc);
        state = "s";
        r.units = {{"k1", "1/s^2"}, {"k2", "1/s"}, {"th", "s"}, {"tau", "s"}, {"eta", "m"}, {"a_max", "m/s^2"}, {"a_min", "m/s^2"}, {"gap", "m"}};
    } else {
        auto idm = std::make_unique<IdmRing>(cars, get("a", 1.0), get("b", 1.5), get("v0", 33.3), get("delta", 4.0), required("th"), get("eta", 2.0),
                                             required("tau"), get("gap", 20.0));
        r.uniform_flow = idm->uniform_flow();
        r.system = std::move(idm);
        state = "s";
        r.units = {{"a", "m/s^2"}, {"b", "m/s^2"}, {"v0", "m/s"}, {"delta", "1"}, {"th", "s"}, {"eta", "m"}, {"tau", "s"}, {"gap", "m"}};
    }
    for (int i = 0; i + 1 < cars; ++i) {
        r.variables.push_back(state + std::to_string(i));
        r.units[r.variables.back()] = "m";
    }
    for (int i = 0; i < cars; ++i) {
        r.variables.push_back("v" + std::to_string(i));
        r.units[r.variables.back()] = "m/s";
    }
    return r;
}

NonlinearRing make_nonlinear_ring(const std::string& model, int cars, ParameterMap parameters, const std::string& free_parameter, double start) {
    const std::vector<std::string> names = nonlinear_ring_parameters(model);
    if (std::find(names.begin(), names.end(), free_parameter) != names.end()) parameters[free_parameter] = start;
    return make_nonlinear_ring(model, cars, parameters);
}

}  // namespace ddemap
