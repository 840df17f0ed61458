// hopf: the Hopf points of a nonlinear DDE on its equilibrium branch in one parameter, with their
// criticality (first Lyapunov coefficient), crossing speed and predicted orbit amplitudes; with
// --par2 the Hopf curves through them in two parameters.
#include <iostream>
#include <memory>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "nonlinear_flags.hpp"
#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/hopf_output.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap::cli {

namespace {

struct HopfArgs {
    NonlinearProblemArgs problem;
    std::string par2, from2, to2, points = "400", svg;
    FormatArg format;
    OutArg out;
} hopf_args;


std::string side_word(int side) { return side > 0 ? "above" : side < 0 ? "below" : "-"; }

}  // namespace

void add_hopf_flags(CLI::App& app) {
    hopf_args.problem.add_to(app);
    app.add_option("--par2", hopf_args.par2, "a second parameter: continue the Hopf curves in (--par, --par2)")->type_name("NAME");
    app.add_option("--from2", hopf_args.from2, "--par2: the lower end of its box (its value in the system must lie in [from2, to2])")->type_name("NUMBER");
    app.add_option("--to2", hopf_args.to2, "--par2: the upper end of its box")->type_name("NUMBER");
    app.add_option("--max-points", hopf_args.points, "the most points of the branch, and of a Hopf curve in each direction")->capture_default_str();
    app.add_option("--svg", hopf_args.svg, "--par2: the two-parameter diagram (Hopf curves by criticality; generalised, double and zero-Hopf points)")
        ->type_name("FILE");
    hopf_args.format.add_to(app);
    hopf_args.out.add_to(app, "PREFIX.csv (one row per Hopf point, or per curve point with --par2) and PREFIX.json", false);
    run_flags().add_to(app, false);
}

int run_hopf() {
    const Format format = hopf_args.format.parse();
    const std::string prefix = hopf_args.out.given() ? hopf_args.out.prepare("hopf", {".csv", ".json"}) : std::string();
    NonlinearProblemArgs::Problem pb = hopf_args.problem.load();
    if (!(pb.from < pb.to)) throw BadInput("--from = '" + hopf_args.problem.from + "', --to = '" + hopf_args.problem.to + "': expected --from < --to");
    const bool two = !hopf_args.par2.empty();
    if (!two && (!hopf_args.from2.empty() || !hopf_args.to2.empty())) throw BadInput("--from2/--to2 without --par2: expected --par2 NAME with them");
    if (!two && !hopf_args.svg.empty()) throw BadInput("--svg = '" + hopf_args.svg + "' draws the curves of --par2: expected --par2 NAME with it");
    const std::string svg_file = hopf_args.svg.empty() ? std::string() : output_file("--svg", hopf_args.svg);
    EquilibriumBranchOptions o;
    o.parameter = hopf_args.problem.par;
    o.from = pb.from;
    o.to = pb.to;
    const int max_points = static_cast<int>(parse_integer("--max-points", hopf_args.points, 2, 100000, "an integer between 2 and 100000"));
    o.continuation.max_points = max_points;
    o.before_roots = branch_roots_guard("hopf");
    const NonlinearDDE& system = *pb.system;
    JsonObject& inputs = pb.inputs;
    inputs.string("par", hopf_args.problem.par).number("from", o.from).number("to", o.to);

    HopfCurveOptions co;
    if (two) second_parameter(pb, o, hopf_args.par2, hopf_args.from2, hopf_args.to2, co);

    JsonEnvelope e;
    e.command = "hopf";
    e.inputs = inputs.str();
    e.has_solver = true;  // the roots of every equilibrium; special points by Newton on their defining systems
    e.solver_given = solver_name(o.roots.method);
    e.solver_used = e.solver_given;
    std::string csv;
    Status status = Status::Converged;
    std::string message;
    HopfCurves curves;
    HopfAnalysis points;
    if (two) {
        co.branch.progress = branch_progress_printer("hopf", "equilibria", hopf_args.problem.par, true, true);
        co.progress = branch_progress_printer("hopf", "curve points", hopf_args.problem.par, false);
        curves = hopf_curves(system, pb.guess, co);
        co.branch.progress = nullptr;  // ends an open progress line before the output
        co.progress = nullptr;
        status = curves.status;
        message = curves.message;
        e.result = hopf_curves_json(curves, hopf_args.par2, pb.variables);
        csv = hopf_curves_csv(curves, hopf_args.par2, pb.units);
    } else {
        o.progress = branch_progress_printer("hopf", "equilibria", hopf_args.problem.par, true, true);
        points = hopf_points(system, pb.guess, o);
        o.progress = nullptr;
        status = points.status;
        message = points.message;
        e.result = hopf_points_json(points, pb.variables);
        csv = hopf_points_csv(points, pb.variables, pb.units);
    }
    e.status = to_string(status);
    e.message = message;
    const HopfAnalysis& start = two ? curves.start : points;
    std::vector<std::pair<std::string, std::string>> files;
    if (!prefix.empty()) files = {{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}};
    if (!svg_file.empty()) {
        const std::string title = "Hopf curves in (" + hopf_args.problem.par + ", " + hopf_args.par2 + ")" + hopf_args.problem.ring_title();
        files.push_back({svg_file, two_parameter_svg(&curves, nullptr, hopf_args.problem.par, hopf_args.par2, o.from, o.to, co.from2, co.to2,
                                                     pb.unit(hopf_args.problem.par), pb.unit(hopf_args.par2), title)});
    }
    if (!files.empty()) write_files_atomic(files);
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        const std::string& par = hopf_args.problem.par;
        out << "branch     " << start.branch.points.size() << " equilibria in " << par << " from " << rounded(o.from) << " to " << rounded(o.to)
            << ", " << start.points.size() << " Hopf points\n";
        out << "  " << pad(par, 14) << pad("omega", 12) << pad("L1", 13) << pad("criticality", 15) << pad("dRe/d" + par, 13) << pad("orbit side", 12) << "max range/sqrt|mu|\n";
        for (const HopfCoefficients& c : start.points) {
            const bool ok = converged(c.status);
            out << "  " << pad(rounded(c.par, 8), 14) << pad(rounded(c.omega, 6), 12) << pad(ok ? rounded(c.l1, 4) : "-", 13)
                << pad(criticality_word(c), 15) << pad(ok ? rounded(c.dre_dpar, 4) : "-", 13) << pad(ok ? side_word(c.side) : "-", 12)
                << (c.amplitude_coefficient.size() > 0 ? rounded(c.amplitude_coefficient.maxCoeff(), 4) : "-") << "\n";
        }
        if (two)
            for (std::size_t k = 0; k < curves.curves.size(); ++k) {
                const HopfCurve& c = curves.curves[k];
                out << "curve " << k << "    " << (c.start >= 0 ? "from Hopf point " + std::to_string(c.start) : std::string("from a double Hopf point")) << ": " << counted(static_cast<long long>(c.points.size()), "point") << " in (" << par << ", " << hopf_args.par2
                    << "), " << to_string(c.status) << "\n";
                out << "  " << pad(par, 14) << pad(hopf_args.par2, 14) << pad("omega", 12) << pad("L1", 13) << "criticality\n";
                const std::size_t step = std::max<std::size_t>(1, c.points.size() / 20);
                for (std::size_t i = 0; i < c.points.size(); i += step) {
                    const HopfCurvePoint& p = c.points[i];
                    const bool ok = converged(p.coefficients.status);
                    out << "  " << pad(rounded(p.par, 8), 14) << pad(rounded(p.par2, 8), 14) << pad(rounded(p.omega, 6), 12)
                        << pad(ok ? rounded(p.coefficients.l1, 4) : "-", 13) << criticality_word(p.coefficients) << "\n";
                }
                for (const GeneralisedHopfPoint& g : c.generalised)
                    out << "  generalised Hopf (L1 = 0): " << par << " = " << rounded(g.par, 10) << ", " << hopf_args.par2 << " = " << rounded(g.par2, 10)
                        << ", omega = " << rounded(g.omega, 8) << " (" << to_string(g.status) << ")"
                        << (g.normal_form.status == Status::Converged ? ", L2 = " + rounded(g.normal_form.l2, 6) : std::string()) << "\n";
                for (const DoubleHopfPoint& d : c.double_hopf)
                    out << (d.resonant ? "  double Hopf, 1:1 resonant: " : "  double Hopf: ") << par << " = " << rounded(d.par, 10) << ", " << hopf_args.par2 << " = " << rounded(d.par2, 10) << ", omega = "
                        << rounded(d.omega1, 8) << " and " << rounded(d.omega2, 8)
                        << (d.other_curve >= 0 ? " (crossing curve " + std::to_string(d.other_curve) + ")" : std::string()) << " (" << to_string(d.status)
                        << ", residual " << rounded(d.residual, 2) << ")"
                        << (d.normal_form.status == Status::Converged
                                ? (std::isfinite(d.normal_form.theta) && std::isfinite(d.normal_form.delta)
                                       ? ", normal form theta = " + rounded(d.normal_form.theta, 6) + ", delta = " + rounded(d.normal_form.delta, 6)
                                       : ", normal form " + d.normal_form.message)
                                : std::string())
                        << "\n";
                for (const HopfCurveBogdanovTakens& b : c.bogdanov_takens)
                    out << "  Bogdanov-Takens (omega -> 0 at its " << (b.forward ? "forward" : "backward") << " end): " << par << " = " << rounded(b.par, 10)
                        << ", " << hopf_args.par2 << " = " << rounded(b.par2, 10) << " (" << to_string(b.status) << ")"
                        << (b.normal_form.status == Status::Converged ? ", normal form a = " + rounded(b.normal_form.a, 6) + ", b = " + rounded(b.normal_form.b, 6)
                                                                       : std::string())
                        << "\n";
                for (const ZeroHopfPoint& z : c.zero_hopf)
                    out << "  zero-Hopf (a real root at 0): " << par << " = " << rounded(z.par, 10) << ", " << hopf_args.par2 << " = " << rounded(z.par2, 10)
                        << ", omega = " << rounded(z.omega, 8) << " (" << to_string(z.status) << ")"
                        << (z.normal_form.status == Status::Converged
                                ? ", normal form s = " + rounded(z.normal_form.s, 6) +
                                      (std::isfinite(z.normal_form.theta) ? ", theta = " + rounded(z.normal_form.theta, 6) : std::string()) +
                                      (std::isfinite(z.normal_form.e) ? ", e = " + rounded(z.normal_form.e, 6) : ", " + z.normal_form.message)
                                : std::string()) << "\n";
            }
        if (status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(status) << "): " << message << "\n";
        if (!prefix.empty()) out << "wrote      " << prefix << ".csv " << prefix << ".json\n";
        if (!svg_file.empty()) out << "wrote      " << svg_file << "\n";
        std::cout << out.str();
    });
    return report_undecided(status, "hopf", message);
}

}  // namespace ddemap::cli
