// bistability: where stable stop-and-go waves (periodic orbits) coexist with stable uniform flow
// (the equilibrium) in two parameters: Hopf curves with their criticality, curves of folds of
// periodic orbits, and the cells of the box they cut, each decided by a one-parameter slice.
#include <algorithm>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "nonlinear_flags.hpp"
#include "ddemap/analysis/bifurcation/bistability.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/io/hopf_output.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap::cli {

namespace {

struct BistabilityArgs {
    NonlinearProblemArgs problem;
    std::string par2, from2, to2, degree = "4", intervals = "40", points = "400", rows = "200";
    FormatArg format;
    OutArg out;
} bi_args;

}  // namespace

void add_bistability_flags(CLI::App& app) {
    bi_args.problem.add_to(app);
    app.add_option("--par2", bi_args.par2, "the second parameter (the vertical axis)")->required()->type_name("NAME");
    app.add_option("--from2", bi_args.from2, "the lower end of --par2's range (its value in the system must lie in [from2, to2])")->required()->type_name("NUMBER");
    app.add_option("--to2", bi_args.to2, "the upper end of --par2's range")->required()->type_name("NUMBER");
    app.add_option("--degree", bi_args.degree, "degree of the orbits' piecewise polynomials (1..20)")->capture_default_str()->type_name("INTEGER");
    app.add_option("--intervals", bi_args.intervals, "mesh intervals of the orbits over one period (2..10000)")->capture_default_str()->type_name("INTEGER");
    app.add_option("--points", bi_args.points, "the most orbits of a branch, and points of a curve in each direction")->capture_default_str()->type_name("INTEGER");
    app.add_option("--rows", bi_args.rows, "horizontal lines that cut the box into cells (4..10000)")->capture_default_str()->type_name("INTEGER");
    bi_args.format.add_to(app);
    bi_args.out.add_to(app, "PREFIX.svg (the chart), PREFIX.json and PREFIX-curves.csv (one row per curve point)", false);
    run_flags().add_to(app, true);
}

int run_bistability() {
    const Format format = bi_args.format.parse();
    const std::string prefix = bi_args.out.given() ? bi_args.out.prepare("bistability", {".svg", ".json", "-curves.csv"}) : std::string();
    NonlinearProblemArgs::Problem pb = bi_args.problem.load();
    if (!(pb.from < pb.to)) throw BadInput("--from = '" + bi_args.problem.from + "', --to = '" + bi_args.problem.to + "': expected --from < --to");
    BistabilityOptions o;
    o.parameter = bi_args.problem.par;
    o.from = pb.from;
    o.to = pb.to;
    if (bi_args.par2 == o.parameter) throw BadInput("--par2 = '" + bi_args.par2 + "': expected a parameter other than --par");
    NonlinearDDE& system = *pb.system;
    const int j2 = system.parameter_index(bi_args.par2);  // unknown: bad input naming the known ones
    o.parameter2 = bi_args.par2;
    o.from2 = parse_number("--from2", bi_args.from2);
    o.to2 = parse_number("--to2", bi_args.to2);
    if (!(o.from2 < o.to2)) throw BadInput("--from2 = '" + bi_args.from2 + "', --to2 = '" + bi_args.to2 + "': expected --from2 < --to2");
    const double held = system.parameter_values()[static_cast<std::size_t>(j2)];
    if (!(held >= o.from2 && held <= o.to2))
        throw BadInput("--par2 " + bi_args.par2 + " = " + rounded(held, 15) + " (its value in the system): expected it in [--from2, --to2]");
    o.degree = static_cast<int>(parse_integer("--degree", bi_args.degree, 1, 20, "an integer between 1 and 20"));
    o.intervals = static_cast<int>(parse_integer("--intervals", bi_args.intervals, 2, 10000, "an integer between 2 and 10000"));
    o.max_points = static_cast<int>(parse_integer("--points", bi_args.points, 2, 100000, "an integer between 2 and 100000"));
    o.rows = static_cast<int>(parse_integer("--rows", bi_args.rows, 4, 10000, "an integer between 4 and 10000"));
    {
        // sized before work: about ten slices of two orbit branches and four fold curves (the
        // 3-car ov ring: 6 slices, 3 curves), branches and curves of at most 100 points (54 on
        // that ring), measured 1.6e-5 (d / 4) N s per orbit and 1e-4 (d / 4) N s per fold point
        const double n = static_cast<double>(system.dimension());
        const double unknowns = static_cast<double>(o.intervals) * o.degree * n;
        const std::string what = "orbits on a mesh of " + std::to_string(o.intervals) + " intervals of degree " + std::to_string(o.degree) + " (" +
                                 rounded(unknowns, 3) + " unknowns), at most " + std::to_string(o.max_points) + " per branch";
        check_size("bistability", what, "memory", 4e4 * unknowns);
        check_size("bistability", what, "time", (10.0 * 2.0 * 1.6e-5 + 4.0 * 1e-4) * (o.degree / 4.0) * unknowns * std::min(o.max_points, 100));
    }
    JsonObject& inputs = pb.inputs;
    inputs.string("par", o.parameter).number("from", o.from).number("to", o.to).string("par2", o.parameter2).number("from2", o.from2).number("to2", o.to2)
        .integer("degree", o.degree).integer("intervals", o.intervals).integer("points", o.max_points).integer("rows", o.rows);

    // the equilibria: the first branch's roots sized before they start, the slices (about ten,
    // as above) alike
    o.before_roots = branch_roots_guard("bistability", "the equilibrium branch and about 10 slices like it", 11.0);
    o.progress = branch_progress_printer("bistability", "stages", o.parameter, false, true);
    const BistabilityChart chart = bistability_chart(system, pb.guess, o);
    o.progress = nullptr;

    JsonEnvelope e;
    e.command = "bistability";
    e.inputs = inputs.str();
    e.status = to_string(chart.status);
    e.message = chart.message;
    e.result = bistability_json(chart, pb.variables);
    const std::string csv = bistability_csv(chart, pb.units);
    if (!prefix.empty()) {
        const std::string u1 = pb.unit(o.parameter);
        const std::string u2 = pb.unit(o.parameter2);
        std::string title = "Bistability of stop-and-go waves and uniform flow";
        title += bi_args.problem.ring_title();
        write_files_atomic({{prefix + ".svg", bistability_svg(chart, u1, u2, title)}, {prefix + ".json", envelope_json(e)}, {prefix + "-curves.csv", csv}});
    }
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        const std::string &p1 = o.parameter, &p2 = o.parameter2;
        out << "box        " << p1 << " in [" << rounded(o.from) << ", " << rounded(o.to) << "], " << p2 << " in [" << rounded(o.from2) << ", " << rounded(o.to2) << "]\n";
        for (std::size_t k = 0; k < chart.hopf.curves.size(); ++k) {
            const HopfCurve& c = chart.hopf.curves[k];
            out << "hopf curve " << k << ": " << counted(static_cast<long long>(c.points.size()), "point") << " (" << to_string(c.status) << ")\n";
            for (const GeneralisedHopfPoint& g : c.generalised)
                out << "  generalised Hopf (L1 = 0): " << p1 << " = " << rounded(g.par, 10) << ", " << p2 << " = " << rounded(g.par2, 10) << " ("
                    << to_string(g.status) << ")\n";
            for (const DoubleHopfPoint& d : c.double_hopf)
                out << "  double Hopf" << (d.resonant ? ", 1:1 resonant" : "") << ": " << p1 << " = " << rounded(d.par, 10) << ", " << p2 << " = "
                    << rounded(d.par2, 10) << ", omega = " << rounded(d.omega1, 8) << " and " << rounded(d.omega2, 8) << " (" << to_string(d.status) << ")\n";
            for (const ZeroHopfPoint& z : c.zero_hopf)
                out << "  zero-Hopf: " << p1 << " = " << rounded(z.par, 10) << ", " << p2 << " = " << rounded(z.par2, 10) << " (" << to_string(z.status) << ")\n";
        }
        for (std::size_t k = 0; k < chart.folds.size(); ++k) {
            const OrbitFoldCurve& c = chart.folds[k];
            out << "fold curve " << k << ": " << counted(static_cast<long long>(c.points.size()), "point") << " of folds of periodic orbits, ended: " << c.stop_backward
                << " and " << c.stop_forward << " (max |g| = " << rounded(c.max_test, 2) << ")\n";
        }
        out << "cells      " << chart.cells.size() << " (cut by " << o.rows << " lines; " << chart.slices << " slices in " << p1 << ")\n";
        out << "  " << pad(p1, 14) << pad(p2, 14) << pad("equilibrium", 13) << pad("stable orbit", 14) << "verdict\n";
        for (const BistabilityCell& c : chart.cells)
            out << "  " << pad(rounded(c.par, 6), 14) << pad(rounded(c.par2, 6), 14) << pad(c.equilibrium_stable ? "stable" : "unstable", 13)
                << pad(c.stable_orbit ? "yes" : "no", 14)
                << (c.status != Status::Converged ? "UNDECIDED: " + c.message : c.bistable ? std::string("BISTABLE") : std::string("-")) << "\n";
        if (chart.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(chart.status) << "): " << chart.message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".svg " << prefix << ".json " << prefix << "-curves.csv\n";
        std::cout << out.str();
    });
    return report_undecided(chart.status, "bistability", chart.message);
}

}  // namespace ddemap::cli
