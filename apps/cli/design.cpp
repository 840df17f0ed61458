// design: the gains (or other law parameters) of one car that minimise a stability objective
// within bounds; the verdicts at the car and at the design, certified.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "ddemap/analysis/design/design.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap::cli {

namespace {
struct DesignArgs {
    std::string car, objective = "sup-gamma", free = "k1,k2", bounds, margin = "0.1", weights, starts = "4";
    bool robust = false;
    RingArg ring;
    FormatArg format;
    OutArg out;
} design_args;

std::vector<std::string> split_commas(const std::string& text) {
    std::vector<std::string> items;
    std::stringstream ss(text);
    std::string item;
    while (std::getline(ss, item, ',')) items.push_back(item);
    if (!text.empty() && text.back() == ',') items.push_back("");
    return items;
}

std::string unit_of(const std::string& model, const std::string& name) {
    for (const ParameterSpec& s : model_parameters(model))
        if (s.name == name) return s.unit;
    return "";
}

std::string verdict_cell(const StringResult& s, const std::string& which) {
    if (which == "plant") return s.plant_stable ? std::string("stable") : verdict_word(s.plant_verdict);
    if (which == "string") return verdict_word(s.string_verdict);
    return s.peak ? verdict_word(s.peak->verdict) : std::string("-");
}

}  // namespace

void add_design_flags(CLI::App& app) {
    app.add_option("CAR", design_args.car, std::string("the car to design from (one car): ") + cars_help())->required()->type_name("CAR");
    app.add_option("--objective", design_args.objective,
                   "sup-gamma (sup |Gamma(iw)| |1 + i m w|, m = --margin; where it reaches 1, the nearest such gains), peak (||h||_1), abscissa "
                   "(the plant's spectral abscissa, or the ring's with --ring) or nearest (the smallest relative change to an attenuation margin of "
                   "at least --margin)")
        ->capture_default_str()
        ->type_name("sup-gamma|peak|abscissa|nearest");
    app.add_option("--free", design_args.free, "the law parameters designed, the others held (e.g. k1,k2,th)")->capture_default_str()->type_name("NAME,...");
    app.add_option("--bounds", design_args.bounds, "bounds NAME=LO:HI,... of free parameters (default: a tenth to ten times the car's value)")
        ->type_name("NAME=LO:HI,...");
    app.add_option("--margin", design_args.margin,
                   "attenuation margin asked for by nearest and sup-gamma, and checked for every objective [s], 0.001 to 1000: every wave is damped "
                   "from car to car at least as by a first-order lag of this time constant, |Gamma(iw)| <= 1/|1 + i margin w|")
        ->capture_default_str()
        ->type_name("SECONDS");
    app.add_flag("--robust", design_args.robust,
                 "ask the margin of every car the fit is consistent with: of the worst point of the fit's 95 % ellipsoid of the held parameters "
                 "(an exchange method over its worst points; CAR must carry a covariance: a fit file from calibrate)");
    app.add_option("--weights", design_args.weights, "nearest: a weight per free parameter of the relative change, each in [0.001, 1000] (default: all 1)")->type_name("W,...");
    app.add_option("--starts", design_args.starts, "runs of the minimiser: from the car's values and from points of a Halton sequence in the bounds (1..64)")
        ->capture_default_str()
        ->type_name("N");
    design_args.ring.add_to(app, "", "abscissa of the ring of N cars (N >= 2 or inf) instead of the plant's; with any objective, the ring verdicts too");
    design_args.format.add_to(app);
    design_args.out.add_to(app, "PREFIX.csv (the car and the design), PREFIX.json and PREFIX.svg (both on their (k1, k2) stability charts)", false);
    run_flags().add_to(app, false);
}

int run_design() {
    const Format format = design_args.format.parse();
    DesignOptions o;
    o.objective = [&] {
        try {
            return parse_design_objective(design_args.objective);
        } catch (const std::invalid_argument&) {
            throw BadInput("--objective = '" + design_args.objective + "': expected sup-gamma, peak, abscissa or nearest");
        }
    }();
    o.free.clear();
    for (const std::string& f : split_commas(design_args.free)) {
        if (f.empty()) throw BadInput("--free = '" + design_args.free + "': expected parameter names separated by commas, e.g. k1,k2");
        o.free.push_back(f);
    }
    if (!design_args.bounds.empty())
        for (const std::string& item : split_commas(design_args.bounds)) {
            const auto eq = item.find('='), colon = item.find(':', eq == std::string::npos ? 0 : eq);
            if (eq == std::string::npos || colon == std::string::npos || eq == 0)
                throw BadInput("--bounds item '" + item + "': expected NAME=LO:HI, e.g. k1=0.01:0.5");
            const std::string name = item.substr(0, eq);
            o.bounds.push_back({name, parse_number("--bounds " + name, item.substr(eq + 1, colon - eq - 1)),
                                parse_number("--bounds " + name, item.substr(colon + 1))});
        }
    o.margin = parse_number("--margin", design_args.margin);
    if (!(o.margin >= 1e-3) || o.margin > 1e3) throw BadInput("--margin = " + design_args.margin + ": expected a number of seconds in [0.001, 1000]");
    if (!design_args.weights.empty())
        for (const std::string& wtext : split_commas(design_args.weights)) o.weights.push_back(parse_number("--weights", wtext));
    o.starts = static_cast<int>(parse_integer("--starts", design_args.starts, 1, 64, "an integer 1..64"));
    if (!design_args.ring.empty()) o.cars = design_args.ring.parse(true, kWindingMaxCars);
    const std::string prefix = design_args.out.given() ? design_args.out.prepare("design", {".csv", ".json", ".svg"}) : std::string();

    const auto cars = distinct_cars(vehicles_argument("CAR", design_args.car));
    if (cars.size() != 1)
        throw BadInput("CAR = '" + design_args.car + "': " + std::to_string(cars.size()) + " cars: expected one car (e.g. FILE.csv:NAME)");
    const CalibratedVehicle& car = cars.front();
    ParameterMap p = car.parameters;
    if (car.has_covariance && car.model == "ovrv") {  // a fit: judge the design under its uncertainty too
        o.has_covariance = true;
        o.covariance = car.covariance;
    }
    if (design_args.robust) {
        if (!o.has_covariance)
            throw BadInput("--robust: the car " + car.name + " has no covariance: expected a fit of calibrate (FILE.json or FILE.csv with cov_ columns)");
        o.robust = true;
    }
    // sized before the work (one core, measured on the paper's cars): an evaluation of the
    // frequency objectives or the plant's abscissa about 3 ms with its gradient, a run at most a
    // few hundred of them; a peak evaluation 1 + 2n norms of about 0.05 s, at most 40 per run; a
    // ring of N = inf about 80 ms per evaluation
    {
        const double n = static_cast<double>(o.free.size());
        const double per_run = o.objective == DesignObjective::Peak ? 40.0 * (1.0 + 2.0 * n) * 0.05
                               : o.cars >= 0 && o.objective == DesignObjective::Abscissa ? 300.0 * 0.08 * (1.0 + n)
                                                                                        : 300.0 * 0.003 * (1.0 + n);
        check_size("design", counted(o.starts, "start"), "time", per_run * (o.starts + 1));
    }
    o.progress = progress_printer("design", o.objective == DesignObjective::Nearest ? "runs" : "evaluations (at most)");
    DesignResult r = design_gains(car.model, p, o);

    const JsonEnvelope e = design_envelope(r, o, design_args.car, car.name);
    const std::string csv = design_csv(r);
    if (!prefix.empty()) {
        // the figure: the car and the design on the (k1, k2) chart(s), the ring of --ring (22 cars by default)
        ExecutionPolicy policy;
        policy.progress = progress_printer("design", "chart rows");
        const std::string svg = design_chart_svg(r, car.name, o.cars >= 0 ? o.cars : 22, car.has_covariance ? &car.covariance : nullptr, policy);
        std::vector<std::pair<std::string, std::string>> files = {{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}};
        if (!svg.empty()) files.emplace_back(prefix + ".svg", svg);
        write_files_atomic(files);
    }
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "car        " << car.name << " (" << car.model << ")\n";
        out << "objective  " << r.objective;
        if (o.objective == DesignObjective::Nearest) out << " (attenuation margin >= " << rounded(o.margin, 6) << " s)";
        if (o.cars >= 0) out << " (ring N = " << ring_name(o.cars) << ")";
        out << "; " << o.starts << " start" << (o.starts == 1 ? "" : "s") << ", " << r.evaluations << " evaluations\n\n";
        char line[256];
        std::snprintf(line, sizeof line, "%-24s %-18s %-18s %s\n", "", "car", "design", "change");
        out << line;
        for (const BoundedParameter& b : r.bounds) {
            const double a = r.initial.at(b.name), d = r.gains.at(b.name);
            const std::string unit = unit_of(r.model, b.name);
            const std::string label = b.name + (unit.empty() ? "" : " [" + unit + "]");
            const std::string change = a != 0.0 ? (d >= a ? "+" : "") + rounded(100.0 * (d - a) / a, 3) + " %" : "";
            const bool at = std::find(r.at_bound.begin(), r.at_bound.end(), b.name) != r.at_bound.end();
            std::snprintf(line, sizeof line, "%-24s %-18s %-18s %s%s\n", label.c_str(), rounded(a, 6).c_str(), rounded(d, 6).c_str(), change.c_str(),
                          at ? "  (at its bound)" : "");
            out << line;
        }
        auto cell = [](double v, int digits) { return std::isfinite(v) ? rounded(v, digits) : std::string("inf"); };
        std::snprintf(line, sizeof line, "%-24s %-18s %s\n", ("objective (" + r.objective + ")").c_str(), cell(r.value_initial, 8).c_str(),
                      cell(r.value, 8).c_str());
        out << line;
        std::snprintf(line, sizeof line, "%-24s %-18s %s\n", "sup |Gamma(iw)|", rounded(r.string_initial.sup_gamma, 8).c_str(),
                      rounded(r.string.sup_gamma, 8).c_str());
        out << line;
        auto margin_cell = [&](const StringResult& s, const AttenuationScan& a) { return s.plant_stable ? rounded(a.margin, 4) : std::string("-"); };
        std::snprintf(line, sizeof line, "%-24s %-18s %s\n", "attenuation margin [s]", margin_cell(r.string_initial, r.attenuation_initial).c_str(),
                      margin_cell(r.string, r.attenuation).c_str());
        out << line;
        auto peak_cell = [&](const StringResult& s) { return s.peak && s.peak->finite ? rounded(s.peak->norm, 8) : std::string("-"); };
        std::snprintf(line, sizeof line, "%-24s %-18s %s\n", "peak ||h||_1", peak_cell(r.string_initial).c_str(), peak_cell(r.string).c_str());
        out << line;
        for (const char* which : {"plant", "string", "peak"}) {
            const std::string label = std::string(which) + (std::string(which) == "string" ? " (L2)" : std::string(which) == "peak" ? " (L-inf)" : "");
            std::snprintf(line, sizeof line, "%-24s %-18s %s\n", label.c_str(), verdict_cell(r.string_initial, which).c_str(),
                          verdict_cell(r.string, which).c_str());
            out << line;
        }
        if (r.ring) {
            auto rv = [](const RingResult& g) { return g.stable ? std::string("stable") : verdict_word(g.verdict); };
            std::snprintf(line, sizeof line, "%-24s %-18s %s\n", ("ring N=" + ring_name(o.cars)).c_str(), rv(*r.ring_initial).c_str(), rv(*r.ring).c_str());
            out << line;
        }
        if (r.has_uncertainty) {
            auto pcell = [](const VerdictUncertainty& u) {
                const ProbabilityEstimate& e = u.string_unstable;
                return "p = " + rounded(1.0 - e.p, 3) + " [" + rounded(1.0 - e.upper, 3) + ", " + rounded(1.0 - e.lower, 3) + "]";
            };
            std::snprintf(line, sizeof line, "%-24s %-18s %s\n", "P(string stable)", pcell(r.uncertainty_initial).c_str(), pcell(r.uncertainty).c_str());
            out << line << "  (under the fit's uncertainty of the held parameters, " << r.uncertainty.samples
                << " draws; 95 % Wilson intervals)\n";
            auto wcell = [](const WorstMargin& w) { return std::isfinite(w.margin) ? rounded(w.margin, 4) : std::string("none (plant unstable)"); };
            std::snprintf(line, sizeof line, "%-24s %-18s %s\n", "worst m* [s]", wcell(r.worst_initial).c_str(), wcell(r.worst).c_str());
            std::string held;
            for (const auto& h : r.worst.held) held += (held.empty() ? "" : ", ") + h;
            out << line << "  (the least attenuation margin over the fit's 95 % confidence ellipsoid of " << (held.empty() ? "no held parameter" : held) << ")\n";
        }
        out << "\n" << to_string(r.status) << ": " << r.message << "\n";
        std::cout << out.str();
    });
    if (r.status != Status::Converged) return report_undecided(r.status, "design", r.message);
    return exit_ok;
}

}  // namespace ddemap::cli
