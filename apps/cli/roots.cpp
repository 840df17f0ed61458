// roots: rightmost characteristic roots of a ring of identical cars (model flags, --ring),
// a mixed ring (--fleet FILE.csv or --fleet-pattern), or any linear DDE (--system FILE.json).
#include <filesystem>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "fleet_flags.hpp"
#include "limits.hpp"
#include "ring_fast.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/system_roots.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/io/system_json.hpp"
#include "ddemap/solve/equilibrium.hpp"

namespace ddemap::cli {

namespace {

struct RootsArgs {
    ModelArgs model;
    RingArg ring;
    std::string count = "6", system, fleet, pattern, cars, length, solver = "auto", degree = "0", ring_method = "auto";
    FormatArg format;
    OutArg out;
} roots_args;

int parse_count() { return static_cast<int>(parse_integer("--count", roots_args.count, 1, 10000, "an integer between 1 and 10000")); }

int parse_degree() {
    const int d = static_cast<int>(parse_integer("--degree", roots_args.degree, 0, 200, "0 (automatic) or an integer 2..200"));
    if (d == 1) throw BadInput("--degree = '1': expected 0 (automatic) or an integer 2..200");
    return d;
}

/// Progress of the root work of --system and --fleet on stderr (README "Limits and progress"):
/// `ddemap: roots: step 12 of at most 200000, Re = -0.53 (4.1 s; time left unknown)`, a step
/// being a contour count (product), an Arnoldi shift (sparse) or a collocation degree (dense,
/// where the step shown is M); the search ends when it has found the roots, long before its
/// budget, so no time left is estimated.
/// The search's progress printer with the run-time limit (limits.hpp with_time_limit).
BranchProgress root_progress() { return with_time_limit(search_progress_printer("roots", "Re")); }

/// The result's message, or why the run-time limit stopped it.
std::string root_message(const RootResult& r) { return r.status == Status::Cancelled && !time_limit_message().empty() ? time_limit_message() : r.message; }

/// Prints (and with --out writes PREFIX.csv, PREFIX.json) the command's output.
void emit(const JsonEnvelope& e, const std::string& csv, const std::string& table, Format format, const std::string& prefix) {
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    print_output(format, e, csv, [&] { std::cout << table; });
}

int run_system(Format format, const std::string& prefix) {
    if (roots_args.model.given() || roots_args.ring.given())
        throw BadInput("--system takes the whole problem from the file: expected no model parameters, --model or --ring");
    RootOptions o;
    o.count = parse_count();
    o.degree = parse_degree();
    o.method = root_method(roots_args.solver);
    if (o.method == "contour") throw BadInput("--solver product goes with --fleet rings: expected auto, dense or sparse for --system");
    // sized before it is read: the text, the parsed document (about twice the text) and two
    // parses at about 20 ns per byte (measured), so that a 1 GB dense file is refused at once
    {
        std::error_code ec;
        const auto bytes = static_cast<double>(std::filesystem::file_size(roots_args.system, ec));
        if (!ec) {
            const std::string what = "--system " + roots_args.system + " (" + human_bytes(bytes) + " of JSON)";
            check_size("roots", what, "memory", 3.0 * bytes);
            check_size("roots", what, "time", 4e-8 * bytes);
        }
    }
    const std::string text = read_input_file("--system", roots_args.system);
    std::string equilibrium_json, equilibrium_line;
    Status eq_status = Status::Converged;
    const std::optional<LinearDDE> lin = [&] {
        if (!is_nonlinear_system_json(text)) {
            // every matrix is held dense (16 n^2 bytes each) and its norm taken by a full SVD
            // (about 64 n^2 bytes and 2e-9 n^3 s each, measured)
            // a text search first: a dense file of too many states is refused before its
            // tokenisation (a 550 MB file once took 30 s and 1.4 GB to be refused)
            if (const auto quick = quick_peek_linear_dde_json(text)) {
                const double n = static_cast<double>(std::max(quick->dimension, 0L)), terms = static_cast<double>(quick->delays) + 1.0;
                const std::string what = "a " + std::to_string(quick->dimension) + "-state system with " + std::to_string(quick->delays) +
                                         (quick->delays == 1 ? " delay" : " delays");
                check_size("roots", what, "memory", n * n * (16.0 * terms + 64.0));
                check_size("roots", what, "time", 2e-9 * n * n * n * terms);
            }
            const LinearDdeShape shape = peek_linear_dde_json(text, roots_args.system);
            const double n = static_cast<double>(std::max(shape.dimension, 0L)), terms = static_cast<double>(shape.delays) + 1.0;
            const std::string what = "a " + std::to_string(shape.dimension) + "-state system with " + std::to_string(shape.delays) + (shape.delays == 1 ? " delay" : " delays");
            if (shape.sparse) {
                // real triplets are held sparse: the sparse LU's fill and the Krylov vectors, a
                // few kB per nonzero and state (measured: 10^4 states, 5e4 nonzeros, 0.3 GB)
                check_size("roots", what, "memory", 4e3 * (static_cast<double>(shape.nonzeros) + n) * terms);
            } else {
                check_size("roots", what, "memory", n * n * (16.0 * terms + 64.0));
                check_size("roots", what, "time", 2e-9 * n * n * n * terms);
            }
            return std::optional<LinearDDE>(read_linear_dde_json(text, roots_args.system));
        }
        // a nonlinear file: its equilibrium by Newton from the file's guess, then the linearisation there
        const NonlinearSystemFile file = read_nonlinear_system_json(text, roots_args.system);
        const EquilibriumResult eq = find_equilibrium(*file.system, file.equilibrium);
        eq_status = eq.status;
        equilibrium_json = equilibrium_result_json(eq);
        equilibrium_line = "equilibrium";
        for (Eigen::Index i = 0; i < eq.x.size(); ++i)
            equilibrium_line += (i ? ", " : " ") + file.system->variables()[static_cast<std::size_t>(i)] + " = " + rounded(eq.x[i], 10);
        equilibrium_line += " (" + eq.message + ")\n";
        if (!converged(eq.status)) return std::optional<LinearDDE>();
        return std::optional<LinearDDE>(linearise(*file.system, eq.x));
    }();
    if (!lin) {
        // no equilibrium: undecided, the Newton result printed
        JsonEnvelope e;
        e.command = "roots";
        e.inputs = JsonObject().string("system", roots_args.system).integer("count", o.count).integer("degree", o.degree).str();
        e.status = to_string(eq_status);
        e.message = "no equilibrium found from the guess";
        e.result = JsonObject().json("equilibrium", equilibrium_json).str();
        emit(e, roots_csv({}), equilibrium_line + "verdict    UNDECIDED (no equilibrium: " + to_string(eq_status) + ")\n", format, prefix);
        std::cerr << "ddemap: undecided: " << roots_args.system << ": Newton found no equilibrium from the guess (" << to_string(eq_status)
                  << "); give a better \"equilibrium\" guess in the file\n";
        return exit_not_converged;
    }
    const LinearDDE& dde = *lin;
    o.progress = root_progress();
    o.before = root_size_guard("roots", "a " + std::to_string(dde.dimension()) + "-state system");
    const SystemRootResult s = analyse_system(dde, o);
    const RootResult& r = s.roots;
    JsonEnvelope e;
    e.command = "roots";
    e.inputs = JsonObject().string("system", roots_args.system).integer("count", o.count).integer("degree", o.degree).str();
    e.has_solver = true;
    e.solver_given = solver_name(r.method_given);
    e.solver_used = solver_name(r.method_used);
    e.status = to_string(r.status);
    e.message = root_message(r);
    e.result = system_roots_json(dde, s);
    if (!equilibrium_json.empty()) e.result = JsonObject().json("equilibrium", equilibrium_json).json("linearisation", e.result).str();
    std::ostringstream out;
    out << "system     " << roots_args.system << " (dimension " << dde.dimension() << ", " << dde.delays().size() << " delays)\n";
    out << equilibrium_line;
    out << "solver     " << solver_name(r.method_used) << ", M = " << r.degree << " (" << to_string(r.status) << ")\n";
    out << (r.status == Status::Converged ? "trusted    " : "why not    ") << root_message(r) << "\n";
    // no root computed (an empty spectrum or a failed solver): the table says so, never "-inf"
    out << "abscissa   " << (std::isfinite(s.spectral_abscissa) ? rounded(s.spectral_abscissa, 10) + " 1/s" : std::string("none (no root was computed)")) << "\n";
    out << "verdict    " << verdict_word(s.verdict);
    if (s.verdict == Verdict::Undecided) out << " (" << to_string(r.status) << ")";
    else if (s.verdict == Verdict::Marginal) out << " (roots on the imaginary axis to rounding: not asymptotically stable)";
    out << "\n\n";
    out << roots_table(r.roots);
    emit(e, roots_csv(r.roots), out.str(), format, prefix);
    return report_undecided(r.status, "roots", root_message(r));
}

int run_fleet(Format format, const std::string& prefix) {
    auto raw = roots_args.model.raw;
    const std::string speed = raw.count("speed") ? raw.at("speed") : "";
    raw.erase("speed");
    if (!roots_args.fleet.empty() && !roots_args.pattern.empty()) throw BadInput("--fleet and --fleet-pattern: expected only one of them");
    if (!roots_args.system.empty() || !raw.empty() || roots_args.model.model != "ovrv")
        throw BadInput("--fleet/--fleet-pattern define the ring: expected no --system, --model or model parameters "
                       "(--speed or --length set the equilibrium, --ring the size of a pattern ring)");
    if (roots_args.ring.given() && !roots_args.cars.empty()) throw BadInput("--ring and --cars: expected only --ring (--cars is its old spelling)");
    const std::string ring_text = roots_args.ring.given() ? roots_args.ring.text : roots_args.cars;
    // a file or a pattern, the same way in --fleet and --fleet-pattern (its old spelling);
    // --ring N repeats the cars to N
    const std::string flag = roots_args.fleet.empty() ? "--fleet-pattern" : "--fleet";
    const std::string spec = roots_args.fleet.empty() ? roots_args.pattern : roots_args.fleet;
    RingArg n;
    n.text = ring_text;
    const Fleet fleet = fleet_argument(flag, spec, ring_text.empty() ? 0 : n.parse(false));
    MixedRingOptions o;
    set_equilibrium(o, speed, roots_args.length);
    o.roots.method = root_method(roots_args.solver);
    o.roots.count = parse_count();
    o.roots.degree = parse_degree();
    o.roots.progress = root_progress();
    o.roots.before = root_size_guard("roots", "a ring of " + std::to_string(fleet.size()) + " cars");
    const MixedRingResult r = analyse_mixed_ring(fleet, o);
    const RootResult& rr = r.roots;
    JsonEnvelope e;
    e.command = "roots";
    JsonObject in;
    in.string(roots_args.fleet.empty() ? "fleet_pattern" : "fleet", spec)
        .integer("ring", static_cast<long long>(fleet.size()));
    equilibrium_inputs(in, o);
    in.integer("count", o.roots.count).integer("degree", o.roots.degree);
    e.inputs = in.str();
    e.has_solver = true;
    e.solver_given = solver_name(rr.method_given);
    e.solver_used = solver_name(rr.method_used);
    e.status = to_string(rr.status);
    e.message = root_message(rr);
    e.result = mixed_ring_json(r, fleet.size());
    std::ostringstream out;
    out << "fleet      " << spec << ": " << fleet.size() << " cars, speed "
        << rounded(r.equilibrium.speed, 6) << " m/s, ring length " << rounded(r.equilibrium.length, 8) << " m\n";
    out << "solver     " << solver_name(rr.method_used);
    if (rr.method_used == "contour")  // no collocation: the counts of the argument principle
        out << ", " << rr.contour_counts << " contour counts, " << rr.evaluations << " evaluations";
    else
        out << ", M = " << rr.degree << ", " << rr.shifts << " shifts, " << rr.factorizations << " LU factorisations";
    out << " (" << to_string(rr.status) << ")\n";
    out << (rr.status == Status::Converged ? "trusted    " : "why not    ") << root_message(rr) << "\n";
    out << "trivial    "
        << (r.trivial_found ? "lambda = 0 found (|lambda| = " + rounded(r.trivial_root, 3) + "), left out"
                            : std::string("not among the rightmost roots"))
        << "\n";
    if (!std::isnan(r.product_residual)) out << "check      max |prod Gamma_i(lambda) - 1| = " << rounded(r.product_residual, 3) << "\n";
    // no root computed (a cancelled or failed search): the table says so, never "-inf"
    out << "abscissa   " << (std::isfinite(r.spectral_abscissa) ? rounded(r.spectral_abscissa, 10) + " 1/s" : std::string("none (no root was computed)")) << "\n";
    if (rr.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(rr.status) << ")\n\n";
    else
        out << "verdict    " << verdict_word(r.verdict) << " ("
            << (r.unstable_count_complete ? counted(r.unstable_roots, "unstable root") : std::to_string(r.unstable_roots) + " or more unstable roots")
            << ")\n\n";
    out << roots_table(rr.roots);
    emit(e, roots_csv(rr.roots), out.str(), format, prefix);
    return report_undecided(rr.status, "roots", root_message(rr));
}

int run_ring(Format format, const std::string& prefix) {
    if (roots_args.solver != "auto" || roots_args.degree != "0" || !roots_args.length.empty() || !roots_args.cars.empty())
        throw BadInput("--solver, --degree, --length and --cars go with --fleet, --fleet-pattern or --system; a ring of identical cars "
                       "takes --ring-method");
    const auto model = roots_args.model.build();
    const std::string given = parse_ring_method(roots_args.ring_method);
    const Linearisation lin = model->linearise();
    const std::string method = resolve_ring_method(given, lin);
    const int cars = roots_args.ring.parse(true, method == "winding" ? kWindingMaxCars : kModesMaxCars);
    const int count = parse_count();
    // N = inf: the wave numbers of the scan, then the steps of the search for --count roots at the abscissa's
    const FastRing fast = analyse_ring_fast(lin, cars, method, count, progress_printer("roots", cars == 0 ? "wave numbers" : "modes"),
                                            cars == 0 ? search_progress_printer("roots", "Re") : nullptr, ring_modes_guard("roots", cars));
    const RingResult& r = fast.ring;
    JsonEnvelope e;
    e.command = "roots";
    e.inputs = model_inputs(*model).json("ring", json_ring(cars)).integer("count", count).string("ring_method", given).str();
    e.has_solver = true;
    e.solver_given = given;
    e.solver_used = fast.method_used;
    e.status = to_string(r.status);
    e.message = r.reason;
    e.result = append_ring_method_json(ring_roots_json(r), fast);
    std::ostringstream out;
    out << "model      " << model->name();
    for (const auto& [k, v] : model->parameters()) out << " " << k << "=" << rounded(v, 6);
    out << "\n";
    out << "ring       N = " << ring_name(cars) << "\n";
    out << "method     " << fast.method_used;
    if (fast.winding_ran)
        out << " (" << fast.winding.tables << " winding passes" << (fast.fell_back ? ", undecided: per-mode path" : "") << ")";
    out << ", listed roots: " << fast.listed_by;
    if (fast.listed_by == "modes") out << ", M = " << r.degree;
    out << " (" << to_string(r.status) << ")\n";
    out << "trivial    lambda = 0 in mode 0 (ring-length invariance), excluded from the verdict\n";
    if (fast.method_used == "winding" && r.verdict == Verdict::Undecided) {
        out << "abscissa   none (the winding pass is undecided)";
    } else {
        out << "abscissa   " << rounded(r.spectral_abscissa, 10) << " 1/s";
        if (cars == 0) out << (r.abscissa_is_limit ? " (approached as theta -> 0)" : " at theta = " + rounded(r.abscissa_theta, 6));
        else out << " (mode " << r.abscissa_mode << ")";
    }
    out << "\n";
    out << "verdict    ring " << verdict_word(r.verdict);
    if (r.verdict == Verdict::Undecided) out << " (" << to_string(r.status) << ")";
    else if (cars > 0 && fast.method_used == "winding")
        out << " (" << counted(fast.winding.unstable_roots, "unstable root") << ", " << fast.winding.marginal_roots << " marginal)";
    else if (cars > 0) out << " (" << counted(r.unstable_roots, "unstable root") << ", " << r.marginal_roots << " marginal)";
    out << "\n";
    // the verdict is the certified winding pass's; a listing that did not converge is marked as such
    if (fast.method_used == "winding" && r.verdict != Verdict::Undecided && r.status != Status::Converged)
        out << "roots      UNSETTLED (" << to_string(r.status) << "): the verdict above is certified by the winding count alone; "
            << "the rows below are not certified\n";
    out << "\n";
    out << "  #   mode  theta [rad]          re [1/s]        im [rad/s]    residual\n";
    int i = 0;
    for (const auto& x : r.roots) {
        char line[200];
        std::snprintf(line, sizeof line, "%3d %6s %12.6f %17.12f %18.12f %11.2e\n", ++i, x.mode < 0 ? "-" : std::to_string(x.mode).c_str(),
                      x.theta, x.root.value.real(), x.root.value.imag(), x.root.residual);
        out << line;
    }
    emit(e, ring_roots_csv(r), out.str(), format, prefix);
    return report_undecided(r.status, "roots", r.reason);
}

}  // namespace

void add_roots_flags(CLI::App& app) {
    roots_args.model.add_to(app);
    roots_args.ring.add_to(app, "22",
                     "ring size N >= 2 (at most 10^9 when the car reacts only to the car ahead: one winding pass, milliseconds; "
                     "the per-mode path, at most 10^6, takes about 0.3 ms per mode), or inf for all wave numbers; "
                     "with --fleet: the number of cars, the fleet repeated (default: the fleet once)");
    app.add_option("--count", roots_args.count, "how many rightmost roots to list")->capture_default_str();
    app.add_option("--system", roots_args.system, "any linear DDE from a JSON file (dimension, delays, A0, A; see README) instead of a ring");
    app.add_option("--fleet", roots_args.fleet, std::string("a mixed ring of these cars in this order, repeated to --ring cars: ") + cars_help())
        ->type_name("CARS");
    app.add_option("--fleet-pattern", roots_args.pattern, "the same as --fleet (kept for old scripts)")->type_name("CARS");
    app.add_option("--cars", roots_args.cars, "old spelling of --ring for --fleet-pattern")->group("");
    app.add_option("--length", roots_args.length, "fleet: ring length [m] (sum of the gaps); the speed follows");
    app.add_option("--solver", roots_args.solver,
                   "--fleet: auto (product: the argument principle on det Delta, for cars that react to the car ahead and "
                   "connected cruise control cars that react to the car two ahead too), product, dense or sparse; "
                   "--system: auto (dense up to 16 states), dense or sparse")
        ->capture_default_str();
    app.add_option("--ring-method", roots_args.ring_method,
                   "a ring of identical cars: auto (winding when the car reacts only to the car ahead, else modes), winding "
                   "(verdict, counts and abscissa from one certified winding pass whatever N) or modes (every mode on its own)")
        ->capture_default_str()
        ->type_name("auto|winding|modes");
    app.add_option("--degree", roots_args.degree, "--fleet (dense and sparse paths) and --system (sparse path): collocation degree M (0 = automatic)")
        ->capture_default_str();
    roots_args.format.add_to(app);
    run_flags().add_to(app, true);
    roots_args.out.add_to(app, "PREFIX.csv (the roots) and PREFIX.json", false);
}

int run_roots() {
    const Format format = roots_args.format.parse();
    const std::string prefix = roots_args.out.given() ? roots_args.out.prepare("roots", {".csv", ".json"}) : std::string();
    if ((!roots_args.fleet.empty() || !roots_args.pattern.empty() || !roots_args.system.empty()) && roots_args.ring_method != "auto")
        throw BadInput("--ring-method = '" + roots_args.ring_method + "' goes with a ring of identical cars; --fleet and --system take --solver");
    if (!roots_args.fleet.empty() || !roots_args.pattern.empty()) return run_fleet(format, prefix);
    if (!roots_args.system.empty()) return run_system(format, prefix);
    return run_ring(format, prefix);
}

}  // namespace ddemap::cli
