// equilibria: a branch of equilibria of a nonlinear DDE in one parameter (a system file with
// expressions, or the built-in ov ring), its stability, folds and Hopf points; with --par2 the fold
// curves through its folds in two parameters, with their cusp and Bogdanov-Takens points.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "nonlinear_flags.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/json.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {

struct EquilibriaArgs {
    NonlinearProblemArgs problem;
    std::string count = "4", points = "400";
    std::string par2, from2, to2, svg;
    std::string branch_point;
    FormatArg format;
    OutArg out;
} equilibria_args;

/// equilibria --par2: the fold curves through the folds of the branch in --par.
int run_fold_curves(NonlinearProblemArgs::Problem& pb, const EquilibriumBranchOptions& o, Format format, const std::string& prefix) {
    const EquilibriaArgs& a = equilibria_args;
    const NonlinearDDE& system = *pb.system;
    FoldCurveOptions co;
    second_parameter(pb, o, a.par2, a.from2, a.to2, co);
    const std::string svg_file = a.svg.empty() ? std::string() : output_file("--svg", a.svg);

    co.branch.progress = branch_progress_printer("equilibria", "points", a.problem.par, true, true);
    co.progress = branch_progress_printer("equilibria", "fold-curve points", a.problem.par, false);
    const FoldCurves fc = fold_curves(system, pb.guess, co);
    co.branch.progress = nullptr;  // ends an open progress line before the output
    co.progress = nullptr;
    JsonEnvelope e;
    e.command = "equilibria";
    e.inputs = pb.inputs.str();
    e.has_solver = true;
    e.solver_given = solver_name(o.roots.method);
    e.solver_used = e.solver_given;
    e.status = to_string(fc.status);
    e.message = fc.message;
    e.result = fold_curves_json(fc, a.par2, pb.variables);
    const std::string csv = fold_curves_csv(fc, a.par2, pb.variables, pb.units);
    std::vector<std::pair<std::string, std::string>> files;
    if (!prefix.empty()) files = {{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}};
    if (!svg_file.empty()) {
        const std::string title = "Fold curves of equilibria in (" + a.problem.par + ", " + a.par2 + ")" + a.problem.ring_title();
        files.push_back({svg_file, two_parameter_svg(nullptr, &fc, a.problem.par, a.par2, o.from, o.to, co.from2, co.to2, pb.unit(a.problem.par), pb.unit(a.par2), title)});
    }
    if (!files.empty()) write_files_atomic(files);
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        const std::string& par = a.problem.par;
        out << "branch     " << fc.start.points.size() << (fc.start.points.size() == 1 ? " equilibrium" : " equilibria") << " in " << par << " from " << rounded(o.from) << " to "
            << rounded(o.to) << ", " << counted(static_cast<long long>(fc.start.folds.size()), "fold") << "\n";
        for (std::size_t k = 0; k < fc.curves.size(); ++k) {
            const FoldCurve& c = fc.curves[k];
            out << "curve " << k << "    from fold " << c.start << ": " << counted(static_cast<long long>(c.points.size()), "point") << " in (" << par << ", " << a.par2
                << "), ended " << to_string(c.stop_backward) << " and " << to_string(c.stop_forward) << ", " << to_string(c.status) << "\n";
            out << "  " << pad(par, 14) << pad(a.par2, 14) << pad("cusp test", 13) << pad("BT test", 13) << "unstable\n";
            const std::size_t step = std::max<std::size_t>(1, c.points.size() / 20);
            for (std::size_t i = 0; i < c.points.size(); i += step) {
                const FoldCurvePoint& p = c.points[i];
                out << "  " << pad(rounded(p.par, 8), 14) << pad(rounded(p.par2, 8), 14) << pad(std::isfinite(p.cusp_test) ? rounded(p.cusp_test, 4) : "-", 13)
                    << pad(std::isfinite(p.bt_test) ? rounded(p.bt_test, 4) : "-", 13) << (p.unstable >= 0 ? std::to_string(p.unstable) : std::string("-")) << "\n";
            }
            for (const FoldCurveSpecialPoint& p : c.special)
                out << "  "
                    << (p.kind == "cusp"              ? std::string("cusp (two fold curves meet)")
                        : p.kind == "bogdanov_takens" ? std::string("Bogdanov-Takens (a double root at 0; a Hopf curve ends here)")
                                                      : "zero-Hopf (a pair +-i " + rounded(p.omega, 8) + " on the axis; a Hopf curve crosses here)")
                    << ": " << par << " = " << rounded(p.par, 10) << ", " << a.par2 << " = " << rounded(p.par2, 10) << " (" << to_string(p.status)
                    << ", residual " << rounded(p.residual, 2) << ")"
                    << (p.kind == "bogdanov_takens" && std::isfinite(p.nf_a) ? "; normal form a = " + rounded(p.nf_a, 8) + ", b = " + rounded(p.nf_b, 8) : std::string())
                    << (p.kind == "cusp" && std::isfinite(p.nf_c) ? "; normal form c = " + rounded(p.nf_c, 8) : std::string()) << "\n";
        }
        if (fc.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(fc.status) << "): " << fc.message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".csv " << prefix << ".json\n";
        if (!svg_file.empty()) out << "wrote      " << svg_file << "\n";
        std::cout << out.str();
    });
    if (fc.status != Status::Converged) std::cerr << "ddemap: undecided: " << fc.message << "\n";
    return exit_code(fc.status);
}

}  // namespace

void add_equilibria_flags(CLI::App& app) {
    equilibria_args.problem.add_to(app);
    app.add_option("--count", equilibria_args.count, "rightmost roots reported at every point")->capture_default_str();
    app.add_option("--max-points", equilibria_args.points, "the most points of the branch (and of each fold curve per direction)")->capture_default_str();
    app.add_option("--par2", equilibria_args.par2, "a second parameter: continue the folds in (--par, --par2), with their cusp and Bogdanov-Takens points")
        ->type_name("NAME");
    app.add_option("--from2", equilibria_args.from2, "--par2: the lower end of its box (its value in the system must lie in [from2, to2])")->type_name("NUMBER");
    app.add_option("--to2", equilibria_args.to2, "--par2: the upper end of its box")->type_name("NUMBER");
    app.add_option("--svg", equilibria_args.svg, "--par2: the two-parameter diagram (fold curves; cusp and Bogdanov-Takens points)")->type_name("FILE");
    app.add_option("--branch-point", equilibria_args.branch_point,
                   "switch at branch point K of the branch (from 0, in the order met) onto the other branch of equilibria through it and follow "
                   "that one on both sides of the point (the half away from --to, then the half towards it, joined; at a pitchfork both sides of the "
                   "broken symmetry); PREFIX-switched.csv, JSON result.switched")
        ->type_name("K");
    equilibria_args.format.add_to(app);
    equilibria_args.out.add_to(app, "PREFIX.csv (one row per point and special point, or per fold-curve point with --par2) and PREFIX.json", false);
    run_flags().add_to(app, false);
}

int run_equilibria() {
    const Format format = equilibria_args.format.parse();
    const bool switching = !equilibria_args.branch_point.empty();
    if (switching && !equilibria_args.par2.empty()) throw BadInput("--branch-point: not with --par2 (expected one branch in --par)");
    const int bp_index = switching ? static_cast<int>(parse_integer("--branch-point", equilibria_args.branch_point, 0, 1000000, "an integer >= 0")) : -1;
    const std::string prefix = !equilibria_args.out.given() ? std::string()
                               : switching              ? equilibria_args.out.prepare("equilibria", {".csv", ".json", "-switched.csv"})
                                                        : equilibria_args.out.prepare("equilibria");
    NonlinearProblemArgs::Problem pb = equilibria_args.problem.load();
    EquilibriumBranchOptions o;
    o.parameter = equilibria_args.problem.par;
    o.from = pb.from;
    o.to = pb.to;
    o.roots.count = static_cast<int>(parse_integer("--count", equilibria_args.count, 1, 100, "an integer between 1 and 100"));
    o.continuation.max_points = static_cast<int>(parse_integer("--max-points", equilibria_args.points, 2, 100000, "an integer between 2 and 100000"));
    o.before_roots = branch_roots_guard("equilibria");
    std::unique_ptr<NonlinearDDE>& system = pb.system;
    const std::vector<std::string>& variables = pb.variables;
    const Eigen::VectorXd& guess = pb.guess;
    JsonObject& inputs = pb.inputs;
    inputs.string("par", equilibria_args.problem.par).number("from", o.from).number("to", o.to).integer("count", o.roots.count);
    const bool two = !equilibria_args.par2.empty();
    if (!two && (!equilibria_args.from2.empty() || !equilibria_args.to2.empty())) throw BadInput("--from2/--to2 without --par2: expected --par2 NAME with them");
    if (!two && !equilibria_args.svg.empty()) throw BadInput("--svg = '" + equilibria_args.svg + "' draws the curves of --par2: expected --par2 NAME with it");
    if (two) return run_fold_curves(pb, o, format, prefix);

    o.progress = branch_progress_printer("equilibria", "points", equilibria_args.problem.par, true, true);
    EquilibriumBranch b = equilibrium_branch(*system, guess, o);
    o.progress = nullptr;  // ends an open progress line before the output
    // the other branch through branch point K (--branch-point)
    EquilibriumBranch nb;
    const FoldPoint* bp = nullptr;
    if (switching) {
        std::vector<const FoldPoint*> points;
        for (const FoldPoint& f : b.folds)
            if (f.kind == "branch_point") points.push_back(&f);
        if (points.empty())
            throw BadInput("--branch-point = '" + equilibria_args.branch_point + "': the branch has no branch point in " + equilibria_args.problem.par + " from " +
                           equilibria_args.problem.from + " to " + equilibria_args.problem.to + " (expected at least one to switch at)");
        if (bp_index >= static_cast<int>(points.size()))
            throw BadInput("--branch-point = '" + equilibria_args.branch_point + "': expected an index from 0 to " + std::to_string(points.size() - 1) +
                           " (the branch has " + counted(static_cast<long long>(points.size()), "branch point") + ")");
        bp = points[static_cast<std::size_t>(bp_index)];
        inputs.integer("branch_point", bp_index);
        if (bp->status != Status::Converged) {
            nb.status = bp->status;
            nb.message = "branch point " + std::to_string(bp_index) + " was not located: no branch switched onto";
        } else {
            o.progress = branch_progress_printer("equilibria", "points of the other branch", equilibria_args.problem.par, true, true);
            nb = equilibrium_branch_from_branch_point(*system, b, *bp, o, BranchSide::Both);
            o.progress = nullptr;
        }
        if (nb.status != Status::Converged && b.status == Status::Converged) {
            b.status = nb.status;
            b.message = "the other branch at the branch point: " + nb.message;
        }
    }
    JsonEnvelope e;
    e.command = "equilibria";
    e.inputs = inputs.str();
    e.has_solver = true;  // the roots of every equilibrium; special points by Newton on their defining systems
    e.solver_given = solver_name(o.roots.method);
    e.solver_used = e.solver_given;
    e.status = to_string(b.status);
    e.message = b.message;
    e.result = equilibrium_branch_json(b, variables);
    if (switching) {
        JsonObject from;
        from.integer("index", bp_index).number("par", bp->par);
        const std::string other = equilibrium_branch_json(nb, variables);
        e.result = e.result.substr(0, e.result.size() - 1) + ",\"switched\":{\"from\":" + from.str() + "," + other.substr(1) + "}";
    }
    const std::string csv = equilibrium_branch_csv(b, variables, pb.units);
    if (!prefix.empty()) {
        if (switching)
            write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + "-switched.csv", equilibrium_branch_csv(nb, variables, pb.units)}});
        else
            write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    }
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        auto table = [&](const EquilibriumBranch& br) {
            const std::size_t shown = std::min<std::size_t>(variables.size(), 3);
            out << "  " << pad(equilibria_args.problem.par, 14);
            for (std::size_t i = 0; i < shown; ++i) out << pad(variables[i], 14);
            out << pad("abscissa", 14) << "unstable  stable\n";
            for (const EquilibriumPoint& p : br.points) {
                out << "  " << pad(rounded(p.par, 8), 14);
                for (std::size_t i = 0; i < shown; ++i) out << pad(rounded(p.x[static_cast<Eigen::Index>(i)], 8), 14);
                // where the roots did not converge there is no verdict: "-" and "undecided"
                const bool decided = p.roots_status == Status::Converged && std::isfinite(p.abscissa);
                out << pad(decided ? rounded(p.abscissa, 6) : "-", 14) << pad(decided ? std::to_string(p.unstable) : "-", 10)
                    << (!decided ? "undecided" : p.stable ? "yes" : "no") << "\n";
            }
            for (const FoldPoint& f : br.folds)
                out << pad(f.kind + " ", 11) << equilibria_args.problem.par << " = " << rounded(f.par, 12) << " (" << to_string(f.status) << ", residual "
                    << rounded(f.residual, 2) << ")\n";
            for (const HopfPoint& h : br.hopf)
                out << "hopf       " << equilibria_args.problem.par << " = " << rounded(h.par, 12) << ", omega = " << rounded(h.omega, 12) << " (" << to_string(h.status)
                    << ", residual " << rounded(h.residual, 2) << ")\n";
        };
        out << "branch     " << counted(static_cast<long long>(b.points.size()), "point") << " in " << equilibria_args.problem.par << " from " << rounded(o.from) << " towards " << rounded(o.to)
            << " (ended: " << to_string(b.stop) << ")\n";
        table(b);
        if (switching) {
            out << "switched   at the branch point " << equilibria_args.problem.par << " = " << rounded(bp->par, 12) << ": the other branch, "
                << counted(static_cast<long long>(nb.points.size()), "point")
                << (nb.message.rfind("one half only", 0) == 0 ? ", one half only (the other did not start)" : ", both halves through the point")
                << " (ended: " << to_string(nb.stop) << ")\n";
            table(nb);
        }
        if (b.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(b.status) << "): " << b.message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".csv " << prefix << ".json" << (switching ? " " + prefix + "-switched.csv" : std::string()) << "\n";
        std::cout << out.str();
    });
    if (b.status != Status::Converged) std::cerr << "ddemap: undecided: " << b.message << "\n";
    return exit_code(b.status);
}

}  // namespace ddemap::cli
