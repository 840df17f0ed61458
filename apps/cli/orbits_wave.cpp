// orbits --wave K: the branch of discrete travelling waves of wave number K of a built-in ring
// (--model ov|idm --ring N), born at the Hopf point of ring mode K, in the reduced form whose
// cost does not depend on N; the same JSON keys as orbits, plus "wave".
#include "orbits_wave.hpp"

#include <iostream>
#include <sstream>

#include "format.hpp"
#include "limits.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap::cli {

std::string crossing_lines(const OrbitBranch& b) {
    std::ostringstream out;
    const std::string& par = b.parameter;
    auto crossing = [&](const char* label, const OrbitCrossing& x) {
        if (x.located)
            out << label << par << " = " << rounded(x.par, 10) << ", period " << rounded(x.period, 8) << ", mu = " << rounded(x.multiplier.real(), 8)
                << (x.multiplier.imag() != 0.0 ? " +/- " + rounded(x.multiplier.imag(), 8) + "i" : std::string()) << " (located: ||mu| - 1| = "
                << rounded(x.accuracy, 2) << ", bracket " << rounded(x.par_bracket, 2) << " in " << par << ")\n";
        else
            out << label << par << " ~ " << rounded(x.par, 6) << ", period " << rounded(x.period, 6) << " (not located: interpolated)\n";
    };
    for (const OrbitCrossing& x : b.period_doublings) crossing("doubling   ", x);
    for (const OrbitCrossing& x : b.tori) crossing("torus      ", x);
    return out.str();
}

int run_orbits_wave(const OrbitsWaveArgs& a) {
    if (a.problem.model.empty())
        throw BadInput("--wave = '" + a.wave + "' needs a built-in ring (--model ov|idm --ring N): a --system file has no ring to travel on");
    if (a.hopf_given) throw BadInput("--hopf: not used with --wave (the branch starts at the first Hopf point of ring mode K from --from)");
    if (a.adapt) throw BadInput("--adapt: not available with --wave (the travelling-wave form keeps the uniform mesh)");
    if (!a.svg.empty()) throw BadInput("--svg: not available with --wave (use --format csv or json)");
    if (!a.variable.empty()) throw BadInput("--variable: not used with --wave (the table shows car 0's headway and speed)");
    const Format format = a.format.parse();
    const std::string prefix = a.out.given() ? a.out.prepare("orbits", {".csv", ".json"}) : std::string();
    NonlinearProblemArgs::Problem built = a.problem.load();  // the ring's flags checked (N up to 2000)
    TravellingWaveOptions o;
    o.model = a.problem.model;
    o.cars = static_cast<int>(parse_integer("--ring", a.problem.ring, 2, 2000, "an integer between 2 and 2000"));
    o.wave = static_cast<int>(parse_integer("--wave", a.wave, 1, o.cars - 1, "a wave number from 1 to N - 1 = " + std::to_string(o.cars - 1)));
    PeriodicOrbitOptions& po = o.orbit;
    po.parameter = a.problem.par;
    po.from = built.from;
    po.to = built.to;
    po.degree = static_cast<int>(parse_integer("--degree", a.degree, 1, 20, "an integer between 1 and 20"));
    po.intervals = static_cast<int>(parse_integer("--intervals", a.intervals, 2, 10000, "an integer between 2 and 10000"));
    po.max_points = static_cast<int>(parse_integer("--points", a.points, 2, 100000, "an integer between 2 and 100000"));
    if (!a.initial_step.empty()) {
        po.initial_step = parse_number("--initial-step", a.initial_step);
        const double upper = a.max_step.empty() ? po.max_step : 1e6;  // with --max-step: checked against it below
        if (!(po.initial_step >= po.min_step && po.initial_step <= upper))
            throw BadInput("--initial-step = '" + a.initial_step + "': expected a value from 1e-6 to " + rounded(upper, 6) +
                           (a.max_step.empty() ? std::string(" (the largest step, --max-step)") : std::string()));
    }
    if (!a.max_step.empty()) {  // as orbits: the largest step of the same step control (analysis/bifurcation/internal/orbit_continuation.hpp)
        po.max_step = parse_number("--max-step", a.max_step);
        if (!(po.max_step >= po.initial_step && po.max_step <= 1e6))
            throw BadInput("--max-step = '" + a.max_step + "': expected a value from " + rounded(po.initial_step, 6) + " (the first step) to 1e6");
    }
    // one line per wave: ddemap: orbits: 37 waves (at most 100), headway = 2.81 (4.2 s)
    po.progress = branch_progress_printer("orbits", "waves", po.parameter, false);
    // N > 10: the full ring's multipliers of every wave by the matrix-free path, after the
    // branch, one progress line per wave (ddemap: orbits: 3 waves with multipliers (of 30), ...)
    if (a.stability && a.no_stability) throw BadInput("--stability and --no-stability: expected at most one of them");
    // the matrix-free multipliers cost 0.2 s per wave on 100 cars but 23-30 s (K = 100) to far more
    // (K = 1, 10: a uniform mesh of thousands of intervals) on 1000 cars (BENCHMARKS.md): by default
    // only up to wave_stability_default_cars, beyond with --stability
    constexpr int wave_stability_default_cars = 200;
    const bool too_long = o.cars > wave_stability_default_cars && !a.stability;
    o.sparse_floquet = !a.no_stability && !too_long;
    o.stability_progress = branch_progress_printer("orbits", "waves with multipliers", po.parameter, true);
    const ParameterMap parameters = built.system->parameters();  // --par at --from, the others as given or default
    const TravellingWaveBranch w = travelling_wave_branch(parameters, o);
    const OrbitBranch& b = w.branch;
    const std::string state = o.model == "ov" ? "h" : "s";
    const std::vector<std::string> variables{state + "0", "v0"};
    JsonObject& inputs = built.inputs;
    inputs.string("par", po.parameter).number("from", po.from).number("to", po.to).integer("wave", o.wave).integer("degree", po.degree)
        .integer("intervals", po.intervals).integer("points", po.max_points).number("initial_step", po.initial_step);
    if (!a.max_step.empty()) inputs.number("max_step", po.max_step);  // only when given, as orbits
    JsonEnvelope e;
    e.command = "orbits";
    e.inputs = inputs.str();
    e.status = to_string(b.status);
    e.message = b.message;
    e.result = travelling_wave_json(w, variables);
    const std::string csv = orbit_branch_csv(b, variables, built.units);
    std::vector<std::pair<std::string, std::string>> files;
    if (!prefix.empty()) {
        files.push_back({prefix + ".csv", csv});
        files.push_back({prefix + ".json", envelope_json(e)});
        write_files_atomic(files);
    }
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        const std::string& par = po.parameter;
        if (w.hopf.status == Status::Converged)
            out << "hopf       " << par << " = " << rounded(w.hopf.par, 10) << ", omega = " << rounded(w.hopf.omega, 10) << " (ring mode " << o.wave
                << " of " << o.cars << " cars)\n";
        out << "wave       car i + 1 = car i shifted by " << o.wave << " T / " << o.cars << "; reduced form: one car, " << counted(static_cast<long long>(b.points.size()), "wave")
            << ", degree " << b.degree << " on " << (b.intervals > po.intervals ? "up to " : "") << b.intervals << " intervals (ended: " << b.stop << ")\n";
        out << "  " << pad(par, 14) << pad("period", 14) << pad("amp " + variables[0], 14) << pad("amp v0", 14) << pad("max|mu|", 12) << "stable\n";
        for (std::size_t i = 0; i < b.points.size(); ++i) {
            const PeriodicOrbit& p = b.points[i];
            const bool undecided = w.stability_method == "matrix_free" && (i >= w.stability.size() || w.stability[i].status != Status::Converged);
            out << "  " << pad(rounded(p.par, 8), 14) << pad(rounded(p.period, 8), 14) << pad(rounded(p.max[0] - p.min[0], 6), 14)
                << pad(rounded(p.max[1] - p.min[1], 6), 14) << pad(p.multipliers.empty() ? "-" : rounded(p.max_nontrivial, 4), 12)
                << (undecided || (!p.multipliers.empty() && !p.undecided.empty()) ? "undecided" : p.multipliers.empty() ? "not computed" : p.stable ? "yes" : "no") << "\n";
        }
        for (const OrbitFold& f : b.folds)
            out << "fold       " << par << " = " << rounded(f.par, 10) << ", period " << rounded(f.period, 8) << (f.located ? "" : " (not located)") << "\n";
        out << crossing_lines(b);
        if (b.points.empty()) {
        } else if (w.full_ring_stability && w.stability_method == "matrix_free") {
            out << "stability  Floquet multipliers of the full ring of " << o.cars << " cars along the wave (matrix-free: Arnoldi, largest ones); max |mu_trivial - 1| = "
                << rounded(b.max_trivial_distance, 2) << "\n";
            for (std::size_t i = 0; i < w.stability.size(); ++i)
                if (w.stability[i].status != Status::Converged)
                    out << "  wave " << i + 1 << " (" << par << " = " << rounded(b.points[i].par, 8) << "): undecided, " << w.stability[i].message << "\n";
        } else if (w.full_ring_stability)
            out << "stability  Floquet multipliers of the full ring of " << o.cars << " cars along the wave; max |mu_trivial - 1| = "
                << rounded(b.max_trivial_distance, 2) << "\n";
        else
            out << "stability  not computed (" << (a.no_stability ? std::string("--no-stability")
                                                   : too_long ? "more than " + std::to_string(wave_stability_default_cars) +
                                                                    " cars: the matrix-free multipliers take minutes per wave; --stability computes them"
                                                              : std::string("the full ring's multipliers need --ring up to 10 or the matrix-free path"))
                << "; the reduced form alone does not decide the ring's stability)\n";
        if (!b.points.empty())
            out << "accuracy   max residual = " << rounded(b.max_residual, 2) << ", max drift |mu| = " << rounded(w.max_drift, 2)
                << ", max relative defect between collocation points = " << rounded(w.max_defect, 2) << "\n";
        if (b.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(b.status) << "): " << b.message << "\n";
        else if (w.stability_status != Status::Converged)
            out << "verdict    UNDECIDED (" << to_string(w.stability_status) << "): " << w.stability_message << "\n";
        if (!files.empty()) {
            out << "wrote     ";
            for (const auto& f : files) out << " " << f.first;
            out << "\n";
        }
        std::cout << out.str();
    });
    if (b.status == Status::Converged && w.stability_status != Status::Converged)
        return report_undecided(w.stability_status, "orbits", w.stability_message);
    return report_undecided(b.status, "orbits", b.message);
}

}  // namespace ddemap::cli
