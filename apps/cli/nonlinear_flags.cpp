#include "nonlinear_flags.hpp"

#include "common.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/traffic/ov_ring.hpp"

namespace ddemap::cli {

void NonlinearProblemArgs::add_to(CLI::App& app) {
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
    app.add_option("--par", par, "the free parameter (a name of the system; ov: alpha, tau, v0, h_st, headway)")->required();
    app.add_option("--from", from, "the branch starts at this value of the parameter")->required();
    app.add_option("--to", to, "and is followed (through folds) until the parameter leaves [from, to]")->required();
}

NonlinearProblemArgs::Problem NonlinearProblemArgs::load() const {
    Problem r;
    if (system.empty() == model.empty()) throw BadInput("expected one of --system FILE or --model ov (with --ring N)");
    r.from = parse_number("--from", from);
    r.to = parse_number("--to", to);
    if (r.from == r.to) throw BadInput("--to = '" + to + "': expected a value other than --from");
    bool ov_given = false;
    for (const auto* f : ov_flags) ov_given = ov_given || f->count() > 0;
    if (!system.empty()) {
        if (!ring.empty() || ov_given) throw BadInput("--system takes the whole problem from the file: expected no --ring or ov parameters");
        NonlinearSystemFile file = read_nonlinear_system_json(read_input_file("--system", system), system);
        r.variables = file.system->variables();
        r.guess = file.equilibrium;
        r.system = std::make_unique<ExpressionSystem>(*file.system);
        r.inputs.string("system", system);
    } else {
        if (model != "ov") throw BadInput("--model = '" + model + "': expected ov (other models: write a --system file)");
        if (ring.empty()) throw BadInput("--model ov needs --ring N: expected the number of cars");
        const int n = static_cast<int>(parse_integer("--ring", ring, 2, 2000, "an integer between 2 and 2000"));
        auto ov = std::make_unique<OvRing>(n, parse_number("--alpha", alpha), parse_number("--tau", tau), parse_number("--v0", v0),
                                           parse_number("--h-st", h_st), parse_number("--headway", headway));
        ov->set_parameter(ov->parameter_names()[static_cast<std::size_t>(ov->parameter_index(par))], r.from);
        r.guess = ov->uniform_flow();
        for (int i = 0; i + 1 < n; ++i) r.variables.push_back("h" + std::to_string(i));
        for (int i = 0; i < n; ++i) r.variables.push_back("v" + std::to_string(i));
        r.inputs.string("model", "ov").integer("ring", n);
        r.system = std::move(ov);
    }
    (void)r.system->parameter_index(par);  // an unknown name is bad input naming the known ones
    for (std::size_t i = 0; i < r.system->parameter_names().size(); ++i) {
        const std::string& name = r.system->parameter_names()[i];
        if (name != par) r.inputs.number(name, r.system->parameter_values()[i]);
    }
    return r;
}

}  // namespace ddemap::cli
