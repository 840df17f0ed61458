#include "charts.hpp"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/boundary.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/analysis/classify.hpp"
#include "builtin_maps.hpp"
#include "sim_commands.hpp"
#include "ddemap/io/csv.hpp"

namespace ddemap::cli {

namespace {

void progress_line(int done, int total) {
    std::fprintf(stderr, "\rsweep: %d/%d rows", done, total);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

json sweep_json(const SweepResult& sw, const BoundarySet* b) {
    json j;
    j["command"] = "sweep";
    j["version"] = DDEMAP_VERSION;
    j["model"] = sw.spec.model;
    json fixed = json::object();
    for (const auto& [k, v] : sw.spec.fixed) fixed[k] = v;
    j["fixed"] = fixed;
    for (const auto* a : {&sw.spec.x, &sw.spec.y}) {
        j[a == &sw.spec.x ? "x" : "y"] = {{"name", a->name}, {"lo", a->lo}, {"hi", a->hi}, {"count", a->count}};
    }
    j["ring"] = sw.spec.cars == 0 ? json("inf") : json(sw.spec.cars);
    j["points"] = sw.points.size();
    int classes[4] = {0, 0, 0, 0};
    for (const auto& p : sw.points) ++classes[region_class(p)];
    j["regions"] = {{"plant_unstable", classes[0]}, {"ring_unstable", classes[1]}, {"string_unstable", classes[2]},
                    {"string_stable", classes[3]}};
    j["method"] =
        "rightmost root of every ring mode and of the plant continued by Newton along grid rows, each certified by an "
        "argument-principle count (no zero right of Re + 1e-10 max(1,|lambda|)); Chebyshev collocation where a "
        "certificate fails";
    j["degree"] = sw.degree_max;
    j["fallbacks"] = sw.fallbacks;
    j["uncertified_points"] = sw.uncertified;
    j["threads"] = sw.threads;
    j["seconds"] = sw.seconds;
    j["points_per_second"] = sw.seconds > 0 ? sw.points.size() / sw.seconds : 0.0;
    if (b) {
        j["boundaries"] = {{"curves", b->curves.size()}, {"seeds", b->seeds}, {"rejected_seeds", b->rejected},
                           {"seconds", b->seconds}};
    }
    return j;
}

std::string fixed_title(const SweepSpec& spec) {
    std::ostringstream t;
    t << spec.model;
    for (const auto& [k, v] : spec.fixed) t << ", " << k << " = " << rounded(v, 4);
    t << ", N = " << (spec.cars == 0 ? std::string("inf") : std::to_string(spec.cars));
    return t.str();
}

const char* keys[] = {"k1", "k2", "th", "tau", "eta"};

std::string classification_table(const std::vector<Classification>& rows, int cars, const std::string& source) {
    std::ostringstream out;
    out << "vehicle settings of " << source << "; ring N = " << (cars == 0 ? std::string("inf") : std::to_string(cars)) << "\n\n";
    out << "name      k1     k2     th     tau    eta     plant     ring      string    sup|Gamma|  w_peak   c2\n";
    for (const auto& row : rows) {
        char line[256];
        const auto& p = row.vehicle.parameters;
        std::snprintf(line, sizeof line, "%-7s %6.3f %6.3f %6.3f %6.3f %6.3f   %-9s %-9s %-9s %9.6f %7.4f %9.2e\n",
                      row.vehicle.name.c_str(), p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"), p.at("eta"),
                      row.string.plant_stable ? "stable" : "UNSTABLE", row.ring.stable ? "stable" : "UNSTABLE",
                      row.string.string_stable ? "stable" : "UNSTABLE", row.string.sup_gamma, row.string.omega_peak,
                      row.string.lowfreq_margin);
        out << line;
    }
    return out.str();
}

std::string classification_csv(const std::vector<Classification>& rows) {
    std::ostringstream out;
    out << "name,k1,k2,th,tau,eta,plant_stable,ring_stable,string_stable,sup_gamma,omega_peak,lowfreq_margin,"
           "spectral_abscissa,plant_abscissa\n";
    for (const auto& row : rows) {
        out << csv_field(row.vehicle.name);
        for (const char* k : keys) out << "," << exact(row.vehicle.parameters.at(k));
        out << "," << (row.string.plant_stable ? "true" : "false") << "," << (row.ring.stable ? "true" : "false") << ","
            << (row.string.string_stable ? "true" : "false") << "," << exact(row.string.sup_gamma) << ","
            << exact(row.string.omega_peak) << "," << exact(row.string.lowfreq_margin) << "," << exact(row.ring.spectral_abscissa)
            << "," << exact(row.string.plant_abscissa) << "\n";
    }
    return out.str();
}

json classification_json(const std::vector<Classification>& rows, int cars, const std::string& source) {
    json j;
    j["command"] = "classify";
    j["version"] = DDEMAP_VERSION;
    j["source"] = source;
    j["ring"] = cars == 0 ? json("inf") : json(cars);
    json arr = json::array();
    for (const auto& row : rows) {
        json o;
        o["name"] = row.vehicle.name;
        for (const char* k : keys) o[k] = row.vehicle.parameters.at(k);
        o["plant_stable"] = row.string.plant_stable;
        o["ring_stable"] = row.ring.stable;
        o["string_stable"] = row.string.string_stable;
        o["sup_gamma"] = num(row.string.sup_gamma);
        o["omega_peak"] = num(row.string.omega_peak);
        o["lowfreq_margin"] = num(row.string.lowfreq_margin);
        o["spectral_abscissa"] = num(row.ring.spectral_abscissa);
        o["plant_abscissa"] = num(row.string.plant_abscissa);
        arr.push_back(o);
    }
    j["vehicles"] = arr;
    return j;
}

/// The classification figure's spec for a set of vehicles: the built-in spec's window and
/// layout with one panel per vehicle.
ChartSpec classification_chart(const std::vector<CalibratedVehicle>& vehicles, int cars) {
    ChartSpec spec = parse_chart_spec(builtin_classification_toml, "maps/classification.toml");
    spec.panels = vehicle_panels(vehicles);
    spec.cars = cars;
    if (cars != 22) spec.title = "Calibrated vehicles on their own stability charts, N = " + (cars == 0 ? std::string("inf") : std::to_string(cars));
    return spec;
}

}  // namespace

struct ChartCommands::Impl {
    CLI::App* classify_cmd = nullptr;
    std::string classify_file, classify_ring = "22", classify_format = "table", classify_svg;
    CLI::App* chart = nullptr;
    std::string chart_spec, chart_out;
    CLI::App* paper = nullptr;
    std::string paper_out;

    void run_classify() const {
        const int cars = parse_ring(classify_ring);
        const Format format = parse_format(classify_format);
        if (!classify_svg.empty()) check_output("--svg", classify_svg);
        std::vector<CalibratedVehicle> vehicles;
        std::string source = "the paper's calibration table (built in)";
        if (classify_file.empty()) {
            vehicles = paper_calibration_table();
        } else {
            vehicles = read_vehicles_csv(read_input_file("VEHICLES.csv", classify_file), classify_file);
            source = classify_file;
        }
        const auto rows = ddemap::classify(vehicles, cars);
        std::string text;
        if (format == Format::Json) text = classification_json(rows, cars, source).dump(2) + "\n";
        else if (format == Format::Csv) text = classification_csv(rows);
        else text = classification_table(rows, cars, source);
        if (!classify_svg.empty()) write_files_atomic({{classify_svg, render_chart(classification_chart(vehicles, cars)).svg}});
        std::cout << text;
    }

    void run_chart() const {
        check_output("--out", chart_out);
        const ChartSpec spec = parse_chart_spec(read_input_file("SPEC", chart_spec), chart_spec);
        const RenderedChart r = render_chart(spec);
        write_files_atomic({{chart_out, r.svg}});
        std::cout << "chart      " << spec.panels.size() << " panels in " << rounded(r.seconds, 3) << " s\nwrote      " << chart_out << "\n";
    }

    void run_paper() const {
        if (paper_out.empty()) throw BadInput("--out DIR is required");
        if (access(paper_out.c_str(), W_OK) != 0) throw BadInput("--out = '" + paper_out + "': the folder does not exist or is not writable");
        const std::string dir = paper_out + "/";
        // the classification of the built-in table, and its figure
        const auto rows = ddemap::classify(paper_calibration_table(), 22);
        const std::string source = "the paper's calibration table (built in)";
        std::vector<std::pair<std::string, std::string>> files;
        files.emplace_back(dir + "classification.csv", classification_csv(rows));
        files.emplace_back(dir + "classification.json", classification_json(rows, 22, source).dump(2) + "\n");
        const RenderedChart cls = render_chart(classification_chart(paper_calibration_table(), 22));
        files.emplace_back(dir + "classification.svg", cls.svg);
        // the paper's stability diagrams
        const ChartSpec spec = parse_chart_spec(builtin_paper_toml, "maps/paper.toml");
        const RenderedChart fig = render_chart(spec);
        files.emplace_back(dir + "paper.svg", fig.svg);
        json summary = json::array();
        for (std::size_t i = 0; i < fig.sweeps.size(); ++i) {
            const std::string base = dir + "paper-panel" + std::to_string(i + 1);
            files.emplace_back(base + ".csv", sweep_csv(fig.sweeps[i]));
            files.emplace_back(base + "-boundaries.csv", boundary_csv(fig.specs[i], fig.boundaries[i]));
            summary.push_back(sweep_json(fig.sweeps[i], &fig.boundaries[i]));
        }
        // the disturbance growth study behind the platoon-test dip
        const auto growth = disturbance_growth(paper_calibration_table(), LeadProfile::builtin("dip"), 15);
        files.emplace_back(dir + "growth.csv", growth_csv(growth));
        files.emplace_back(dir + "growth.svg", growth_svg(growth, "dip"));
        files.emplace_back(dir + "paper.json", json{{"command", "paper"}, {"version", DDEMAP_VERSION}, {"panels", summary},
                                                    {"seconds", fig.seconds + cls.seconds}}.dump(2) + "\n");
        write_files_atomic(files);
        std::ostringstream out;
        out << classification_table(rows, 22, source);
        out << "\ndisturbance growth behind the dip (22.4 -> 19.7 -> 22.4 m/s), platoons of up to 15 followers\n";
        out << growth_table(growth);
        out << "\nfigures and data in " << paper_out << ": paper.svg (" << spec.panels.size()
            << " panels), classification.svg, classification.csv/.json, paper-panel*.csv, paper-panel*-boundaries.csv, growth.csv/.svg, paper.json\n";
        std::cout << out.str();
    }

    CLI::App* sweep = nullptr;
    CLI::App* boundary = nullptr;
    ModelArgs sweep_model, boundary_model;
    std::string sweep_ring = "22", sweep_out, sweep_x;
    bool no_boundaries = false;
    std::string boundary_ring = "22", boundary_out, boundary_grid = "41";

    SweepSpec spec_from(const ModelArgs& margs, const std::string& ring, const std::string& x_name, bool counts,
                        const std::string& grid) const {
        SweepSpec spec;
        spec.model = margs.model;
        std::vector<std::pair<std::string, std::string>> axes;
        margs.split(spec.fixed, axes);
        if (axes.size() != 2) {
            throw BadInput(std::string("expected exactly two swept parameters given as ") + (counts ? "LO:HI:COUNT" : "LO:HI") +
                           " (e.g. --k1 0.01:1" + (counts ? ":200" : "") + " --k2 0.01:1" + (counts ? ":200" : "") + "), got " +
                           std::to_string(axes.size()));
        }
        if (!x_name.empty()) {
            if (axes[1].first == x_name) std::swap(axes[0], axes[1]);
            if (axes[0].first != x_name) throw BadInput("--x = '" + x_name + "': expected one of the swept parameters");
        }
        for (int i = 0; i < 2; ++i) {
            const std::string text = counts ? axes[i].second : axes[i].second + ":" + grid;
            if (!counts && std::count(axes[i].second.begin(), axes[i].second.end(), ':') != 1) {
                throw BadInput("--" + axes[i].first + " = '" + axes[i].second + "': expected LO:HI with finite LO < HI");
            }
            (i == 0 ? spec.x : spec.y) = parse_axis(axes[i].first, text);
        }
        spec.cars = parse_ring(ring);
        spec.validate();
        return spec;
    }

    void run_sweep_command() const {
        const SweepSpec spec = spec_from(sweep_model, sweep_ring, sweep_x, true, "");
        check_output("--out", sweep_out);
        const bool tty = isatty(2);
        ExecutionPolicy policy;
        if (tty) policy.progress = progress_line;
        const SweepResult sw = run_sweep(spec, policy);
        BoundarySet b;
        if (!no_boundaries) b = trace_boundaries(sw);
        ChartOptions co;
        co.title = "Stability chart: " + fixed_title(spec);
        co.columns = 1;
        co.panel_width = 520;
        co.panel_height = 440;
        ChartPanel panel;
        panel.title = fixed_title(spec);
        panel.sweep = &sw;
        panel.boundaries = no_boundaries ? nullptr : &b;
        const json j = sweep_json(sw, no_boundaries ? nullptr : &b);
        std::vector<std::pair<std::string, std::string>> files = {
            {sweep_out + ".csv", sweep_csv(sw)},
            {sweep_out + ".json", j.dump(2) + "\n"},
            {sweep_out + ".svg", render_chart_svg({panel}, co)},
        };
        if (!no_boundaries) files.emplace_back(sweep_out + "-boundaries.csv", boundary_csv(spec, b));
        write_files_atomic(files);
        std::ostringstream out;
        out << "sweep      " << sw.points.size() << " points in " << rounded(sw.seconds, 3) << " s ("
 << static_cast<long>(std::lround(sw.points.size() / std::max(sw.seconds, 1e-9))) << " points/s, " << sw.threads << " threads)\n";
        out << "regions    plant unstable " << j["regions"]["plant_unstable"] << ", ring unstable " << j["regions"]["ring_unstable"]
            << ", string unstable " << j["regions"]["string_unstable"] << ", string stable " << j["regions"]["string_stable"] << "\n";
        if (!no_boundaries) out << "boundaries " << b.curves.size() << " curves\n";
        out << "wrote      ";
        for (const auto& f : files) out << f.first << " ";
        out << "\n";
        std::cout << out.str();
    }

    void run_boundary_command() const {
        const int grid = static_cast<int>(parse_integer("--seed-grid", boundary_grid, 5, 2001, "an integer between 5 and 2001"));
        const SweepSpec spec = spec_from(boundary_model, boundary_ring, "", false, std::to_string(grid));
        check_output("--out", boundary_out);
        const SweepResult sw = run_sweep(spec);
        const BoundarySet b = trace_boundaries(sw);
        write_files_atomic({{boundary_out, boundary_csv(spec, b)}});
        std::ostringstream out;
        out << "boundaries " << b.curves.size() << " curves (" << b.seeds << " seeds on a " << grid << " x " << grid << " grid)\n";
        for (std::size_t i = 0; i < b.curves.size(); ++i) {
            const auto& c = b.curves[i];
            out << "  " << i + 1 << "  " << kind_name(c.kind) << "/" << subkind_name(c.kind);
            if (c.kind == BoundaryKind::RingHopf) out << " mode " << c.mode;
            out << ": " << c.points.size() << " points, max residual " << rounded(c.max_residual, 2) << (c.closed ? ", closed" : "") << "\n";
        }
        out << "wrote      " << boundary_out << "\n";
        std::cout << out.str();
    }
};

void ChartCommands::add_to(CLI::App& app) {
    m = std::make_shared<Impl>();
    m->classify_cmd = app.add_subcommand("classify",
                                     "plant, ring and string verdicts of calibrated vehicles (default: the paper's 14 settings)");
    m->classify_cmd->add_option("VEHICLES.csv", m->classify_file, "CSV with columns name,k1,k2,th,tau[,eta] (OVRV; units 1/s^2, 1/s, s, s, m)");
    m->classify_cmd->add_option("--ring", m->classify_ring, "ring size N >= 2 or inf for the ring verdict")->capture_default_str();
    m->classify_cmd->add_option("--format", m->classify_format, "table, json or csv")->capture_default_str();
    m->classify_cmd->add_option("--svg", m->classify_svg, "also write the figure: one (k1, k2) chart per vehicle, vehicle marked");

    m->chart = app.add_subcommand("chart", "render a chart spec (TOML, see maps/) to SVG");
    m->chart->add_option("SPEC", m->chart_spec, "chart specification (TOML)")->required();
    m->chart->add_option("--out", m->chart_out, "output SVG file")->required();

    m->paper = app.add_subcommand("paper", "the seed paper's main job: classification table on stdout, figures and data in DIR");
    m->paper->add_option("--out", m->paper_out, "output folder (must exist)")->required();

    m->sweep = app.add_subcommand("sweep",
                                  "grid sweep over two model parameters (each given as LO:HI:COUNT): spectral abscissa, "
                                  "unstable roots, sup|Gamma| and verdicts per point; writes PREFIX.csv, .json, .svg");
    m->sweep_model.add_to(m->sweep);
    m->sweep->add_option("--ring", m->sweep_ring, "ring size N >= 2, or inf")->capture_default_str();
    m->sweep->add_option("--out", m->sweep_out, "output prefix: PREFIX.csv, PREFIX.json, PREFIX.svg, PREFIX-boundaries.csv");
    m->sweep->add_option("--x", m->sweep_x, "which swept parameter is the horizontal axis (default: alphabetical)");
    m->sweep->add_flag("--no-boundaries", m->no_boundaries, "skip the boundary continuation");

    m->boundary = app.add_subcommand("boundary",
                                     "stability boundaries in a window of two parameters (each given as LO:HI) by "
                                     "pseudo-arclength continuation; writes FILE.csv");
    m->boundary_model.add_to(m->boundary);
    m->boundary->add_option("--ring", m->boundary_ring, "ring size N >= 2, or inf")->capture_default_str();
    m->boundary->add_option("--out", m->boundary_out, "output CSV file");
    m->boundary->add_option("--seed-grid", m->boundary_grid, "grid points per axis used to seed the branches")->capture_default_str();
}

bool ChartCommands::run() const {
    if (m->classify_cmd->parsed()) {
        m->run_classify();
        return true;
    }
    if (m->chart->parsed()) {
        m->run_chart();
        return true;
    }
    if (m->paper->parsed()) {
        m->run_paper();
        return true;
    }
    if (m->sweep->parsed()) {
        m->run_sweep_command();
        return true;
    }
    if (m->boundary->parsed()) {
        m->run_boundary_command();
        return true;
    }
    return false;
}

}  // namespace ddemap::cli
