// paper: the seed paper's main job (io/paper.hpp): classification table and growth on stdout,
// figures and data under PREFIX.
#include <iostream>
#include <sstream>

#include "builtin_maps.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "tables.hpp"
#include "ddemap/io/paper.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct PaperArgs {
    FormatArg format;
    OutArg out;
} paper_args;
}  // namespace

void add_paper_flags(CLI::App& app) {
    paper_args.out.add_to(app,
                    "PREFIX.svg (the diagrams), PREFIX.json, PREFIX-classification.csv/.json/.svg, PREFIX-panelK.csv, "
                    "PREFIX-panelK-boundaries.csv, PREFIX-growth.csv/.svg (a folder DIR: DIR/paper...)",
                    true);
    paper_args.format.add_to(app, {Format::Table, Format::Json});
    run_flags().add_to(app, false);
}

int run_paper() {
    const Format format = paper_args.format.parse();
    const std::string prefix = paper_args.out.prepare("paper", {".svg", ".json", "-classification.csv", "-classification.json", "-classification.svg", "-growth.csv", "-growth.svg"});
    const PaperJob job = run_paper_job(builtin_paper_toml, "maps/paper.toml", builtin_classification_toml, "maps/classification.toml", {},
                                       progress_printer("paper", "steps"));
    const std::string envelope = write_paper(job, prefix);
    if (format == Format::Json) {
        std::cout << envelope;  // print_json's text
        return exit_ok;
    }
    std::ostringstream out;
    out << classification_table(job.study.classification, job.study.options.cars, "the paper's calibration table (built in)");
    out << "\ndisturbance growth behind the dip (22.4 -> 19.7 -> 22.4 m/s), platoons of up to " << job.study.options.followers << " followers\n";
    out << growth_table(job.study.growth);
    out << "\nfigures and data: " << prefix << ".svg (" << job.figure_spec.panels.size() << " panels), " << prefix << "-classification.svg, "
        << prefix << "-classification.csv/.json, " << prefix << "-panel*.csv, " << prefix << "-panel*-boundaries.csv, " << prefix
        << "-growth.csv/.svg, " << prefix << ".json\n";
    std::cout << out.str();
    return exit_ok;
}

}  // namespace ddemap::cli
