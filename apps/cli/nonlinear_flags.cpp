#include "nonlinear_flags.hpp"

#include <algorithm>

#include "common.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"

namespace ddemap::cli {

void NonlinearProblemArgs::add_to(CLI::App& app) {
    app.add_option("--system", system, "a nonlinear DDE from a JSON file (variables, parameters, equations, equilibrium; see README)");
    app.add_option("--model", model, "a built-in nonlinear ring instead of --system: ov (optimal velocity with reaction delay), "
                                      "idm (intelligent driver model with sensing delay) or acc (the paper's OVRV law with acceleration limits)");
    app.add_option("--ring", ring, "--model ov|idm|acc: the number of cars N >= 2 (one headway or gap is eliminated: 2N - 1 states)");
    model_flags = {
        app.add_option("--alpha", alpha, "--model ov: sensitivity alpha [1/s] (default 1)"),
        app.add_option("--tau", tau, "--model ov: reaction delay tau [s] (default 1); idm, acc: sensing delay [s] (required, acc: or from --car)"),
        app.add_option("--v0", v0, "--model ov: the speed scale v0 of V(h) [m/s] (default 1); idm: desired speed [m/s] (default 33.3)"),
        app.add_option("--h-st", h_st, "--model ov: the standstill headway h_st of V(h) [m] (V = 0 below; default 1)"),
        app.add_option("--headway", headway, "--model ov: mean headway = ring length / N [m] (default 2)"),
        app.add_option("--a", a, "--model idm: maximum acceleration [m/s^2] (default 1)"),
        app.add_option("--b", b, "--model idm: comfortable deceleration [m/s^2] (default 1.5)"),
        app.add_option("--delta", delta, "--model idm: acceleration exponent [1] (default 4)"),
        app.add_option("--th", th, "--model idm, acc: time headway [s] (required; acc: or from --car)"),
        app.add_option("--eta", eta, "--model idm: jam (standstill) gap s0 [m] (default 2); acc: standstill gap [m] (required or from --car)"),
        app.add_option("--gap", gap, "--model idm, acc: mean gap = ring length / N - car length [m] (idm: default 20; acc: required; the uniform flow needs gap > eta)"),
        app.add_option("--k1", k1, "--model acc: gain on the spacing error [1/s^2] (required or from --car)"),
        app.add_option("--k2", k2, "--model acc: gain on the speed difference [1/s] (required or from --car)"),
        app.add_option("--a-max", a_max, "--model acc: the acceleration limit [m/s^2] (default 2; a smooth saturation, see README)"),
        app.add_option("--a-min", a_min, "--model acc: the braking limit, negative [m/s^2] (default -3)"),
    };
    app.add_option("--car", car, "--model acc: k1, k2, th, tau, eta of a calibrated car (A_min, mycars.csv:Sedan, a fit file; flags given override)")
        ->type_name("CAR");
    app.add_option("--par", par, "the free parameter (a name of the system; ov: alpha, tau, v0, h_st, headway; idm: a, b, v0, delta, th, eta, tau, gap)")->required();
    app.add_option("--from", from, "the branch starts at this value of the parameter")->required();
    app.add_option("--to", to, "and is followed (through folds) until the parameter leaves [from, to]")->required();
}


NonlinearProblemArgs::Problem NonlinearProblemArgs::load() const {
    Problem r;
    if (system.empty() == model.empty()) throw BadInput("expected one of --system FILE or --model ov|idm|acc (with --ring N)");
    if (!car.empty() && model != "acc") throw BadInput("--car: only with --model acc (expected --model acc --ring N --car CAR)");
    r.from = parse_number("--from", from);
    r.to = parse_number("--to", to);
    if (r.from == r.to) throw BadInput("--to = '" + to + "': expected a value other than --from");
    std::vector<std::string> given;
    for (const auto* f : model_flags)
        if (f->count() > 0) given.push_back(f->get_name());
    auto refuse_flags = [&](const std::vector<std::string>& allowed, const std::string& what) {
        for (const std::string& g : given)
            if (std::find(allowed.begin(), allowed.end(), g) == allowed.end()) throw BadInput(g + " is not a parameter of " + what);
    };
    if (!system.empty()) {
        if (!ring.empty() || !given.empty()) throw BadInput("--system takes the whole problem from the file: expected no --ring or model parameters");
        NonlinearSystemFile file = read_nonlinear_system_json(read_input_file("--system", system), system);
        r.variables = file.system->variables();
        r.guess = file.equilibrium;
        r.system = std::make_unique<ExpressionSystem>(*file.system);
        r.inputs.string("system", system);
    } else {
        if (model != "ov" && model != "idm" && model != "acc") throw BadInput("--model = '" + model + "': expected ov, idm or acc (other models: write a --system file)");
        if (ring.empty()) throw BadInput("--model " + model + " needs --ring N: expected the number of cars");
        const int n = static_cast<int>(parse_integer("--ring", ring, 2, 2000, "an integer between 2 and 2000"));
        if (model == "ov") {
            refuse_flags({"--alpha", "--tau", "--v0", "--h-st", "--headway"}, "--model ov (alpha, tau, v0, h_st, headway)");
        } else if (model == "acc") {
            refuse_flags({"--k1", "--k2", "--th", "--tau", "--eta", "--a-max", "--a-min", "--gap"}, "--model acc (k1, k2, th, tau, eta, a_max, a_min, gap)");
            if (gap.empty()) throw BadInput("--model acc needs --gap: expected the mean gap [m] (ring length / N - car length)");
        } else {
            refuse_flags({"--a", "--b", "--v0", "--delta", "--th", "--eta", "--tau", "--gap"}, "--model idm (a, b, v0, delta, th, eta, tau, gap)");
            if (th.empty()) throw BadInput("--model idm needs --th: expected a number");
            if (tau.empty()) throw BadInput("--model idm needs --tau: expected a number");
        }
        // the flags given, by parameter name (--h-st: h_st); --par starts at --from (the uniform flow
        // there is the guess; for idm a gap <= eta is refused naming gap and eta)
        ParameterMap values;
        if (!car.empty()) {  // the calibrated car's law parameters, then the flags given over them
            const FleetCar c = car_argument("--car", car);
            if (c.model != "ovrv") throw BadInput("--car = '" + car + "': a " + c.model + " car; expected an OVRV car (the acc ring's law)");
            for (const char* name : {"k1", "k2", "th", "tau", "eta"}) {
                const auto it = c.parameters.find(name);
                if (it != c.parameters.end()) values[name] = it->second;
            }
            r.inputs.string("car", car);
        }
        for (const auto* f : model_flags)
            if (f->count() > 0) {
                std::string name = f->get_name().substr(2);
                for (char& c : name) c = c == '-' ? '_' : c;
                values[name] = parse_number(f->get_name(), f->as<std::string>());
            }
        NonlinearRing built = make_nonlinear_ring(model, n, values, par, r.from);
        r.guess = built.uniform_flow;
        r.variables = built.variables;
        r.units = built.units;
        r.system = std::move(built.system);
        r.inputs.string("model", model).integer("ring", n);
    }
    add_held_parameters(r.inputs, *r.system, par);  // an unknown --par is bad input naming the known ones
    return r;
}

void second_parameter(NonlinearProblemArgs::Problem& pb, const EquilibriumBranchOptions& o, const std::string& par2, const std::string& from2,
                      const std::string& to2, TwoParameterOptions& co) {
    if (from2.empty() || to2.empty()) throw BadInput("--par2 needs --from2 and --to2: expected the box of " + par2);
    if (par2 == o.parameter) throw BadInput("--par2 = '" + par2 + "': expected a parameter other than --par");
    const int j2 = pb.system->parameter_index(par2);  // unknown: bad input naming the known ones
    co.branch = o;
    co.parameter2 = par2;
    co.from2 = parse_number("--from2", from2);
    co.to2 = parse_number("--to2", to2);
    if (!(co.from2 < co.to2)) throw BadInput("--from2 = '" + from2 + "', --to2 = '" + to2 + "': expected --from2 < --to2");
    const double held = pb.system->parameter_values()[static_cast<std::size_t>(j2)];
    if (!(held >= co.from2 && held <= co.to2))
        throw BadInput("--par2 " + par2 + " = " + rounded(held, 15) + " (its value in the system): expected it in [--from2, --to2]");
    co.continuation.max_points = o.continuation.max_points;
    pb.inputs.string("par2", par2).number("from2", co.from2).number("to2", co.to2);
}

}  // namespace ddemap::cli
