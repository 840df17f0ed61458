// mix: the penetration-rate study (study/penetration) on a ring of N cars.
#include <utility>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "fleet_flags.hpp"
#include "limits.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/penetration.hpp"

namespace ddemap::cli {

namespace {
struct MixArgs {
    std::string x, y, cars, p = "0:1:11", draws = "0", seed = "1", speed, length, solver = "auto";
    RingArg ring;
    FormatArg format;
    OutArg out;
} mix_args;
}  // namespace

void add_mix_flags(CLI::App& app) {
    app.add_option("--x", mix_args.x, std::string("type X: one car, given as any car list that names one car: ") + cars_help())->required()->type_name("CAR");
    app.add_option("--y", mix_args.y, "type Y: as --x")->required()->type_name("CAR");
    mix_args.ring.add_to(app, "40", "ring size N >= 2 (finite)");
    app.add_option("--cars", mix_args.cars, "old spelling of --ring")->group("");
    app.add_option("--p", mix_args.p, "fractions of X as LO:HI:COUNT in [0, 1]")->capture_default_str();
    app.add_option("--draws", mix_args.draws, "random arrangements per p besides the evenly spread one (order matters only for CCC)")->capture_default_str();
    app.add_option("--seed", mix_args.seed, "seed of the random arrangements")->capture_default_str();
    app.add_option("--speed", mix_args.speed, "common equilibrium speed [m/s] (default 20)");
    app.add_option("--length", mix_args.length, "ring length [m]; the speed follows for each mix");
    app.add_option("--solver", mix_args.solver, "auto, product, dense or sparse (as roots --fleet)")->capture_default_str();
    mix_args.out.add_to(app, "PREFIX.csv, PREFIX.json and PREFIX.svg", true);
    mix_args.format.add_to(app);
    run_flags().add_to(app, true);
}

namespace {

/// The size guard of mix, before any work: every arrangement is one mixed ring of N cars (2N
/// states) solved on its own, one after the other. Per arrangement, in CPU time of one core
/// (A_min and C_max, measured with mix --quiet): the product path about 1e-5 s per car (0.27 s
/// at N = 40,000) and 2 kB per car; the sparse path about 4e-5 n^1.6 s (n = 2N states: 0.53 s
/// at N = 200; the exponent from N = 200 and 1,000) and 25 kB per state; the dense path about
/// 1e-5 n^3 s (1.6 s at N = 30), its collocation matrix of (M + 1) n complex rows held dense
/// (about 16 (32 n)^2 bytes at the degrees these rings reach: 240 MB at N = 60; the degree
/// grows only to DenseRootOptions::max_rows = 3000 rows, so above about 50 cars the dense
/// path may stop undecided, budget_exhausted, rather than use more). The output:
/// about 600 bytes per fraction (a CSV row, a JSON record and an SVG marker).
/// Checks the study's size; returns what it is and its estimated run time (announced once the
/// output is prepared).
std::pair<std::string, double> size_mix(const MixOptions& o) {
    const double arrangements = static_cast<double>(o.fractions.size()) * (o.draws + 1.0);
    const double cars = o.cars, n = 2.0 * o.cars;
    const std::string& method = o.ring.roots.method;
    double seconds = 0.0, bytes = 0.0;
    if (method == "dense") {
        seconds = 1e-5 * n * n * n;
        bytes = 16.0 * (32.0 * n) * (32.0 * n);
    } else if (method == "shift_invert") {
        seconds = 4e-5 * std::pow(n, 1.6);
        bytes = 2.5e4 * n;
    } else {  // auto: the product path (every law reacts to the car ahead, ccc also to the car two ahead)
        seconds = 1e-5 * cars;
        bytes = 2e3 * cars;
    }
    char what[160];
    std::snprintf(what, sizeof what, "%.0f arrangement%s of a %d-car ring (%s path)", arrangements, arrangements == 1.0 ? "" : "s", o.cars,
                  solver_name(method == "auto" ? std::string("contour") : method).c_str());
    check_size("mix", what, "memory", bytes);
    check_size("mix", what, "output", 600.0 * static_cast<double>(o.fractions.size()));
    check_size("mix", what, "time", seconds * arrangements);
    return {what, seconds * arrangements};
}

}  // namespace

int run_mix() {
    const Format format = mix_args.format.parse();
    const FleetCar x = car_argument("--x", mix_args.x), y = car_argument("--y", mix_args.y);
    if (mix_args.ring.given() && !mix_args.cars.empty()) throw BadInput("--ring and --cars: expected only --ring (--cars is its old spelling)");
    RingArg ring = mix_args.ring;
    if (!mix_args.cars.empty()) ring.text = mix_args.cars;
    MixOptions o;
    o.cars = ring.parse(false);
    const Axis axis = parse_axis("--p", mix_args.p);
    for (int i = 0; i < axis.count; ++i) {
        const double p = axis.value(i);
        if (!(p >= 0.0 && p <= 1.0))
            throw BadInput("--p = '" + mix_args.p + "': the fraction " + json_number(p) + ": expected fractions of X in [0, 1]");
        o.fractions.push_back(p);
    }
    o.draws = static_cast<int>(parse_integer("--draws", mix_args.draws, 0, 10000, "an integer 0..10000"));
    o.seed = static_cast<unsigned>(parse_integer("--seed", mix_args.seed, 0, 4294967295L, "an integer 0..4294967295"));
    set_equilibrium(o.ring, mix_args.speed, mix_args.length);
    o.ring.roots.method = root_method(mix_args.solver);
    o.ring.roots.count = 4;
    o.validate();
    const std::pair<std::string, double> size = size_mix(o);
    const std::string prefix = mix_args.out.prepare("mix");
    announce_estimate("mix", size.first, size.second);
    // one line per arrangement solved: ddemap: mix: arrangements 3/11, p = 0.2 (1.2 s, about 3 s left)
    o.progress = branch_progress_printer("mix", "arrangements", "p", true);
    const std::vector<MixPoint> pts = penetration_study(x, y, o);
    Status status = Status::Converged;
    std::string used;
    for (const auto& pt : pts) {
        if (pt.status != Status::Converged) status = pt.status;
        const std::string u = solver_name(pt.method_used);
        if (used.find(u) == std::string::npos) used += (used.empty() ? "" : ",") + u;
    }
    JsonEnvelope e;
    e.command = "mix";
    JsonObject in;
    in.string("x", mix_args.x).string("y", mix_args.y).integer("ring", o.cars).json("p", json_array([&] {
        std::vector<std::string> v;
        for (double f : o.fractions) v.push_back(json_number(f));
        return v;
    }()));
    in.integer("draws", o.draws).integer("seed", o.seed);
    equilibrium_inputs(in, o.ring);
    e.inputs = in.str();
    e.has_solver = true;
    e.solver_given = solver_name(o.ring.roots.method);
    e.solver_used = used;
    e.status = to_string(status);
    e.message = mix_message(pts);
    e.result = mix_json(pts, o.cars);
    const std::string csv = mix_csv(pts);
    write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", mix_svg(pts, o, x.label, y.label)}});
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "p      k   abscissa        stable\n";
        for (const auto& pt : pts) {
            char line[160];
            std::snprintf(line, sizeof line, "%-6.3f %-3d %-15.8f %s\n", pt.fraction, pt.x_cars, pt.abscissa,
                          pt.status != Status::Converged ? "UNDECIDED" : pt.stable ? "yes" : "no");
            out << line;
        }
        out << "wrote      " << prefix << ".csv " << prefix << ".json " << prefix << ".svg\n";
        std::cout << out.str();
    });
    for (const auto& pt : pts)  // the reason of each UNDECIDED on stderr
        report_undecided(pt.status, "mix: p = " + rounded(pt.fraction, 6), "an arrangement's roots did not converge");
    return exit_code(status);
}

}  // namespace ddemap::cli
