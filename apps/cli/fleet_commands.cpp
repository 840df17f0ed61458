#include "fleet_commands.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "ddemap/io/svg.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/study/sweep.hpp"
#include "common.hpp"
#include "format.hpp"

namespace ddemap::cli {

namespace {

/// speed / length flags -> ring options (default: speed 20 m/s)
void set_equilibrium(MixedRingOptions& o, const std::string& speed, const std::string& length) {
    if (!speed.empty() && !length.empty()) throw BadInput("--speed and --length: expected only one of them");
    if (!length.empty()) {
        o.length = parse_number("--length", length);
    } else {
        o.speed = speed.empty() ? 20.0 : parse_number("--speed", speed);
    }
}

json root_json(const Root& x, cplx eig) {
    return {{"re", num(x.value.real())}, {"im", num(x.value.imag())}, {"residual", num(x.residual)},
            {"newton_step", num(x.newton_step)}, {"eigenvalue_re", num(eig.real())}, {"eigenvalue_im", num(eig.imag())}};
}

}  // namespace

std::string root_method(const std::string& solver) {
    if (solver == "sparse") return "shift_invert";
    if (solver == "product") return "contour";
    if (solver == "auto" || solver == "dense" || solver == "shift_invert" || solver == "contour") return solver;
    throw BadInput("--solver = '" + solver + "': expected auto, dense, sparse or product");
}

std::string solver_name(const std::string& method) {
    if (method == "shift_invert") return "sparse";
    if (method == "contour") return "product";
    return method;
}

void FleetArgs::add_to(CLI::App* roots) {
    roots->add_option("--fleet", fleet, "a mixed ring from a CSV file (one row per car: vehicle and/or model and parameters, optional count; see README)");
    roots->add_option("--fleet-pattern", pattern, "a mixed ring from calibrated vehicles, e.g. \"A_min,C_max*3,E_min\", repeated to --cars");
    roots->add_option("--cars", cars, "number of cars for --fleet-pattern (default: the pattern once)");
    roots->add_option("--length", length, "fleet: ring length [m] (sum of the gaps); the speed follows");
    roots->add_option("--solver", solver, "--fleet: auto (product for cars that react only to the car ahead, else dense up to 8 cars and sparse beyond), product, dense or sparse; --system: auto (dense up to 16 states), dense or sparse")->capture_default_str();
    roots->add_option("--degree", degree, "--fleet (dense and sparse paths) and --system (sparse path): collocation degree M (0 = automatic)")->capture_default_str();
}

void run_fleet_roots(const FleetArgs& args, const std::string& speed, const std::string& count_text, const std::string& format_text) {
    if (!args.fleet.empty() && !args.pattern.empty()) throw BadInput("--fleet and --fleet-pattern: expected only one of them");
    const int count = static_cast<int>(parse_integer("--count", count_text, 1, 10000, "an integer between 1 and 10000"));
    const Format format = parse_format(format_text);
    Fleet fleet;
    if (!args.fleet.empty()) {
        if (!args.cars.empty()) throw BadInput("--cars goes with --fleet-pattern; a --fleet file lists every car (use its count column)");
        fleet = read_fleet_csv(read_input_file("--fleet", args.fleet), args.fleet);
    } else {
        const int cars = args.cars.empty() ? 0 : static_cast<int>(parse_integer("--cars", args.cars, 2, 1000000, "an integer 2..1000000"));
        fleet = fleet_from_pattern(args.pattern, cars);
    }
    MixedRingOptions o;
    set_equilibrium(o, speed, args.length);
    o.roots.method = root_method(args.solver);
    o.roots.count = count;
    o.roots.degree = static_cast<int>(parse_integer("--degree", args.degree, 0, 200, "0 (automatic) or an integer 2..200"));
    if (o.roots.degree == 1) throw BadInput("--degree = '1': expected 0 (automatic) or an integer 2..200");
    const MixedRingResult r = analyse_mixed_ring(fleet, o);
    const RootResult& rr = r.roots;
    std::ostringstream out;
    if (format == Format::Json) {
        json j;
        j["command"] = "roots";
        j["version"] = DDEMAP_VERSION;
        j["fleet"] = args.fleet.empty() ? args.pattern : args.fleet;
        j["cars"] = fleet.size();
        j["speed"] = num(r.equilibrium.speed);
        j["length"] = num(r.equilibrium.length);
        json roots = json::array();
        for (std::size_t i = 0; i < rr.roots.size(); ++i) roots.push_back(root_json(rr.roots[i], rr.roots[i].eigenvalue));
        j["roots"] = roots;
        j["trivial_root_found"] = r.trivial_found;
        j["trivial_root_abs"] = num(r.trivial_root);
        j["spectral_abscissa"] = num(r.spectral_abscissa);
        j["stable"] = r.stable;
        j["unstable_roots"] = r.unstable_roots;
        j["unstable_count_complete"] = r.unstable_count_complete;
        j["product_residual"] = std::isnan(r.product_residual) ? json(nullptr) : num(r.product_residual);
        j["solver"] = solver_name(rr.method_used);
        j["degree"] = rr.degree;
        j["strip_floor"] = num(rr.strip_floor);
        j["right_bound"] = num(rr.right_bound);
        j["shifts"] = rr.shifts;
        j["factorizations"] = rr.factorizations;
        j["max_residual"] = num(rr.max_residual);
        j["collocation_error"] = num(rr.collocation_error);
        j["status"] = to_string(rr.status);
        j["reason"] = rr.message;
        out << j.dump(2) << "\n";
    } else if (format == Format::Csv) {
        out << roots_csv(rr.roots);
    } else {
        out << "fleet      " << (args.fleet.empty() ? args.pattern : args.fleet) << ": " << fleet.size() << " cars, speed "
            << rounded(r.equilibrium.speed, 6) << " m/s, ring length " << rounded(r.equilibrium.length, 8) << " m\n";
        out << "solver     " << solver_name(rr.method_used) << ", M = " << rr.degree << ", " << rr.shifts << " shifts, " << rr.factorizations << " LU factorisations ("
            << to_string(rr.status) << ")\n";
        out << "trusted    " << rr.message << "\n";
        out << "trivial    " << (r.trivial_found ? "lambda = 0 found (|lambda| = " + rounded(r.trivial_root, 3) + "), left out"
                                                  : std::string("not among the rightmost roots")) << "\n";
        if (!std::isnan(r.product_residual)) out << "check      max |prod Gamma_i(lambda) - 1| = " << rounded(r.product_residual, 3) << "\n";
        out << "abscissa   " << rounded(r.spectral_abscissa, 10) << "\n";
        out << "verdict    " << (r.stable ? "STABLE" : "UNSTABLE") << " (" << r.unstable_roots
            << (r.unstable_count_complete ? "" : " or more") << " unstable roots)\n\n";
        out << roots_table(rr.roots);
    }
    std::cout << out.str();
}

struct MixCommand::Impl {
    CLI::App* app = nullptr;
    std::string x, y, cars = "40", p = "0:1:11", draws = "0", seed = "1", speed, length, solver = "auto", count = "4", out;
};

void MixCommand::add_to(CLI::App& app) {
    m = std::make_shared<Impl>();
    auto* c = app.add_subcommand("mix", "penetration-rate study: spectral abscissa of a ring with a fraction p of type X among type Y");
    c->add_option("--x", m->x, "type X: a calibrated vehicle (e.g. E_min) or MODEL:NAME=VALUE,...")->required();
    c->add_option("--y", m->y, "type Y: as --x")->required();
    c->add_option("--cars", m->cars, "ring size N")->capture_default_str();
    c->add_option("--p", m->p, "fractions of X as LO:HI:COUNT in [0, 1]")->capture_default_str();
    c->add_option("--draws", m->draws, "random arrangements per p besides the evenly spread one (order matters only for CCC)")->capture_default_str();
    c->add_option("--seed", m->seed, "seed of the random arrangements")->capture_default_str();
    c->add_option("--speed", m->speed, "common equilibrium speed [m/s] (default 20)");
    c->add_option("--length", m->length, "ring length [m]; the speed follows for each mix");
    c->add_option("--solver", m->solver, "auto, product, dense or sparse (as roots --fleet)")->capture_default_str();
    c->add_option("--out", m->out, "output prefix: writes PREFIX.csv and PREFIX.svg")->required();
    m->app = c;
}

bool MixCommand::run() const {
    if (!m->app->parsed()) return false;
    const FleetCar x = parse_fleet_car(m->x), y = parse_fleet_car(m->y);
    MixOptions o;
    o.cars = static_cast<int>(parse_integer("--cars", m->cars, 2, 1000000, "an integer 2..1000000"));
    const Axis axis = parse_axis("p", m->p);
    for (int i = 0; i < axis.count; ++i) o.fractions.push_back(axis.value(i));
    o.draws = static_cast<int>(parse_integer("--draws", m->draws, 0, 10000, "an integer 0..10000"));
    o.seed = static_cast<unsigned>(parse_integer("--seed", m->seed, 0, 4294967295L, "an integer 0..4294967295"));
    set_equilibrium(o.ring, m->speed, m->length);
    o.ring.roots.method = root_method(m->solver);
    o.ring.roots.count = 4;
    o.validate();
    const std::vector<MixPoint> pts = penetration_study(x, y, o);
    std::ostringstream csv;
    csv << "p,x_cars,abscissa,abscissa_min,abscissa_max,speed,stable,unstable_roots,arrangements,max_residual,status\n";
    PlotSeries spread{"evenly spread", {}, {}, "#1f77b4", false}, lo{"min over arrangements", {}, {}, "#7f7f7f", true},
        hi{"max over arrangements", {}, {}, "#7f7f7f", true}, zero{"stability boundary", {}, {}, "#000000", true};
    for (const auto& pt : pts) {
        csv << exact(pt.fraction) << "," << pt.x_cars << "," << exact(pt.abscissa) << "," << exact(pt.abscissa_min) << ","
            << exact(pt.abscissa_max) << "," << exact(pt.speed) << "," << (pt.stable ? 1 : 0) << "," << pt.unstable_roots << ","
            << pt.arrangements << "," << exact(pt.max_residual) << "," << to_string(pt.status) << "\n";
        const double p = static_cast<double>(pt.x_cars) / o.cars;
        spread.x.push_back(p);
        spread.y.push_back(pt.abscissa);
        lo.x.push_back(p);
        lo.y.push_back(pt.abscissa_min);
        hi.x.push_back(p);
        hi.y.push_back(pt.abscissa_max);
    }
    zero.x = {0.0, 1.0};
    zero.y = {0.0, 0.0};
    PlotPanel panel{"Ring of " + std::to_string(o.cars) + " cars: X = " + x.label + ", Y = " + y.label, "fraction of X cars p = k / N",
                    "spectral abscissa [1/s] (trivial root excluded)", {spread}, {}};
    if (o.draws > 0) {
        panel.series.push_back(lo);
        panel.series.push_back(hi);
    }
    panel.series.push_back(zero);
    PlotOptions po;
    po.columns = 1;
    po.panel_width = 560.0;
    po.panel_height = 320.0;
    po.title = "Penetration-rate study (" + std::string(std::isnan(o.ring.length) ? "speed " + rounded(o.ring.speed, 4) + " m/s" : "length " + rounded(o.ring.length, 6) + " m") + ")";
    po.note = "above 0: the ring is unstable (a small disturbance grows)";
    write_files_atomic({{m->out + ".csv", csv.str()}, {m->out + ".svg", render_line_plots_svg({panel}, po)}});
    std::cout << "p      k   abscissa        stable\n";
    for (const auto& pt : pts) {
        char line[160];
        std::snprintf(line, sizeof line, "%-6.3f %-3d %-15.8f %s\n", pt.fraction, pt.x_cars, pt.abscissa, pt.stable ? "yes" : "no");
        std::cout << line;
    }
    std::cout << "wrote " << m->out << ".csv, " << m->out << ".svg\n";
    return true;
}

}  // namespace ddemap::cli
