// growth: disturbance growth for every setting of the calibration table.
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "lead_flags.hpp"
#include "tables.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/growth.hpp"

namespace ddemap::cli {

namespace {
struct Args {
    std::string followers = "15";
    LeadArgs lead;
    FormatArg format;
    OutArg out;
} args;
}  // namespace

void add_growth_flags(CLI::App& app) {
    app.add_option("--followers", args.followers, "longest platoon")->capture_default_str();
    args.lead.add_to(app);
    args.out.add_to(app, "PREFIX.csv, PREFIX.json and PREFIX.svg", false);
    args.format.add_to(app);
}

int run_growth() {
    const int followers = static_cast<int>(parse_integer("--followers", args.followers, 1, 200, "an integer from 1 to 200"));
    const Format format = args.format.parse();
    const std::string prefix = args.out.given() ? args.out.prepare("growth") : std::string();
    std::string label;
    const LeadProfile lead = args.lead.parse(label);
    const auto g = disturbance_growth(paper_calibration_table(), lead, followers);
    JsonEnvelope e;
    e.command = "growth";
    e.inputs = JsonObject().string("vehicles", "the paper's calibration table (built in)").string("lead", label).integer("followers", followers).str();
    e.result = growth_json(g, label);
    const std::string csv = growth_csv(g);
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", growth_svg(g, label)}});
    print_output(format, e, csv, [&] { std::cout << growth_table(g); });
    return exit_ok;
}

}  // namespace ddemap::cli
