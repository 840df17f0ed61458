#include "charts.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "ddemap/chart.hpp"
#include "ddemap/continuation.hpp"
#include "ddemap/sweep.hpp"
#include "ddemap/writers.hpp"

namespace ddemap::cli {

namespace {

void progress_line(int done, int total) {
    std::fprintf(stderr, "\rsweep: %d/%d rows", done, total);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
}

/// Writes several files so that either all appear or none is left half-written.
void write_all(const std::vector<std::pair<std::string, std::string>>& files) {
    std::vector<std::string> written;
    try {
        for (const auto& [path, text] : files) {
            write_file_atomic(path + ".part", text);
            written.push_back(path + ".part");
        }
    } catch (...) {
        for (const auto& w : written) std::remove(w.c_str());
        throw;
    }
    for (const auto& [path, text] : files) {
        if (std::rename((path + ".part").c_str(), path.c_str()) != 0) throw std::runtime_error("cannot write " + path);
    }
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

}  // namespace

struct ChartCommands::Impl {
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
        if (sweep_out.empty()) throw BadInput("--out PREFIX is required");
        const bool tty = isatty(2);
        const SweepResult sw = run_sweep(spec, tty ? progress_line : nullptr);
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
        write_all(files);
        std::ostringstream out;
        out << "sweep      " << sw.points.size() << " points in " << rounded(sw.seconds, 3) << " s ("
            << rounded(sw.points.size() / std::max(sw.seconds, 1e-9), 4) << " points/s, " << sw.threads << " threads)\n";
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
        if (boundary_out.empty()) throw BadInput("--out FILE.csv is required");
        const SweepResult sw = run_sweep(spec);
        const BoundarySet b = trace_boundaries(sw);
        write_all({{boundary_out, boundary_csv(spec, b)}});
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
