// chart: render a chart spec (TOML) to PREFIX.svg, with each panel's grid and boundaries as CSV.
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "sweep_flags.hpp"
#include "ddemap/io/chart_spec.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct ChartArgs {
    std::string spec;
    FormatArg format;
    OutArg out;
} chart_args;
}  // namespace

void add_chart_flags(CLI::App& app) {
    app.add_option("SPEC", chart_args.spec, "chart specification (TOML)")->required();
    chart_args.out.add_to(app, "PREFIX.svg, and for panel K its grid PREFIX-panelK.csv and boundaries PREFIX-panelK-boundaries.csv", true);
    chart_args.format.add_to(app, {Format::Table, Format::Json});
    run_flags().add_to(app, true);
}

int run_chart() {
    const Format format = chart_args.format.parse();
    const std::string prefix = chart_args.out.prepare("chart", {".svg"});
    const ChartSpec spec = parse_chart_spec(read_input_file("SPEC", chart_args.spec), chart_args.spec);
    if (!spec.panels.empty()) check_sweep_size(panel_sweep(spec, 0), "chart", false, spec.panels.size());  // panels share the window and ring
    ExecutionPolicy policy;
    policy.progress = progress_printer("chart", "grid rows of all panels");
    const RenderedChart r = render_chart(spec, policy);
    const auto files = chart_files(r, prefix);
    // an earlier run's panels beyond this chart's are not left beside it: PREFIX-panelK*.csv, K > panels
    std::vector<std::string> stale;
    const std::filesystem::path base(prefix);
    const std::string stem = base.filename().string() + "-panel";
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(base.parent_path().empty() ? "." : base.parent_path(), ec)) {
        const std::string name = entry.path().filename().string();
        if (name.compare(0, stem.size(), stem) != 0) continue;
        std::size_t k = stem.size(), n = 0;
        while (k < name.size() && name[k] >= '0' && name[k] <= '9') n = 10 * n + static_cast<std::size_t>(name[k++] - '0');
        const std::string tail = name.substr(k);
        if (k > stem.size() && n > spec.panels.size() && (tail == ".csv" || tail == "-boundaries.csv"))
            stale.push_back((base.parent_path() / name).string());
    }
    write_files_atomic(files, stale);
    std::vector<std::string> names;
    for (const auto& f : files) names.push_back(json_string(f.first));
    if (format == Format::Json) {
        JsonEnvelope e;
        e.command = "chart";
        e.status = chart_uncertified(r) > 0 ? "uncertified" : "converged";
        e.message = chart_message(r);
        e.inputs = JsonObject().string("spec", chart_args.spec).string("out", prefix).str();
        e.result = JsonObject()
                       .integer("panels", static_cast<long long>(spec.panels.size()))
                       .number("seconds", r.seconds)
                       .json("files", json_array(names))
                       .str();
        print_json(e);
    } else {
        std::cout << "chart      " << counted(static_cast<long long>(spec.panels.size()), "panel") << " in " << rounded(r.seconds, 3) << " s\nwrote      " << prefix
                  << ".svg, " << prefix << "-panel1.csv .. and their -boundaries.csv\n";
    }
    if (chart_uncertified(r) > 0) {  // the reason of the UNDECIDED points on stderr
        std::cerr << "ddemap: chart undecided (uncertified): " << chart_message(r) << "\n";
        return exit_not_converged;
    }
    return exit_ok;
}

}  // namespace ddemap::cli
