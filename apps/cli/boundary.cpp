// boundary: stability boundaries in a window of two parameters (LO:HI) by continuation.
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "sweep_flags.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/boundary.hpp"

namespace ddemap::cli {

namespace {
struct BoundaryArgs {
    ModelArgs model;
    RingArg ring;
    std::string grid = "41";
    std::string ring_curves = "auto";
    FormatArg format;
    OutArg out;
} boundary_args;
}  // namespace

void add_boundary_flags(CLI::App& app) {
    boundary_args.model.add_to(app);
    boundary_args.ring.add_to(app, "22", "ring size N >= 2 (at most 10^9; 10^6 with --ring-curves all), or inf");
    boundary_args.out.add_to(app, "PREFIX.csv (one row per curve point) and PREFIX.json", true);
    app.add_option("--ring-curves", boundary_args.ring_curves,
                   "ring Hopf curves: all (every mode's), envelope (only the boundary of the ring-stable region, any N), auto (all up to 64 cars)")
        ->type_name("all|envelope|auto")
        ->capture_default_str();
    app.add_option("--seed-grid", boundary_args.grid, "grid points per axis used to seed the branches")->capture_default_str();
    boundary_args.format.add_to(app);
    run_flags().add_to(app, true);
}

int run_boundary() {
    const Format format = boundary_args.format.parse();
    const int grid = static_cast<int>(parse_integer("--seed-grid", boundary_args.grid, 5, 2001, "an integer between 5 and 2001"));
    SweepSpec spec = sweep_spec(boundary_args.model, boundary_args.ring, "", false, grid);
    const RingCurves ring_curves = parse_ring_curves_flag(boundary_args.ring_curves, spec);
    if (ring_curves == RingCurves::All && spec.cars > 0) spec.ring_method = "modes";  // every mode's curve needs every mode's root
    check_sweep_size(spec, "boundary", false, 1, ring_curves == RingCurves::All);
    const std::string prefix = boundary_args.out.prepare("boundary", {".csv", ".json"});
    ExecutionPolicy policy;
    policy.progress = progress_printer("boundary", "seed-grid rows");
    const SweepResult sw = run_sweep(spec, policy);
    BoundaryOptions bo;
    bo.ring_curves = ring_curves;
    bo.progress = progress_printer("boundary", "seeds");
    const BoundarySet b = trace_boundaries(sw, bo);
    JsonEnvelope e;
    e.command = "boundary";
    e.inputs = sweep_inputs(spec).integer("seed_grid", grid).string("ring_curves", ring_curves_name(ring_curves)).str();
        e.message = b.rejected > 0 ? std::to_string(b.rejected) + " seeds failed their Newton correction (the branches through the others were traced)" : "";
    e.result = boundary_json(b);
    const std::string csv = boundary_csv(spec, b);
    write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "boundaries " << counted(static_cast<long long>(b.curves.size()), "curve") << " (" << b.seeds << " seeds on a " << grid << " x " << grid << " grid)\n";
        for (std::size_t i = 0; i < b.curves.size(); ++i) {
            const auto& c = b.curves[i];
            out << "  " << i + 1 << "  " << kind_name(c.kind) << "/" << subkind_name(c.kind);
            if (c.kind == BoundaryKind::RingHopf) out << " mode " << c.mode;
            out << ": " << counted(static_cast<long long>(c.points.size()), "point") << ", max residual " << rounded(c.max_residual, 2) << (c.closed ? ", closed" : "") << "\n";
        }
        out << "wrote      " << prefix << ".csv " << prefix << ".json\n";
        std::cout << out.str();
    });
    return exit_ok;
}

}  // namespace ddemap::cli
