// chart: render a chart spec (TOML) to PREFIX.svg.
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
    chart_args.out.add_to(app, "PREFIX.svg", true);
    chart_args.format.add_to(app, {Format::Table, Format::Json});
    run_flags().add_to(app, true);
}

int run_chart() {
    const Format format = chart_args.format.parse();
    const std::string prefix = chart_args.out.prepare("chart", {".svg"});
    const ChartSpec spec = parse_chart_spec(read_input_file("SPEC", chart_args.spec), chart_args.spec);
    if (!spec.panels.empty()) check_sweep_size(panel_sweep(spec, 0), "chart", false, spec.panels.size());  // panels share the window and ring
    ExecutionPolicy policy;
    policy.progress = progress_printer("chart", "panels");
    const RenderedChart r = render_chart(spec, policy);
    write_files_atomic({{prefix + ".svg", r.svg}});
    if (format == Format::Json) {
        JsonEnvelope e;
        e.command = "chart";
        e.inputs = JsonObject().string("spec", chart_args.spec).string("out", prefix).str();
        e.result = JsonObject()
                       .integer("panels", static_cast<long long>(spec.panels.size()))
                       .number("seconds", r.seconds)
                       .json("files", json_array({json_string(prefix + ".svg")}))
                       .str();
        print_json(e);
    } else {
        std::cout << "chart      " << spec.panels.size() << " panels in " << rounded(r.seconds, 3) << " s\nwrote      " << prefix << ".svg\n";
    }
    return exit_ok;
}

}  // namespace ddemap::cli
