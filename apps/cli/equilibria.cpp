// equilibria: a branch of equilibria of a nonlinear DDE in one parameter (a system file with
// expressions, or the built-in ov ring), its stability, folds and Hopf points.
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "ddemap/analysis/equilibrium_branch.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/traffic/ov_ring.hpp"

namespace ddemap::cli {

namespace {

struct Args {
    std::string system, model, ring, par, from, to, count = "4", points = "400";
    std::string alpha = "1", tau = "1", v0 = "1", h_st = "1", headway = "2";
    FormatArg format;
    OutArg out;
    std::vector<CLI::Option*> ov_flags;
} args;

/// Left-aligned in a column of width w (at least one space after).
std::string pad(std::string s, std::size_t w) {
    if (s.size() < w) s.resize(w, ' ');
    else s += ' ';
    return s;
}

bool any_given(const std::vector<CLI::Option*>& flags) {
    for (const auto* f : flags)
        if (f->count() > 0) return true;
    return false;
}

}  // namespace

void add_equilibria_flags(CLI::App& app) {
    app.add_option("--system", args.system, "a nonlinear DDE from a JSON file (variables, parameters, equations, equilibrium; see README)");
    app.add_option("--model", args.model, "a built-in nonlinear ring instead of --system: ov (optimal velocity with reaction delay)");
    app.add_option("--ring", args.ring, "--model ov: the number of cars N >= 2 (one headway is eliminated: 2N - 1 states)");
    args.ov_flags = {
        app.add_option("--alpha", args.alpha, "--model ov: sensitivity alpha [1/s]")->capture_default_str(),
        app.add_option("--tau", args.tau, "--model ov: reaction delay tau [s]")->capture_default_str(),
        app.add_option("--v0", args.v0, "--model ov: the speed scale v0 of V(h) [m/s]")->capture_default_str(),
        app.add_option("--h-st", args.h_st, "--model ov: the standstill headway h_st of V(h) [m] (V = 0 below)")->capture_default_str(),
        app.add_option("--headway", args.headway, "--model ov: mean headway = ring length / N [m]")->capture_default_str(),
    };
    app.add_option("--par", args.par, "the free parameter (a name of the system; ov: alpha, tau, v0, h_st, headway)")->required();
    app.add_option("--from", args.from, "the branch starts at this value of the parameter")->required();
    app.add_option("--to", args.to, "and is followed (through folds) until the parameter leaves [from, to]")->required();
    app.add_option("--count", args.count, "rightmost roots reported at every point")->capture_default_str();
    app.add_option("--max-points", args.points, "the most points of the branch")->capture_default_str();
    args.format.add_to(app);
    args.out.add_to(app, "PREFIX.csv (one row per point and special point) and PREFIX.json", false);
}

int run_equilibria() {
    const Format format = args.format.parse();
    const std::string prefix = args.out.given() ? args.out.prepare("equilibria") : std::string();
    if (args.system.empty() == args.model.empty()) throw BadInput("expected one of --system FILE or --model ov (with --ring N)");
    EquilibriumBranchOptions o;
    o.parameter = args.par;
    o.from = parse_number("--from", args.from);
    o.to = parse_number("--to", args.to);
    if (o.from == o.to) throw BadInput("--to = '" + args.to + "': expected a value other than --from");
    o.roots.count = static_cast<int>(parse_integer("--count", args.count, 1, 100, "an integer between 1 and 100"));
    o.continuation.max_points = static_cast<int>(parse_integer("--max-points", args.points, 2, 100000, "an integer between 2 and 100000"));

    std::unique_ptr<NonlinearDDE> system;
    std::vector<std::string> variables;
    Eigen::VectorXd guess;
    JsonObject inputs;
    if (!args.system.empty()) {
        if (!args.ring.empty() || any_given(args.ov_flags))
            throw BadInput("--system takes the whole problem from the file: expected no --ring or ov parameters");
        NonlinearSystemFile file = read_nonlinear_system_json(read_input_file("--system", args.system), args.system);
        variables = file.system->variables();
        guess = file.equilibrium;
        system = std::make_unique<ExpressionSystem>(*file.system);
        inputs.string("system", args.system);
    } else {
        if (args.model != "ov") throw BadInput("--model = '" + args.model + "': expected ov (other models: write a --system file)");
        if (args.ring.empty()) throw BadInput("--model ov needs --ring N: expected the number of cars");
        const int n = static_cast<int>(parse_integer("--ring", args.ring, 2, 2000, "an integer between 2 and 2000"));
        auto ring = std::make_unique<OvRing>(n, parse_number("--alpha", args.alpha), parse_number("--tau", args.tau),
                                             parse_number("--v0", args.v0), parse_number("--h-st", args.h_st),
                                             parse_number("--headway", args.headway));
        ring->set_parameter(ring->parameter_names()[static_cast<std::size_t>(ring->parameter_index(args.par))], o.from);
        guess = ring->uniform_flow();
        for (int i = 0; i + 1 < n; ++i) variables.push_back("h" + std::to_string(i));
        for (int i = 0; i < n; ++i) variables.push_back("v" + std::to_string(i));
        inputs.string("model", "ov").integer("ring", n);
        system = std::move(ring);
    }
    (void)system->parameter_index(args.par);  // an unknown name is bad input naming the known ones
    for (std::size_t i = 0; i < system->parameter_names().size(); ++i) {
        const std::string& name = system->parameter_names()[i];
        if (name != args.par) inputs.number(name, system->parameter_values()[i]);
    }
    inputs.string("par", args.par).number("from", o.from).number("to", o.to).integer("count", o.roots.count);

    const EquilibriumBranch b = equilibrium_branch(*system, guess, o);
    JsonEnvelope e;
    e.command = "equilibria";
    e.inputs = inputs.str();
    e.status = to_string(b.status);
    e.message = b.message;
    e.result = equilibrium_branch_json(b, variables);
    const std::string csv = equilibrium_branch_csv(b, variables);
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "branch     " << b.points.size() << " points in " << args.par << " from " << rounded(o.from) << " towards " << rounded(o.to)
            << " (ended: " << to_string(b.stop) << ")\n";
        const std::size_t shown = std::min<std::size_t>(variables.size(), 3);
        out << "  " << pad(args.par, 14);
        for (std::size_t i = 0; i < shown; ++i) out << pad(variables[i], 14);
        out << pad("abscissa", 14) << "unstable  stable\n";
        for (const EquilibriumPoint& p : b.points) {
            out << "  " << pad(rounded(p.par, 8), 14);
            for (std::size_t i = 0; i < shown; ++i) out << pad(rounded(p.x[static_cast<Eigen::Index>(i)], 8), 14);
            out << pad(rounded(p.abscissa, 6), 14) << pad(std::to_string(p.unstable), 10) << (p.stable ? "yes" : "no") << "\n";
        }
        for (const FoldPoint& f : b.folds)
            out << "fold       " << args.par << " = " << rounded(f.par, 12) << " (" << to_string(f.status) << ", residual " << rounded(f.residual, 2)
                << ")\n";
        for (const HopfPoint& h : b.hopf)
            out << "hopf       " << args.par << " = " << rounded(h.par, 12) << ", omega = " << rounded(h.omega, 12) << " (" << to_string(h.status)
                << ", residual " << rounded(h.residual, 2) << ")\n";
        if (b.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(b.status) << "): " << b.message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".csv " << prefix << ".json\n";
        std::cout << out.str();
    });
    if (b.status != Status::Converged) std::cerr << "ddemap: undecided: " << b.message << "\n";
    return exit_code(b.status);
}

}  // namespace ddemap::cli
