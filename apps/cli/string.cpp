// string: plant and string stability of identical cars (model flags), optionally the ring
// verdict for --ring N|inf.
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "ring_fast.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct StringArgs {
    ModelArgs model;
    RingArg ring;
    std::string ring_method = "auto";
    FormatArg format;
    OutArg out;
} string_args;
}  // namespace

void add_string_flags(CLI::App& app) {
    string_args.model.add_to(app);
    string_args.ring.add_to(app, "", "also decide ring stability for N cars (N >= 2 or inf; at most 10^9 on the winding path, 10^6 on the per-mode path)");
    app.add_option("--ring-method", string_args.ring_method,
                   "with --ring: auto (winding when the car reacts only to the car ahead, else modes), winding or modes")
        ->capture_default_str()
        ->type_name("auto|winding|modes");
    string_args.format.add_to(app);
    string_args.out.add_to(app, "PREFIX.csv and PREFIX.json", false);
    run_flags().add_to(app, false);
}

int run_string() {
    const auto model = string_args.model.build();
    const Format format = string_args.format.parse();
    const Linearisation lin = model->linearise();
    const std::string given = parse_ring_method(string_args.ring_method);
    if (string_args.ring.empty() && given != "auto") throw BadInput("--ring-method = '" + given + "' goes with --ring: expected --ring N|inf too");
    std::optional<int> cars;
    std::string method;
    if (!string_args.ring.empty()) {
        method = resolve_ring_method(given, lin);
        cars = string_args.ring.parse(true, method == "winding" ? kWindingMaxCars : kModesMaxCars);
    }
    const std::string prefix = string_args.out.given() ? string_args.out.prepare("string", {".csv", ".json"}) : std::string();
    StringOptions so;
    so.peak = true;  // peak (L-infinity) string stability beside the L2 one
    const StringResult s = analyse_string(lin, so);
    std::optional<RingResult> ring;
    std::optional<FastRing> fast;
    if (cars) {
        fast = analyse_ring_fast(lin, *cars, method, 0, progress_printer("string", *cars == 0 ? "wave numbers" : "modes"), nullptr, ring_modes_guard("string", *cars));
        ring = fast->ring;
    }
    const RingResult* rp = ring ? &*ring : nullptr;
    Status status = s.plant_roots.status;
    if (ring && ring->status != Status::Converged) status = ring->status;
    const bool peak_undecided = status == Status::Converged && s.peak->verdict == Verdict::Undecided;
    if (peak_undecided) status = s.peak->status;

    JsonEnvelope e;
    e.command = "string";
    JsonObject in = model_inputs(*model);
    if (cars) in.json("ring", json_ring(*cars));
    if (cars) in.string("ring_method", given);
    e.inputs = in.str();
    if (fast) {
        e.has_solver = true;
        e.solver_given = given;
        e.solver_used = fast->method_used;
    }
    e.status = to_string(status);
    e.message = ring && ring->status != Status::Converged ? ring->reason : peak_undecided ? s.peak->message : s.plant_roots.message;
    e.result = fast ? append_ring_method_json(string_json(s, rp), *fast) : string_json(s, rp);
    const std::string csv = string_csv(s, rp);
    if (!prefix.empty()) write_files_atomic({{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}});
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        out << "model            " << model->name();
        for (const auto& [k, v] : model->parameters()) out << " " << k << "=" << rounded(v, 6);
        out << "\n";
        out << "plant            " << (s.plant_stable ? std::string("stable") : verdict_word(s.plant_verdict))
            << "   (rightmost root of D: Re = " << rounded(s.plant_abscissa, 6) << ")\n";
        out << "sup |Gamma(iw)|  " << rounded(s.sup_gamma, 10);
        if (s.omega_peak > 0.0) out << " at w = " << rounded(s.omega_peak, 8) << " rad/s";
        else out << " (only approached as w -> 0)";
        out << "\n";
        out << "low frequency    c" << s.lowfreq.decisive_order << " = " << rounded(s.lowfreq_margin, 6)
            << (s.lowfreq.attenuates ? "  (attenuates as w -> 0)" : "  (AMPLIFIES as w -> 0)") << "\n";
        if (ring) {
            char label[32];
            std::snprintf(label, sizeof label, "%-16s ", ("ring N=" + ring_name(*cars)).c_str());
            out << label << (ring->stable ? std::string("stable") : verdict_word(ring->verdict)) << "   (spectral abscissa "
                << rounded(ring->spectral_abscissa, 6) << ")\n";
        }
        const PeakResult& pk = *s.peak;
        out << "peak ||h||_1     ";
        if (pk.verdict == Verdict::Undecided) out << "undecided (" << pk.message << ")";
        else if (!pk.finite) out << (s.plant_stable ? "not computed; > 1, since sup |Gamma(iw)| > 1" : "infinite (the plant is unstable)");
        else
            out << rounded(pk.norm, 10) << " (error estimate " << rounded(pk.error, 2) << "); a step of the lead's speed "
                << (pk.overshoot <= pk.error ? std::string("does not overshoot") : "overshoots by " + rounded(100.0 * pk.overshoot, 4) + " %");
        out << "\n";
        out << "verdict          string " << verdict_word(s.string_verdict) << ", peak " << verdict_word(pk.verdict) << "\n";
        std::cout << out.str();
    });
    if (s.plant_roots.status != Status::Converged) return report_undecided(status, "string: plant", s.plant_roots.message);
    if (ring && ring->status != Status::Converged) return report_undecided(status, "string: ring", ring->reason);
    if (s.peak->verdict == Verdict::Undecided) return report_undecided(s.peak->status, "string: peak", s.peak->message);
    return exit_ok;
}

}  // namespace ddemap::cli
