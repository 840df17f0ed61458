// ddemap: a thin command-line front. It parses, calls the library, formats.
// Exit codes: 0 success, 2 bad input (one line on stderr), 3 internal error.
#include <cerrno>
#include <fstream>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "ddemap/traffic/model.hpp"
#include "ddemap/analysis/ring_stability.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/analysis/string_stability.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/analysis/classify.hpp"
#include "charts.hpp"
#include "fleet_commands.hpp"
#include "sim_commands.hpp"
#include "common.hpp"
#include "format.hpp"

using namespace ddemap;
using namespace ddemap::cli;
using ddemap::cli::exact;
using ddemap::cli::rounded;

namespace {
// ------------------------------------------------------------------ roots

struct RootsArgs {
    ModelArgs model;
    std::string ring = "22";
    std::string count = "6";
    std::string format = "table";
    std::string system;
    FleetArgs fleet;
    bool ring_given = false;
};

/// roots --system FILE.json: any linear DDE with discrete delays
void run_system_roots(const RootsArgs& args) {
    if (!args.model.raw.empty() || args.ring_given || args.model.model != "ovrv") {
        throw BadInput("--system takes the whole problem from the file: expected no model parameters, --model or --ring");
    }
    const int count = static_cast<int>(parse_integer("--count", args.count, 1, 10000, "an integer between 1 and 10000"));
    const Format format = parse_format(args.format);
    const LinearDDE dde = read_linear_dde_json(read_input_file("--system", args.system), args.system);
    if (args.fleet.solver == "product") throw BadInput("--solver product goes with --fleet rings: expected auto, dense or sparse for --system");
    RootOptions opt;
    opt.method = root_method(args.fleet.solver);
    opt.count = count;
    opt.degree = static_cast<int>(parse_integer("--degree", args.fleet.degree, 0, 200, "0 (automatic) or an integer 2..200"));
    if (opt.degree == 1) throw BadInput("--degree = '1': expected 0 (automatic) or an integer 2..200");
    const RootResult r = rightmost_roots(dde, opt);  // the library chooses (auto) or checks the method
    const std::string path = solver_name(r.method_used);
    const double a = r.spectral_abscissa();
    const bool stable = r.status == Status::Converged && !r.roots.empty() && a < -marginal_band(r.roots.front().value);
    std::ostringstream out;
    if (format == Format::Json) {
        json j;
        j["command"] = "roots";
        j["version"] = DDEMAP_VERSION;
        j["system"] = args.system;
        j["dimension"] = dde.dimension();
        json delays = json::array();
        for (const auto& t : dde.delayed()) delays.push_back(t.delay);
        j["delays"] = delays;
        json roots = json::array();
        for (const auto& x : r.roots) {
            roots.push_back({{"re", num(x.value.real())}, {"im", num(x.value.imag())}, {"residual", num(x.residual)},
                             {"newton_step", num(x.newton_step)}});
        }
        j["roots"] = roots;
        j["spectral_abscissa"] = num(a);
        j["stable"] = stable;
        j["solver"] = path;
        j["degree"] = r.degree;
        j["degree_reason"] = r.message;
        j["status"] = to_string(r.status);
        out << j.dump(2) << "\n";
    } else if (format == Format::Csv) {
        out << roots_csv(r.roots);
    } else {
        out << "system     " << args.system << " (dimension " << dde.dimension() << ", " << dde.delayed().size() << " delays)\n";
        out << "solver     " << path << ", M = " << r.degree << " (" << to_string(r.status) << ")\n";
        out << "trusted    " << r.message << "\n";
        out << "abscissa   " << rounded(a, 10) << "\n";
        out << "verdict    " << (stable ? "STABLE" : "NOT asymptotically stable") << "\n\n";
        out << roots_table(r.roots);
    }
    std::cout << out.str();
}

void run_roots(const RootsArgs& args) {
    if (args.fleet.given()) {
        auto raw = args.model.raw;
        const std::string speed = raw.count("speed") ? raw.at("speed") : "";
        raw.erase("speed");
        if (!args.system.empty() || !raw.empty() || args.ring_given || args.model.model != "ovrv")
            throw BadInput("--fleet/--fleet-pattern define the ring: expected no --system, --ring, --model or model parameters (--speed or --length set the equilibrium)");
        run_fleet_roots(args.fleet, speed, args.count, args.format);
        return;
    }
    if (!args.system.empty()) {
        run_system_roots(args);
        return;
    }
    const auto model = args.model.build();
    const int cars = parse_ring(args.ring);
    const int count = static_cast<int>(parse_integer("--count", args.count, 1, 10000, "an integer between 1 and 10000"));
    const Format format = parse_format(args.format);
    RingOptions opt;
    opt.roots.count = count;
    const RingResult r = analyse_ring(model->linearise(), cars, opt);

    std::ostringstream out;
    if (format == Format::Json) {
        json j;
        j["command"] = "roots";
        j["version"] = DDEMAP_VERSION;
        j["model"] = model->name();
        j["parameters"] = parameters_json(*model);
        j["ring"] = cars == 0 ? json("inf") : json(cars);
        json roots = json::array();
        for (const auto& x : r.roots) {
            json o;
            o["re"] = num(x.root.value.real());
            o["im"] = num(x.root.value.imag());
            o["mode"] = x.mode < 0 ? json(nullptr) : json(x.mode);
            o["theta"] = num(x.theta);
            o["residual"] = num(x.root.residual);
            o["newton_step"] = num(x.root.newton_step);
            roots.push_back(o);
        }
        j["roots"] = roots;
        j["spectral_abscissa"] = num(r.spectral_abscissa);
        j["abscissa_mode"] = r.abscissa_mode < 0 ? json(nullptr) : json(r.abscissa_mode);
        j["abscissa_theta"] = num(r.abscissa_theta);
        j["abscissa_is_limit"] = r.abscissa_is_limit;
        j["ring_stable"] = r.stable;
        j["ring_margin"] = num(-r.spectral_abscissa);
        j["unstable_roots"] = r.unstable_roots < 0 ? json(nullptr) : json(r.unstable_roots);
        j["marginal_roots"] = r.marginal_roots;
        j["trivial_root"] = {{"re", 0.0}, {"im", 0.0}, {"mode", 0}, {"excluded", true},
                             {"meaning", "ring-length invariance (family of equilibria)"}};
        j["degree"] = r.degree;
        j["degree_reason"] = r.reason;
        j["status"] = to_string(r.status);
        j["modes_solved"] = r.modes_solved;
        out << j.dump(2) << "\n";
    } else if (format == Format::Csv) {
        out << "mode,theta,re,im,residual,newton_step\n";
        for (const auto& x : r.roots) {
            out << (x.mode < 0 ? std::string() : std::to_string(x.mode)) << "," << exact(x.theta) << ","
                << exact(x.root.value.real()) << "," << exact(x.root.value.imag()) << "," << exact(x.root.residual)
                << "," << exact(x.root.newton_step) << "\n";
        }
    } else {
        out << "model      " << describe(*model) << "\n";
        out << "ring       N = " << ring_name(cars) << "\n";
        out << "degree     M = " << r.degree << " (" << to_string(r.status) << ")\n";
        out << "trivial    lambda = 0 in mode 0 (ring-length invariance), excluded from the verdict\n";
        out << "abscissa   " << rounded(r.spectral_abscissa, 10);
        if (cars == 0) {
            out << (r.abscissa_is_limit ? " (approached as theta -> 0)" : " at theta = " + rounded(r.abscissa_theta, 6));
        } else {
            out << " (mode " << r.abscissa_mode << ")";
        }
        out << "\n";
        out << "verdict    ring " << (r.stable ? "STABLE" : "UNSTABLE");
        if (cars > 0) out << " (" << r.unstable_roots << " unstable roots, " << r.marginal_roots << " marginal)";
        out << "\n\n";
        out << "  #   mode        theta                re                 im    residual\n";
        int i = 0;
        for (const auto& x : r.roots) {
            char line[200];
            std::snprintf(line, sizeof line, "%3d %6s %12.6f %17.12f %18.12f %11.2e\n", ++i,
                          x.mode < 0 ? "-" : std::to_string(x.mode).c_str(), x.theta, x.root.value.real(),
                          x.root.value.imag(), x.root.residual);
            out << line;
        }
    }
    std::cout << out.str();
}

// ------------------------------------------------------------------ string

struct StringArgs {
    ModelArgs model;
    std::string ring;
    std::string format = "table";
};

void run_string(const StringArgs& args) {
    const auto model = args.model.build();
    const Format format = parse_format(args.format);
    std::optional<int> cars;
    if (!args.ring.empty()) cars = parse_ring(args.ring);
    const Linearisation lin = model->linearise();
    const StringResult s = analyse_string(lin);
    std::optional<RingResult> ring;
    if (cars) ring = analyse_ring(lin, *cars);

    std::ostringstream out;
    if (format == Format::Json) {
        json j;
        j["command"] = "string";
        j["version"] = DDEMAP_VERSION;
        j["model"] = model->name();
        j["parameters"] = parameters_json(*model);
        j["plant_stable"] = s.plant_stable;
        j["plant_abscissa"] = num(s.plant_abscissa);
        j["plant_margin"] = num(-s.plant_abscissa);
        j["sup_gamma"] = num(s.sup_gamma);
        j["omega_peak"] = num(s.omega_peak);
        j["peak_margin"] = num(s.peak_margin);
        j["lowfreq_margin"] = num(s.lowfreq_margin);
        j["lowfreq"] = {{"c2", num(s.lowfreq.c2)}, {"c4", num(s.lowfreq.c4)}, {"c6", num(s.lowfreq.c6)},
                        {"c8", num(s.lowfreq.c8)}, {"decisive_order", s.lowfreq.decisive_order},
                        {"attenuates", s.lowfreq.attenuates}};
        j["string_stable"] = s.string_stable;
        json peaks = json::array();
        for (const auto& p : s.peaks) peaks.push_back({{"omega", num(p.omega)}, {"gain", num(p.gain)}});
        j["peaks"] = peaks;
        j["omega_search_max"] = num(s.omega_search_max);
        j["plant_degree"] = s.plant_roots.degree;
        if (ring) {
            j["ring"] = *cars == 0 ? json("inf") : json(*cars);
            j["ring_stable"] = ring->stable;
            j["spectral_abscissa"] = num(ring->spectral_abscissa);
            j["ring_margin"] = num(-ring->spectral_abscissa);
        }
        out << j.dump(2) << "\n";
    } else if (format == Format::Csv) {
        out << "plant_stable,plant_abscissa,sup_gamma,omega_peak,peak_margin,lowfreq_margin,string_stable";
        if (ring) out << ",ring,ring_stable,spectral_abscissa";
        out << "\n";
        out << (s.plant_stable ? "true" : "false") << "," << exact(s.plant_abscissa) << "," << exact(s.sup_gamma)
            << "," << exact(s.omega_peak) << "," << exact(s.peak_margin) << "," << exact(s.lowfreq_margin) << ","
            << (s.string_stable ? "true" : "false");
        if (ring) out << "," << ring_name(*cars) << "," << (ring->stable ? "true" : "false") << "," << exact(ring->spectral_abscissa);
        out << "\n";
    } else {
        out << "model            " << describe(*model) << "\n";
        out << "plant            " << (s.plant_stable ? "stable" : "UNSTABLE") << "   (rightmost root of D: Re = "
            << rounded(s.plant_abscissa, 6) << ")\n";
        out << "sup |Gamma(iw)|  " << rounded(s.sup_gamma, 10);
        if (s.omega_peak > 0.0) out << " at w = " << rounded(s.omega_peak, 8) << " rad/s";
        else out << " (only approached as w -> 0)";
        out << "\n";
        out << "low frequency    c" << s.lowfreq.decisive_order << " = " << rounded(s.lowfreq_margin, 6)
            << (s.lowfreq.attenuates ? "  (attenuates as w -> 0)" : "  (AMPLIFIES as w -> 0)") << "\n";
        if (ring) {
            char label[32];
            std::snprintf(label, sizeof label, "%-17s", ("ring N=" + ring_name(*cars)).c_str());
            out << label << (ring->stable ? "stable" : "UNSTABLE")
                << "   (spectral abscissa " << rounded(ring->spectral_abscissa, 6) << ")\n";
        }
        out << "verdict          string " << (s.string_stable ? "STABLE" : "UNSTABLE") << "\n";
    }
    std::cout << out.str();
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"ddemap: stability of delay differential car-following models.\n"
                 "Rightmost characteristic roots of rings of cars, string stability verdicts."};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(DDEMAP_VERSION));

    RootsArgs roots_args;
    auto* roots = app.add_subcommand("roots", "rightmost characteristic roots of a ring of N identical cars, a mixed fleet, or any linear DDE");
    roots_args.model.add_to(roots);
    roots->add_option("--ring", roots_args.ring, "number of cars N >= 2 (time grows linearly: about 0.3 ms per mode, N/2+1 modes), or inf for all wave numbers")->capture_default_str();
    roots->add_option("--count", roots_args.count, "how many rightmost roots to list")->capture_default_str();
    roots->add_option("--format", roots_args.format, "table, json or csv")->capture_default_str();
    roots->add_option("--system", roots_args.system, "any linear DDE from a JSON file (dimension, delays, A0, A; see README) instead of a ring");
    roots_args.fleet.add_to(roots);

    StringArgs string_args;
    auto* str = app.add_subcommand("string", "plant and string stability from the head-to-tail transfer function");
    string_args.model.add_to(str);
    str->add_option("--ring", string_args.ring, "also decide ring stability for N cars (N >= 2 or inf)");
    str->add_option("--format", string_args.format, "table, json or csv")->capture_default_str();

    ChartCommands charts;
    charts.add_to(app);
    SimCommands sims;
    sims.add_to(app);
    MixCommand mix;
    mix.add_to(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::string msg = e.what();
        for (auto& c : msg)
            if (c == '\n') c = ' ';
        std::cerr << "ddemap: error: " << msg << " (see ddemap --help)\n";
        return 2;
    }
    try {
        if (roots->parsed()) {
            roots_args.ring_given = roots->count("--ring") > 0;
            run_roots(roots_args);
        }
        else if (str->parsed()) run_string(string_args);
        else if (!charts.run() && !sims.run()) mix.run();
        return 0;
    } catch (const std::invalid_argument& e) {
        std::cerr << "ddemap: error: " << e.what() << "\n";
        return 2;
    } catch (const std::runtime_error& e) {
        std::cerr << "ddemap: error: " << e.what() << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "ddemap: internal error: " << e.what() << "\n";
        return 3;
    }
}
