// sweep: a grid over two model parameters (LO:HI:COUNT), the boundaries, the chart.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "sweep_flags.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/boundary.hpp"

namespace ddemap::cli {

namespace {
struct SweepArgs {
    ModelArgs model;
    RingArg ring;
    std::string x, mark;
    bool no_boundaries = false;
    bool peak = false;
    std::string ring_curves = "auto";
    FormatArg format;
    OutArg out;
} sweep_args;
}  // namespace

namespace {

/// The cars of --mark as the chart's markers (car_markers); a car whose other parameters differ
/// from the chart's is named on stderr.
std::vector<ChartMarker> mark_cars(const SweepSpec& spec) {
    std::vector<std::string> notes;
    std::vector<ChartMarker> out;
    try {
        out = car_markers(distinct_cars(cars_argument("--mark", sweep_args.mark)), spec, &notes);
    } catch (const BadInput&) {
        throw;
    } catch (const std::invalid_argument& e) {
        throw BadInput(std::string("--mark: ") + e.what());
    }
    for (const auto& n : notes) std::cerr << "ddemap: sweep: --mark: " << n << "\n";
    return out;
}

}  // namespace

void add_sweep_flags(CLI::App& app) {
    sweep_args.model.add_to(app);
    sweep_args.ring.add_to(app, "22", "ring size N >= 2 (at most 10^9; 10^6 with --ring-curves all), or inf");
    sweep_args.out.add_to(app, "PREFIX.csv, PREFIX.json, PREFIX.svg, PREFIX-boundaries.csv", true);
    app.add_option("--x", sweep_args.x, "which swept parameter is the horizontal axis (default: alphabetical)");
    app.add_flag("--no-boundaries", sweep_args.no_boundaries, "skip the boundary continuation");
    app.add_flag("--peak", sweep_args.peak,
                 "also decide peak (L-infinity) string stability at every L2-stable point, ||h||_1 <= 1: the chart shades \"L2 stable, peak "
                 "unstable\" apart (about 0.03 s more per such point)");
    app.add_option("--mark", sweep_args.mark,
                   std::string("cars drawn on the chart, each distinct car as a labelled marker at its values of the two swept parameters, "
                               "with its 95 % confidence ellipse where it has a fit's covariance: ") +
                       cars_help())
        ->type_name("CARS");
    app.add_option("--ring-curves", sweep_args.ring_curves,
                   "ring Hopf curves: all (every mode's), envelope (only the boundary of the ring-stable region, any N), auto (all up to 64 cars)")
        ->type_name("all|envelope|auto")
        ->capture_default_str();
    sweep_args.format.add_to(app);
    run_flags().add_to(app, true);
}

int run_sweep() {
    const Format format = sweep_args.format.parse();
    SweepSpec spec = sweep_spec(sweep_args.model, sweep_args.ring, sweep_args.x, true, 0);
    spec.peak = sweep_args.peak;
    const RingCurves ring_curves = parse_ring_curves_flag(sweep_args.ring_curves, spec);
    // every mode's curve needs every mode's root; the envelope is seeded from the winding sweep
    if (!sweep_args.no_boundaries && ring_curves == RingCurves::All && spec.cars > 0) spec.ring_method = "modes";
    check_sweep_size(spec, "sweep", true, 1, !sweep_args.no_boundaries && ring_curves == RingCurves::All);
    const std::vector<ChartMarker> marks = sweep_args.mark.empty() ? std::vector<ChartMarker>{} : mark_cars(spec);
    const std::string prefix = sweep_args.out.prepare("sweep", {".csv", ".json", ".svg", "-boundaries.csv"});
    ExecutionPolicy policy;
    policy.progress = progress_printer("sweep", "rows");
    const SweepResult sw = run_sweep(spec, policy);
    BoundarySet b;
    BoundaryOptions bo;
    bo.ring_curves = ring_curves;
    bo.progress = progress_printer("sweep", "boundary seeds");
    if (!sweep_args.no_boundaries) b = trace_boundaries(sw, bo);
    const BoundarySet* bp = sweep_args.no_boundaries ? nullptr : &b;
    JsonEnvelope e;
    e.command = "sweep";
    JsonObject inputs = sweep_inputs(spec).boolean("boundaries", !sweep_args.no_boundaries).string("ring_curves", ring_curves_name(ring_curves));
    if (spec.peak) inputs.boolean("peak", true);
    if (!sweep_args.mark.empty()) inputs.string("mark", sweep_args.mark);
    e.inputs = inputs.str();
    e.has_solver = true;  // the ring method: winding tables, or per mode where boundaries need it
    e.solver_given = spec.ring_method;
    e.solver_used = sw.ring_method;
    e.status = sw.uncertified > 0 ? "uncertified" : "converged";
    e.message = sweep_message(sw);
    e.result = sweep_json(sw, bp);
    const std::string csv = sweep_csv(sw);
    std::vector<std::pair<std::string, std::string>> files = {
        {prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", sweep_chart_svg(spec, sw, bp, marks)}};
    if (bp) files.emplace_back(prefix + "-boundaries.csv", boundary_csv(spec, b));
    // without boundaries an earlier run's PREFIX-boundaries.csv is not left beside the new chart
    write_files_atomic(files, bp ? std::vector<std::string>{} : std::vector<std::string>{prefix + "-boundaries.csv"});
    print_output(format, e, csv, [&] {
        int classes[5] = {0, 0, 0, 0, 0};
        for (const auto& p : sw.points) ++classes[region_class(p)];
        std::ostringstream out;
        out << "sweep      " << sw.points.size() << " points in " << rounded(sw.seconds, 3) << " s ("
            << static_cast<long>(std::lround(sw.points.size() / std::max(sw.seconds, 1e-9))) << " points/s, " << counted(sw.threads, "thread") << ")\n";
        out << "regions    plant unstable " << classes[0] << ", ring unstable " << classes[1] << ", string unstable " << classes[2]
            << ", string stable " << classes[3] + classes[4];
        if (spec.peak) out << " (peak stable " << classes[4] << ")";
        if (sw.uncertified > 0) out << " (" << sw.uncertified << " of them UNDECIDED: no certificate)";
        out << "\n";
        if (bp) out << "boundaries " << counted(static_cast<long long>(b.curves.size()), "curve") << "\n";
        out << "wrote      ";
        for (const auto& f : files) out << f.first << " ";
        out << "\n";
        std::cout << out.str();
    });
    if (sw.uncertified > 0)  // the reason of the UNDECIDED points on stderr
        std::cerr << "ddemap: sweep undecided (uncertified): " << e.message << "\n";
    return sw.uncertified > 0 ? exit_not_converged : exit_ok;
}

}  // namespace ddemap::cli
