#include "nonlinear_flags.hpp"

#include "ddemap/io/system_json.hpp"
#include "ddemap/traffic/ov_ring.hpp"

namespace ddemap::cli {

void NonlinearSystemArgs::add_to(CLI::App& app) {
    app.add_option("--system", system, "a nonlinear DDE from a JSON file (variables, parameters, equations, equilibrium; see README)");
    app.add_option("--model", model, "a built-in nonlinear ring instead of --system: ov (optimal velocity with reaction delay)");
    app.add_option("--ring", ring, "--model ov: the number of cars N >= 2 (one headway is eliminated: 2N - 1 states)");
    ov_flags = {
        app.add_option("--alpha", alpha, "--model ov: sensitivity alpha [1/s]")->capture_default_str(),
        app.add_option("--tau", tau, "--model ov: reaction delay tau [s]")->capture_default_str(),
        app.add_option("--v0", v0, "--model ov: the speed scale v0 of V(h) [m/s]")->capture_default_str(),
        app.add_option("--h-st", h_st, "--model ov: the standstill headway h_st of V(h) [m] (V = 0 below)")->capture_default_str(),
        app.add_option("--headway", headway, "--model ov: mean headway = ring length / N [m]")->capture_default_str(),
    };
}

NonlinearSystemArgs::Built NonlinearSystemArgs::build(const std::string& par, double from) const {
    if (system.empty() == model.empty()) throw BadInput("expected one of --system FILE or --model ov (with --ring N)");
    Built b;
    if (!system.empty()) {
        for (const auto* f : ov_flags)
            if (f->count() > 0 || !ring.empty())
                throw BadInput("--system takes the whole problem from the file: expected no --ring or ov parameters");
        NonlinearSystemFile file = read_nonlinear_system_json(read_input_file("--system", system), system);
        b.variables = file.system->variables();
        b.guess = file.equilibrium;
        b.system = std::make_unique<ExpressionSystem>(*file.system);
        b.inputs.string("system", system);
    } else {
        if (model != "ov") throw BadInput("--model = '" + model + "': expected ov (other models: write a --system file)");
        if (ring.empty()) throw BadInput("--model ov needs --ring N: expected the number of cars");
        const int n = static_cast<int>(parse_integer("--ring", ring, 2, 2000, "an integer between 2 and 2000"));
        auto r = std::make_unique<OvRing>(n, parse_number("--alpha", alpha), parse_number("--tau", tau), parse_number("--v0", v0),
                                          parse_number("--h-st", h_st), parse_number("--headway", headway));
        r->set_parameter(r->parameter_names()[static_cast<std::size_t>(r->parameter_index(par))], from);
        b.guess = r->uniform_flow();
        for (int i = 0; i + 1 < n; ++i) {
            b.variables.push_back("h" + std::to_string(i));
            b.units[b.variables.back()] = "m";
        }
        for (int i = 0; i < n; ++i) {
            b.variables.push_back("v" + std::to_string(i));
            b.units[b.variables.back()] = "m/s";
        }
        b.units.insert({{"alpha", "1/s"}, {"tau", "s"}, {"v0", "m/s"}, {"h_st", "m"}, {"headway", "m"}});
        b.inputs.string("model", "ov").integer("ring", n);
        b.system = std::move(r);
    }
    (void)b.system->parameter_index(par);  // an unknown name is bad input naming the known ones
    for (std::size_t i = 0; i < b.system->parameter_names().size(); ++i) {
        const std::string& name = b.system->parameter_names()[i];
        if (name != par) b.inputs.number(name, b.system->parameter_values()[i]);
    }
    return b;
}

}  // namespace ddemap::cli
