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
#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/design/verdict_distance.hpp"
#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct ClassifyArgs {
    std::string file, svg, samples = "4000", ring_samples = "200", seed = "1";
    bool peak = true, peak_flag = false, no_peak = false, distance = false;
    RingArg ring;
    FormatArg format;
    OutArg out;
} classify_args;
}  // namespace

void add_classify_flags(CLI::App& app) {
    app.add_option("VEHICLES", classify_args.file,
                   std::string("the cars to classify, each distinct car once (default: the paper's table): ") + cars_help() +
                       ". Every car is of the ovrv law (units of k1, k2, th, tau, eta: 1/s^2, 1/s, s, s, m). With a fit's covariance (the "
                       "cov_k1_k1 .. cov_eta_eta columns or the JSON that calibrate writes) the verdicts come with probabilities, from samples "
                       "of the parameters' normal distribution restricted to the fit's bounds (lo_k1, hi_k1 .. as calibrate writes; "
                       "calibrate's default bounds when there are none)")
        ->type_name("CARS");
    app.add_option("--samples", classify_args.samples, "parameter samples per vehicle with a covariance")->capture_default_str();
    app.add_option("--ring-samples", classify_args.ring_samples, "of these, how many are also classified as rings (a ring costs 30-400 string verdicts)")
        ->capture_default_str();
    app.add_option("--seed", classify_args.seed, "seed of the parameter samples")->capture_default_str();
    app.add_flag("--distance", classify_args.distance,
                 "also find the distance to the other string verdict: the smallest relative change of (k1, k2, th, tau), "
                 "sqrt(sum ((x - x0) / x0)^2), that turns a string-stable car unstable or an unstable one stable (about 0.2 s more per car)");
    app.add_flag("--no-peak", classify_args.no_peak,
                 "skip peak (L-infinity) string stability, which is decided by default: ||h||_1 <= 1 for the impulse response h of Gamma "
                 "(about 0.03 s per car)");
    app.add_flag("--peak", classify_args.peak_flag, "the peak verdict (the default; kept for old scripts)");
    classify_args.ring.add_to(app, "22", "ring size N >= 2 or inf for the ring verdict");
    classify_args.format.add_to(app);
    classify_args.out.add_to(app, "PREFIX.csv, PREFIX.json and PREFIX.svg (one (k1, k2) chart per vehicle, vehicle marked)", false);
    app.add_option("--svg", classify_args.svg, "old spelling: write only the figure to this file")->group("");
    run_flags().add_to(app, true);
}

int run_classify() {
    if (classify_args.no_peak && classify_args.peak_flag) throw BadInput("--peak and --no-peak: expected one of them");
    classify_args.peak = !classify_args.no_peak;
    const int cars = classify_args.ring.parse();
    const Format format = classify_args.format.parse();
    if (classify_args.out.given() && !classify_args.svg.empty()) throw BadInput("--out and --svg: expected only --out (--svg is its old spelling)");
    const std::string prefix = classify_args.out.given() ? classify_args.out.prepare("classify") : std::string();
    // --svg FILE writes exactly FILE (through a link; into a device such as /dev/null directly)
    const std::string svg_file = classify_args.svg.empty() ? std::string() : output_file("--svg", classify_args.svg);
    std::vector<CalibratedVehicle> vehicles;
    std::string source = "the paper's calibration table (built in)";
    if (classify_args.file.empty()) {
        vehicles = paper_calibration_table();
    } else {
        vehicles = distinct_cars(vehicles_argument("VEHICLES", classify_args.file));
        source = classify_args.file;
    }
    UncertaintyOptions uo;
    uo.samples = static_cast<int>(parse_integer("--samples", classify_args.samples, 1, 1000000, "an integer 1..1000000"));
    // calibrate's default search space, replaced per vehicle by the bounds its file carries (lo_NAME, hi_NAME)
    uo.domain = classification_domain();
    uo.ring_samples = static_cast<int>(parse_integer("--ring-samples", classify_args.ring_samples, 0, 1000000, "an integer 0..1000000"));
    uo.seed = static_cast<unsigned long long>(parse_integer("--seed", classify_args.seed, 0, 4294967295L, "an integer 0..4294967295"));
    // sized before the work (CPU time of one core, measured on 300 random cars and on fits with a
    // covariance): a verdict about 0.011 s per car (0.08 s with --ring inf), and a ring verdict
    // grows with N (0.23 s at N = 1,000, 22 s at 10^5 for A_min: 2.3e-4 N s); a car with a
    // covariance adds about 0.0005 s per parameter sample and a ring verdict per ring sample
    {
        const double ring_s = cars == 0 ? 0.09 : std::max(0.008, 2.3e-4 * cars);
        double seconds = 0.0;
        for (const auto& v : vehicles) {
            seconds += (cars == 0 ? 0.08 : std::max(0.011, ring_s)) + (classify_args.peak ? 0.03 : 0.0) + (classify_args.distance ? 0.2 : 0.0);
            if (v.has_covariance) seconds += 0.0005 * uo.samples + ring_s * uo.ring_samples;
        }
        const std::string what = counted(static_cast<long long>(vehicles.size()), "car") + (cars > 0 ? " in rings of " + std::to_string(cars) + " cars" : std::string());
        // the cars run in parallel, each on one core
        const double wall = seconds / static_cast<double>(std::max<std::size_t>(1, std::min<std::size_t>(static_cast<std::size_t>(std::max(1, thread_count())), vehicles.size())));
        check_size("classify", what, "time", wall);
        announce_estimate("classify", what, wall);
    }
    const bool figure = !prefix.empty() || !svg_file.empty();
    ChartSpec chart;
    if (figure) {
        chart = classification_chart(parse_chart_spec(builtin_classification_toml, "maps/classification.toml"), vehicles, cars, classify_args.file);
        if (!chart.panels.empty()) check_sweep_size(panel_sweep(chart, 0), "classify", false, chart.panels.size());
    }
    ExecutionPolicy policy;
    policy.progress = progress_printer("classify", "cars");  // one line per car classified
    StringOptions so;
    so.peak = classify_args.peak;
    auto rows = classify(vehicles, cars, uo, policy, so);
    if (classify_args.distance) {
        ExecutionPolicy dp;
        dp.progress = progress_printer("classify", "verdict distances");
        add_verdict_distances(rows, {}, dp);
    }
    JsonEnvelope e;
    e.command = "classify";
    JsonObject inputs;
    inputs.string("vehicles", source).json("ring", json_ring(cars));
    inputs.boolean("peak", classify_args.peak);
    if (classify_args.distance) inputs.boolean("distance", true);
    for (const auto& r : rows)
        if (r.has_uncertainty) {
            inputs.integer("samples", uo.samples).integer("ring_samples", uo.ring_samples).integer("seed", static_cast<long long>(uo.seed));
            break;
        }
    e.inputs = inputs.str();
    e.result = classification_json(rows, cars, source);
    const Status status = classification_status(rows);
    for (const auto& r : rows)
        if (r.has_uncertainty && r.uncertainty.status != Status::Converged)
            std::cerr << "ddemap: classify: " << r.vehicle.name << ": probabilities undecided: " << r.uncertainty.message << "\n";
    e.status = to_string(status);
    e.message = classification_message(rows);
    const std::string csv = classification_csv(rows);
    if (figure) {
        ExecutionPolicy policy;
        policy.progress = progress_printer("classify", "panels");
        const std::string svg = render_chart(chart, policy).svg;
        if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", svg}});
        else write_files_atomic({{svg_file, svg}});
    }
    print_output(format, e, csv, [&] { std::cout << classification_table(rows, cars, source); });
    for (const auto& r : rows) {  // the reason of each UNDECIDED on stderr
        report_undecided(r.string.plant_roots.status, "classify: " + r.vehicle.name + ": plant", r.string.plant_roots.message);
        report_undecided(r.ring.status, "classify: " + r.vehicle.name + ": ring", r.ring.reason);
        if (r.string.peak && r.string.peak->verdict == Verdict::Undecided)
            report_undecided(r.string.peak->status, "classify: " + r.vehicle.name + ": peak", r.string.peak->message);
        if (r.has_distance) report_undecided(r.distance.status, "classify: " + r.vehicle.name + ": verdict distance", r.distance.message);
    }
    return exit_code(status);
}

}  // namespace ddemap::cli
