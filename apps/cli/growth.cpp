// growth: disturbance growth for each car (the paper's table, or the cars of --fleet).
#include <algorithm>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "lead_flags.hpp"
#include "limits.hpp"
#include "tables.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/growth.hpp"

namespace ddemap::cli {

namespace {
struct GrowthArgs {
    std::string followers = "15", fleet;
    LeadArgs lead;
    FormatArg format;
    OutArg out;
} growth_args;
}  // namespace

void add_growth_flags(CLI::App& app) {
    app.add_option("--fleet", growth_args.fleet,
                   std::string("the cars, each distinct car in platoons of its own (default: the paper's table): ") + cars_help() +
                       "; every car of the ovrv law")
        ->type_name("CARS");
    app.add_option("--followers", growth_args.followers, "longest platoon")->capture_default_str();
    growth_args.lead.add_to(app);
    growth_args.out.add_to(app, "PREFIX.csv, PREFIX.json and PREFIX.svg", false);
    growth_args.format.add_to(app);
    run_flags().add_to(app, true);
}

int run_growth() {
    const int followers = static_cast<int>(parse_integer("--followers", growth_args.followers, 1, 200, "an integer from 1 to 200"));
    const Format format = growth_args.format.parse();
    const std::string prefix = growth_args.out.given() ? growth_args.out.prepare("growth") : std::string();
    std::string label;
    const LeadProfile lead = growth_args.lead.parse(label);
    const std::vector<CalibratedVehicle> vehicles =
        growth_args.fleet.empty() ? paper_calibration_table() : distinct_cars(vehicles_argument("--fleet", growth_args.fleet));
    const std::string source = growth_args.fleet.empty() ? "the paper's calibration table (built in)" : growth_args.fleet;
    // sized before the work as simulate is: the platoons run in parallel (memory: the largest
    // ones at once), about 2 us per car and step in all (simulate's measured rate)
    double largest = 0.0, car_steps = 0.0, steps = 0.0, t_end = 0.0;
    for (const CalibratedVehicle& v : vehicles) {
        const SimEstimate size = estimate_simulation(lead, platoon_of(v, followers));
        largest = std::max(largest, size.memory_bytes);
        car_steps += size.car_steps;
        steps = std::max(steps, size.steps);
        t_end = size.t_end;
    }
    const std::string what = std::to_string(vehicles.size()) + " platoons of " + std::to_string(followers) + " followers over " + rounded(t_end, 6) +
                             " s (" + rounded(steps, 3) + " steps)";
    const double parallel = static_cast<double>(std::min<long>(thread_count(), static_cast<long>(vehicles.size())));
    check_size("growth", what, "memory", largest * parallel);
    check_size("growth", what, "time", car_steps * 2e-6);
    ExecutionPolicy policy;
    policy.progress = progress_printer("growth", "platoons");  // one line per platoon simulated
    const auto g = disturbance_growth(vehicles, lead, followers, SimOptions{}, policy);
    JsonEnvelope e;
    e.command = "growth";
    e.inputs = JsonObject().string("vehicles", source).string("lead", label).integer("followers", followers).str();
    for (const GrowthResult& r : g)  // the envelope's status: the first platoon that is undecided
        if (r.status != Status::Converged && e.status == "converged") e.status = to_string(r.status);
    e.message = growth_message(g);
    e.result = growth_json(g, label);
    const std::string csv = growth_csv(g);
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", growth_svg(g, label)}});
    print_output(format, e, csv, [&] { std::cout << growth_table(g); });
    int code = exit_ok;  // a diverged platoon is undecided: its reason on stderr, exit 4
    for (const GrowthResult& r : g)
        if (r.status != Status::Converged) code = report_undecided(r.status, "growth of " + r.name, r.message);
    return code;
}

}  // namespace ddemap::cli
