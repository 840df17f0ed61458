// equilibria: a branch of equilibria of a nonlinear DDE in one parameter (a system file with
// expressions, or the built-in ov ring), its stability, folds and Hopf points.
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "nonlinear_flags.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {

struct EquilibriaArgs {
    NonlinearProblemArgs problem;
    std::string count = "4", points = "400";
    FormatArg format;
    OutArg out;
} equilibria_args;

/// Left-aligned in a column of width w (at least one space after).

}  // namespace

void add_equilibria_flags(CLI::App& app) {
    equilibria_args.problem.add_to(app);
    app.add_option("--count", equilibria_args.count, "rightmost roots reported at every point")->capture_default_str();
    app.add_option("--max-points", equilibria_args.points, "the most points of the branch")->capture_default_str();
    equilibria_args.format.add_to(app);
    equilibria_args.out.add_to(app, "PREFIX.csv (one row per point and special point) and PREFIX.json", false);
    run_flags().add_to(app, false);
}

int run_equilibria() {
    const Format format = equilibria_args.format.parse();
    const std::string prefix = equilibria_args.out.given() ? equilibria_args.out.prepare("equilibria") : std::string();
    NonlinearProblemArgs::Problem pb = equilibria_args.problem.load();
    EquilibriumBranchOptions o;
    o.parameter = equilibria_args.problem.par;
    o.from = pb.from;
    o.to = pb.to;
    o.roots.count = static_cast<int>(parse_integer("--count", equilibria_args.count, 1, 100, "an integer between 1 and 100"));
    o.continuation.max_points = static_cast<int>(parse_integer("--max-points", equilibria_args.points, 2, 100000, "an integer between 2 and 100000"));
    std::unique_ptr<NonlinearDDE>& system = pb.system;
    const std::vector<std::string>& variables = pb.variables;
    const Eigen::VectorXd& guess = pb.guess;
    JsonObject& inputs = pb.inputs;
    inputs.string("par", equilibria_args.problem.par).number("from", o.from).number("to", o.to).integer("count", o.roots.count);

    o.progress = branch_progress_printer("equilibria", "points", equilibria_args.problem.par, true);
    const EquilibriumBranch b = equilibrium_branch(*system, guess, o);
    o.progress = nullptr;  // ends an open progress line before the output
    JsonEnvelope e;
    e.command = "equilibria";
    e.inputs = inputs.str();
    e.has_solver = true;  // the roots of every equilibrium; special points by Newton on their defining systems
    e.solver_given = solver_name(o.roots.method);
    e.solver_used = e.solver_given;
    e.status = to_string(b.status);
    e.message = b.message;
    e.result = equilibrium_branch_json(b, variables);
    const std::string csv = equilibrium_branch_csv(b, variables, pb.units);
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "branch     " << counted(static_cast<long long>(b.points.size()), "point") << " in " << equilibria_args.problem.par << " from " << rounded(o.from) << " towards " << rounded(o.to)
            << " (ended: " << to_string(b.stop) << ")\n";
        const std::size_t shown = std::min<std::size_t>(variables.size(), 3);
        out << "  " << pad(equilibria_args.problem.par, 14);
        for (std::size_t i = 0; i < shown; ++i) out << pad(variables[i], 14);
        out << pad("abscissa", 14) << "unstable  stable\n";
        for (const EquilibriumPoint& p : b.points) {
            out << "  " << pad(rounded(p.par, 8), 14);
            for (std::size_t i = 0; i < shown; ++i) out << pad(rounded(p.x[static_cast<Eigen::Index>(i)], 8), 14);
            out << pad(rounded(p.abscissa, 6), 14) << pad(std::to_string(p.unstable), 10) << (p.stable ? "yes" : "no") << "\n";
        }
        for (const FoldPoint& f : b.folds)
            out << pad(f.kind + " ", 11) << equilibria_args.problem.par << " = " << rounded(f.par, 12) << " (" << to_string(f.status) << ", residual " << rounded(f.residual, 2)
                << ")\n";
        for (const HopfPoint& h : b.hopf)
            out << "hopf       " << equilibria_args.problem.par << " = " << rounded(h.par, 12) << ", omega = " << rounded(h.omega, 12) << " (" << to_string(h.status)
                << ", residual " << rounded(h.residual, 2) << ")\n";
        if (b.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(b.status) << "): " << b.message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".csv " << prefix << ".json\n";
        std::cout << out.str();
    });
    if (b.status != Status::Converged) std::cerr << "ddemap: undecided: " << b.message << "\n";
    return exit_code(b.status);
}

}  // namespace ddemap::cli
