// classify: plant, ring and string verdicts of calibrated vehicles (built-in table or a CSV).
#include <cstdio>
#include <iostream>
#include <sstream>

#include "builtin_maps.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "sweep_flags.hpp"
#include "tables.hpp"
#include "ddemap/analysis/classify.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct Args {
    std::string file, svg;
    RingArg ring;
    FormatArg format;
    OutArg out;
} args;
}  // namespace

void add_classify_flags(CLI::App& app) {
    app.add_option("VEHICLES.csv", args.file, "CSV with columns name,k1,k2,th,tau[,eta] (OVRV; units 1/s^2, 1/s, s, s, m)");
    args.ring.add_to(app, "22", "ring size N >= 2 or inf for the ring verdict");
    args.format.add_to(app);
    args.out.add_to(app, "PREFIX.csv, PREFIX.json and PREFIX.svg (one (k1, k2) chart per vehicle, vehicle marked)", false);
    app.add_option("--svg", args.svg, "old spelling: write only the figure to this file")->group("");
    run_flags().add_to(app, true);
}

int run_classify() {
    const int cars = args.ring.parse();
    const Format format = args.format.parse();
    if (args.out.given() && !args.svg.empty()) throw BadInput("--out and --svg: expected only --out (--svg is its old spelling)");
    const std::string prefix = args.out.given() ? args.out.prepare("classify") : std::string();
    std::string svg_file;
    if (!args.svg.empty()) {
        OutArg o;
        o.text = args.svg;
        svg_file = o.prepare("classify") + ".svg";
    }
    std::vector<CalibratedVehicle> vehicles;
    std::string source = "the paper's calibration table (built in)";
    if (args.file.empty()) {
        vehicles = paper_calibration_table();
    } else {
        vehicles = read_vehicles_csv(read_input_file("VEHICLES.csv", args.file), args.file);
        source = args.file;
    }
    const bool figure = !prefix.empty() || !svg_file.empty();
    ChartSpec chart;
    if (figure) {
        chart = classification_chart(parse_chart_spec(builtin_classification_toml, "maps/classification.toml"), vehicles, cars);
        if (!chart.panels.empty()) check_sweep_size(panel_sweep(chart, 0), "classify", false, chart.panels.size());
    }
    const auto rows = classify(vehicles, cars);
    JsonEnvelope e;
    e.command = "classify";
    e.inputs = JsonObject().string("vehicles", source).json("ring", json_ring(cars)).str();
    e.result = classification_json(rows, cars, source);
    Status status = Status::Converged;
    for (const auto& r : rows) {
        if (r.ring.status != Status::Converged) status = r.ring.status;
        if (r.string.plant_roots.status != Status::Converged) status = r.string.plant_roots.status;
    }
    e.status = to_string(status);
    const std::string csv = classification_csv(rows);
    if (figure) {
        ExecutionPolicy policy;
        policy.progress = progress_printer("classify", "panels");
        const std::string svg = render_chart(chart, policy).svg;
        if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", svg}});
        else write_files_atomic({{svg_file, svg}});
    }
    print_output(format, e, csv, [&] { std::cout << classification_table(rows, cars, source); });
    return exit_code(status);
}

}  // namespace ddemap::cli
