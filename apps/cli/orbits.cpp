// orbits: the branch of periodic orbits born at a Hopf point of a nonlinear DDE's equilibrium
// branch (a system file with expressions, or the built-in ov ring), with Floquet stability,
// folds of orbits, period doublings and tori; the bifurcation diagram as SVG.
#include <algorithm>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "format.hpp"
#include "limits.hpp"
#include "nonlinear_flags.hpp"
#include "orbits_wave.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/json.hpp"

namespace ddemap::cli {

namespace {

struct OrbitsArgs {
    NonlinearProblemArgs problem;
    std::string hopf = "0", degree = "4", intervals = "40", points = "100", variable, svg;
    std::string wave, initial_step, max_step;
    std::string par2, from2, to2;
    std::string period_doubling;
    std::string from_simulation, history, guess;
    CLI::Option* hopf_option = nullptr;
    bool adapt = false;
    bool no_stability = false;
    bool stability = false;
    FormatArg format;
    OutArg out;
} orbits_args;


/// The orbit of a --guess file: columns t and one per variable (a header row of names allowed,
/// '#' comments), times increasing, the last row one period after the first.
struct GuessSamples {
    std::vector<double> times;
    Eigen::MatrixXd states;
};

GuessSamples read_guess(const std::string& path, int n) {
    const std::string text = read_input_file("--guess", path);
    std::vector<std::vector<double>> rows;
    std::istringstream in(text);
    std::string line;
    int row = 0;
    while (std::getline(in, line)) {
        ++row;
        const std::size_t hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::vector<std::string> fields;
        std::string f;
        std::istringstream ls(line);
        while (std::getline(ls, f, ',')) {
            const std::size_t a = f.find_first_not_of(" \t\r"), z = f.find_last_not_of(" \t\r");
            fields.push_back(a == std::string::npos ? std::string() : f.substr(a, z - a + 1));
        }
        if (static_cast<int>(fields.size()) != n + 1)
            throw BadInput("--guess = " + path + ", row " + std::to_string(row) + ": expected " + std::to_string(n + 1) + " columns (t and one per variable), found " +
                           std::to_string(fields.size()));
        if (rows.empty() && !fields[0].empty() && !(std::isdigit(static_cast<unsigned char>(fields[0][0])) || fields[0][0] == '-' || fields[0][0] == '+' || fields[0][0] == '.'))
            continue;  // the header
        std::vector<double> v;
        for (std::size_t k = 0; k < fields.size(); ++k) v.push_back(parse_number("--guess = " + path + ", row " + std::to_string(row) + ", column " + std::to_string(k + 1), fields[k]));
        if (!rows.empty() && !(v[0] > rows.back()[0]))
            throw BadInput("--guess = " + path + ", row " + std::to_string(row) + ": t = " + fields[0] + ": expected times increasing");
        rows.push_back(std::move(v));
        if (rows.size() > 1000000) throw BadInput("--guess = " + path + ": more than 1,000,000 rows (expected one period, sampled)");
    }
    if (rows.size() < 4) throw BadInput("--guess = " + path + ": " + std::to_string(rows.size()) + " rows of numbers: expected at least 4 covering one period");
    GuessSamples g;
    g.states.resize(static_cast<Eigen::Index>(rows.size()), n);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        g.times.push_back(rows[i][0]);
        for (int k = 0; k < n; ++k) g.states(static_cast<Eigen::Index>(i), k) = rows[i][static_cast<std::size_t>(k) + 1];
    }
    return g;
}

}  // namespace

void add_orbits_flags(CLI::App& app) {
    orbits_args.problem.add_to(app);  // --system | --model ov|idm ..., --par, --from (the equilibrium branch, whose Hopf points start the orbits), --to
    orbits_args.hopf_option = app.add_option("--hopf", orbits_args.hopf, "the index (from 0, in the order met along the equilibrium branch) of the Hopf point to start from")
        ->capture_default_str()->type_name("INTEGER");
    app.add_option("--degree", orbits_args.degree, "degree d of the piecewise polynomials (1..20)")->capture_default_str()->type_name("INTEGER");
    app.add_option("--intervals", orbits_args.intervals, "number L of mesh intervals over one period (2..10000)")->capture_default_str()->type_name("INTEGER");
    app.add_option("--points", orbits_args.points, "the most orbits on the branch")->capture_default_str()->type_name("INTEGER");
    app.add_flag("--adapt", orbits_args.adapt,
                 "move the mesh after every orbit to equidistribute |x^(d+1)|^(1/(d+1)) (more accurate orbits, less accurate multipliers; see README)");
    app.add_option("--variable", orbits_args.variable, "the variable whose amplitude max - min the figure shows (default: the first)")->type_name("NAME");
    app.add_option("--svg", orbits_args.svg, "the bifurcation diagram (amplitude against the parameter, equilibria, Hopf and fold markers); with --par2 the curves in the plane (--par, --par2)");
    app.add_option("--par2", orbits_args.par2,
                   "a second parameter: continue every fold of the branch as a curve of folds of periodic orbits, every period doubling as a "
                   "curve of period doublings and every torus bifurcation as a curve of tori, in (--par, --par2), in the box [--from, --to] x "
                   "[--from2, --to2] (a fold curve also ends where it meets the Hopf curve, at a generalised Hopf point; a torus curve at a "
                   "double Hopf point)")
        ->type_name("NAME");
    app.add_option("--period-doubling", orbits_args.period_doubling,
                   "switch at period doubling K of the branch (from 0, in the order met) onto the branch of orbits of twice the period, "
                   "and follow it too (its own period doublings are the next of a cascade); PREFIX-doubled.csv, JSON result.period_doubled")
        ->type_name("K");
    app.add_option("--from-simulation", orbits_args.from_simulation,
                   "start from the orbit a simulation at --par = --from settles on (run to time T_END, read off its last third) instead of a "
                   "Hopf point, and follow the branch from there towards --to")
        ->type_name("T_END");
    app.add_option("--history", orbits_args.history,
                   "--from-simulation: the constant initial state, one value per variable (default: the equilibrium guess with the first "
                   "variable raised by 10 % of max(1, |x_1|))")
        ->type_name("V1,V2,..");
    app.add_option("--guess", orbits_args.guess,
                   "start from an orbit given as CSV (columns t and one per variable, rows covering one period, the last row one period "
                   "after the first) at --par = --from, instead of a Hopf point; the branch is followed towards --to")
        ->type_name("FILE");
    app.add_option("--from2", orbits_args.from2, "--par2: the lower end of its box (its value in the system must lie in [from2, to2])")->type_name("NUMBER");
    app.add_option("--to2", orbits_args.to2, "--par2: the upper end of its box")->type_name("NUMBER");
    orbits_args.format.add_to(app);
    orbits_args.out.add_to(app, "PREFIX.csv (one row per orbit and special point) and PREFIX.json; with --par2 also PREFIX-folds.csv, PREFIX-doublings.csv and PREFIX-tori.csv (one row per point of the curves of folds, of period doublings and of tori)", false);
    run_flags().add_to(app, false);

    app.add_option("--wave", orbits_args.wave,
                   "--model ov|idm --ring N: the travelling waves of wave number K (1..N-1; car i + 1 repeats car i shifted by K T / N) in "
                   "the reduced form, one car whatever N (see README)")
        ->type_name("K");
    app.add_option("--initial-step", orbits_args.initial_step, "--wave: the first step along the branch in its weighted norm (default 0.02; long waves need smaller)")
        ->type_name("H");
    app.add_flag("--no-stability", orbits_args.no_stability,
                 "--wave on more than 10 cars: skip the full ring's Floquet multipliers (matrix-free Arnoldi; on long rings far costlier than the branch)");
    app.add_flag("--stability", orbits_args.stability,
                 "--wave on more than 200 cars: compute the full ring's Floquet multipliers anyway (minutes per wave on 1000 cars; "
                 "by default not computed above 200 cars)");
    app.add_option("--max-step", orbits_args.max_step,
                   "the largest step along the branch in its weighted norm (default 0.1; larger steps: fewer orbits for the same stretch, "
                   "see README)")
        ->type_name("S");
}

int run_orbits() {
    const bool from_simulation = !orbits_args.from_simulation.empty(), from_file = !orbits_args.guess.empty();
    if (!orbits_args.wave.empty() && (from_simulation || from_file))
        throw BadInput(std::string(from_simulation ? "--from-simulation" : "--guess") + ": not with --wave (expected the orbits of a system or ring without --wave)");
    if (from_simulation && from_file) throw BadInput("--from-simulation and --guess: expected one start of the orbits");
    if (!orbits_args.history.empty() && !from_simulation) throw BadInput("--history: only with --from-simulation (expected --from-simulation T_END)");
    if ((from_simulation || from_file) && orbits_args.hopf_option && orbits_args.hopf_option->count() > 0)
        throw BadInput("--hopf: not with " + std::string(from_simulation ? "--from-simulation" : "--guess") + " (the orbits start from the simulation or the file)");
    if (!orbits_args.wave.empty() && !orbits_args.period_doubling.empty())
        throw BadInput("--period-doubling: not with --wave (expected the orbits of a system or ring without --wave)");
    if (!orbits_args.wave.empty() && !orbits_args.par2.empty()) throw BadInput("--par2: not with --wave (expected the orbits of a system or ring without --wave)");
    if (!orbits_args.wave.empty())
        return run_orbits_wave({orbits_args.problem, orbits_args.wave, orbits_args.degree, orbits_args.intervals, orbits_args.points, orbits_args.initial_step, orbits_args.svg, orbits_args.variable, orbits_args.adapt,
                                orbits_args.hopf_option && orbits_args.hopf_option->count() > 0, orbits_args.format, orbits_args.out, orbits_args.max_step, orbits_args.no_stability, orbits_args.stability});
    if (!orbits_args.par2.empty() || !orbits_args.from2.empty() || !orbits_args.to2.empty()) {
        if (!orbits_args.wave.empty()) throw BadInput("--par2: not with --wave (expected the orbits of a system or ring without --wave)");
        if (orbits_args.par2.empty()) throw BadInput("--from2/--to2 without --par2: expected --par2 NAME with them");
        if (orbits_args.from2.empty() || orbits_args.to2.empty()) throw BadInput("--par2 needs --from2 and --to2: expected the box of " + orbits_args.par2);
    }
    if (!orbits_args.initial_step.empty()) throw BadInput("--initial-step: only with --wave (expected --wave K)");
    if (orbits_args.no_stability) throw BadInput("--no-stability: only with --wave (expected --wave K)");
    if (orbits_args.stability) throw BadInput("--stability: only with --wave (expected --wave K)");
    const Format format = orbits_args.format.parse();
    const bool two = !orbits_args.par2.empty();
    const bool doubling = !orbits_args.period_doubling.empty();
    const int doubling_index =
        doubling ? static_cast<int>(parse_integer("--period-doubling", orbits_args.period_doubling, 0, 1000000, "an integer >= 0")) : -1;
    const std::string prefix = !orbits_args.out.given() ? std::string()
                               : two && doubling        ? orbits_args.out.prepare("orbits", {".csv", ".json", "-folds.csv", "-doublings.csv", "-doubled.csv"})
                               : two                    ? orbits_args.out.prepare("orbits", {".csv", ".json", "-folds.csv", "-doublings.csv"})
                               : doubling               ? orbits_args.out.prepare("orbits", {".csv", ".json", "-doubled.csv"})
                                                        : orbits_args.out.prepare("orbits", {".csv", ".json"});
    const std::string svg_file = orbits_args.svg.empty() ? std::string() : output_file("--svg", orbits_args.svg);
    PeriodicOrbitOptions o;
    const std::string& par = orbits_args.problem.par;
    o.parameter = par;
    const int hopf_index = static_cast<int>(parse_integer("--hopf", orbits_args.hopf, 0, 1000000, "an integer >= 0"));
    o.degree = static_cast<int>(parse_integer("--degree", orbits_args.degree, 1, 20, "an integer between 1 and 20"));
    o.intervals = static_cast<int>(parse_integer("--intervals", orbits_args.intervals, 2, 10000, "an integer between 2 and 10000"));
    o.max_points = static_cast<int>(parse_integer("--points", orbits_args.points, 2, 100000, "an integer between 2 and 100000"));
    o.adapt = orbits_args.adapt;
    if (!orbits_args.max_step.empty()) {
        o.max_step = parse_number("--max-step", orbits_args.max_step);
        if (!(o.max_step >= o.initial_step && o.max_step <= 1e6))
            throw BadInput("--max-step = '" + orbits_args.max_step + "': expected a value from " + rounded(o.initial_step, 6) +
                           " (the first step) to 1e6");
    }

    NonlinearProblemArgs::Problem built = orbits_args.problem.load();  // --from != --to checked there
    o.from = built.from;
    o.to = built.to;
    const std::vector<std::string>& variables = built.variables;
    int variable = 0;
    if (!orbits_args.variable.empty()) {
        const auto it = std::find(variables.begin(), variables.end(), orbits_args.variable);
        if (it == variables.end()) {
            std::string known;
            for (const auto& v : variables) known += (known.empty() ? "" : ", ") + v;
            throw BadInput("--variable = '" + orbits_args.variable + "': expected one of " + known);
        }
        variable = static_cast<int>(it - variables.begin());
    }
    // the mesh is sized before any work: N = L d n collocation unknowns; measured (ov rings, Wright's
    // equation, degree 4 to 20, N = 800 to 20,000): at most about 40 kB of memory per unknown (the
    // condensed linearisation's history window) and 2e-4 (d / 4) N seconds per orbit
    {
        const double n = static_cast<double>(built.system->dimension());
        const double unknowns = static_cast<double>(o.intervals) * o.degree * n;
        const std::string what = "a mesh of " + std::to_string(o.intervals) + " intervals of degree " + std::to_string(o.degree) + " (" +
                                 rounded(unknowns, 3) + " collocation unknowns)";
        // the doubled branch (--period-doubling) has twice the intervals: twice the memory, about
        // twice the time per orbit
        check_size("orbits", what + (doubling ? " and twice that for the doubled branch" : ""), "memory", (doubling ? 2.0 : 1.0) * 4e4 * unknowns);
        check_size("orbits", what + " for " + std::to_string(o.max_points) + " orbits" + (doubling ? " and as many of twice the period" : ""), "time",
                   (doubling ? 3.0 : 1.0) * 2e-4 * (o.degree / 4.0) * unknowns * o.max_points);
    }
    OrbitFoldCurveOptions fo;
    if (two) {
        if (orbits_args.par2 == par) throw BadInput("--par2 = '" + orbits_args.par2 + "': expected a parameter other than --par");
        const int j2 = built.system->parameter_index(orbits_args.par2);  // unknown: bad input naming the known ones
        fo.parameter2 = orbits_args.par2;
        fo.from2 = parse_number("--from2", orbits_args.from2);
        fo.to2 = parse_number("--to2", orbits_args.to2);
        if (!(fo.from2 < fo.to2)) throw BadInput("--from2 = '" + orbits_args.from2 + "', --to2 = '" + orbits_args.to2 + "': expected --from2 < --to2");
        const double held = built.system->parameter_values()[static_cast<std::size_t>(j2)];
        if (!(held >= fo.from2 && held <= fo.to2))
            throw BadInput("--par2 " + orbits_args.par2 + " = " + rounded(held, 15) + " (its value in the system): expected it in [--from2, --to2]");
        if (o.adapt) throw BadInput("--par2: not with --adapt (the fold curves are computed on the uniform mesh)");
        // each fold curve point is a few Newton steps on the extended system (measured 0.08 s for
        // 800 unknowns: about 1e-4 (d / 4) N seconds), at most 2 --points of them per curve; two
        // curves assumed (a branch has as many as it has folds, known only after it)
        const double n = static_cast<double>(built.system->dimension());
        const double unknowns = static_cast<double>(o.intervals) * o.degree * n;
        check_size("orbits", "fold curves of " + std::to_string(2 * o.max_points) + " points at most on a mesh of " + rounded(unknowns, 3) + " unknowns",
                   "time", 2.0 * 2.0 * 1e-4 * (o.degree / 4.0) * unknowns * o.max_points);
    }
    JsonObject& inputs = built.inputs;
    inputs.string("par", par).number("from", o.from).number("to", o.to);
    if (!from_simulation && !from_file) inputs.integer("hopf", hopf_index);
    inputs.integer("degree", o.degree).integer("intervals", o.intervals).integer("points", o.max_points).boolean("adapt", o.adapt);
    if (!orbits_args.max_step.empty()) inputs.number("max_step", o.max_step);  // only when given: the Python binding's envelope has no step option yet

    // the starts other than a Hopf point, read and sized before any work: at --par = --from
    Eigen::VectorXd sim_history;
    double sim_end = 0.0, sim_step = 0.0;
    GuessSamples guess_samples;
    if (from_simulation || from_file) {
        built.system->set_parameter(par, o.from);
        inputs.number(from_simulation ? "from_simulation" : "guess_at", o.from);
    }
    if (from_simulation) {
        const int n = built.system->dimension();
        sim_end = parse_number("--from-simulation", orbits_args.from_simulation);
        if (!(sim_end > 0.0 && sim_end <= 1e7)) throw BadInput("--from-simulation = '" + orbits_args.from_simulation + "': expected a run time above 0, at most 1e7");
        if (orbits_args.history.empty()) {
            sim_history = built.guess;
            sim_history(0) += 0.1 * std::max(1.0, std::abs(sim_history(0)));
        } else {
            std::vector<double> v;
            std::istringstream hs(orbits_args.history);
            std::string f;
            while (std::getline(hs, f, ',')) v.push_back(parse_number("--history", f));
            if (static_cast<int>(v.size()) != n)
                throw BadInput("--history = '" + orbits_args.history + "': expected " + std::to_string(n) + " values (one per variable), found " + std::to_string(v.size()));
            sim_history = Eigen::Map<const Eigen::VectorXd>(v.data(), n);
        }
        sim_step = default_simulation_step(*built.system);
        const std::vector<double> tau = built.system->delays();
        // measured about 1.5e-6 s per step and variable-delay pair (ov rings, Mackey-Glass)
        const double work = (sim_end / sim_step) * n * (static_cast<double>(tau.size()) + 1.0);
        check_size("orbits", "a simulation of " + rounded(sim_end / sim_step, 3) + " steps of " + std::to_string(n) + " variables", "time", 1.5e-6 * work);
        check_size("orbits", "a simulation of " + rounded(sim_end / sim_step, 3) + " steps of " + std::to_string(n) + " variables", "memory",
                   8.0 * 3.0 * n * (sim_end / sim_step));
        inputs.number("t_end", sim_end);
        if (!orbits_args.history.empty()) {
            std::string list;
            for (Eigen::Index k = 0; k < sim_history.size(); ++k) list += (k ? "," : "") + format_exact(sim_history(k));
            inputs.json("history", "[" + list + "]");
        }
    }
    if (from_file) {
        guess_samples = read_guess(orbits_args.guess, built.system->dimension());
        inputs.string("guess", orbits_args.guess);
    }

    EquilibriumBranchOptions eo;
    eo.parameter = par;
    eo.from = o.from;
    eo.to = o.to;
    eo.roots.count = 2;
    eo.progress = branch_progress_printer("orbits", "equilibria", par, true, true);
    eo.before_roots = branch_roots_guard("orbits", "the equilibrium branch");
    // the equilibria start the orbits at a Hopf point; from a simulation or a file they are only
    // drawn (--svg), so computed only then (a long ring's branch takes minutes)
    const bool from_hopf = !from_simulation && !from_file;
    EquilibriumBranch eq;
    if (from_hopf || !svg_file.empty()) eq = equilibrium_branch(*built.system, built.guess, eo);
    eo.progress = nullptr;  // ends an open progress line
    if (from_hopf && eq.hopf.empty())
        throw BadInput("no Hopf point on the equilibrium branch in " + par + " from " + orbits_args.problem.from + " to " + orbits_args.problem.to +
                       " (ended: " + to_string(eq.stop) + "): expected at least one to start the periodic orbits from");
    if (from_hopf && hopf_index >= static_cast<int>(eq.hopf.size()))
        throw BadInput("--hopf = '" + orbits_args.hopf + "': expected an index from 0 to " + std::to_string(eq.hopf.size() - 1) + " (the branch has " +
                       std::to_string(eq.hopf.size()) + " Hopf point" + (eq.hopf.size() == 1 ? "" : "s") + ")");
    const HopfPoint* hp = from_hopf ? &eq.hopf[static_cast<std::size_t>(hopf_index)] : nullptr;
    OrbitBranch b;
    std::string start_json;  // result.start of a simulation or a file
    std::string start_line;
    if (hp) {
        o.progress = branch_progress_printer("orbits", "orbits", par, false);
        b = orbit_branch_from_hopf(*built.system, *hp, o);
        o.progress = nullptr;
        if (hp->status != Status::Converged && b.status == Status::Converged) {
            b.status = hp->status;
            b.message = "the Hopf point was not located (" + to_string(hp->status) + "); the orbits start from its estimate";
        }
    } else {
        const PeriodicMesh mesh(o.degree, o.intervals);
        OrbitGuess guess;
        bool have = true;
        if (from_simulation) {
            const SimulatedOrbitGuess sg = orbit_guess_from_simulation(*built.system, par, mesh, sim_history, sim_end, sim_step);
            start_json = simulation_start_json(sg, sim_end, sim_step);
            std::ostringstream sl;
            sl << "start      simulation at " << par << " = " << rounded(o.from, 10) << " to t = " << rounded(sim_end, 6) << " (step " << rounded(sim_step, 3) << "): " << sg.message << "\n";
            start_line = sl.str();
            o.progress = branch_progress_printer("orbits", "orbits", par, false);
            b = orbit_branch_from_simulation(*built.system, sg, o);
            o.progress = nullptr;
            have = false;  // done
        } else {
            try {
                guess = orbit_guess_from_samples(mesh, guess_samples.times, guess_samples.states, guess_samples.times.back() - guess_samples.times.front(), o.from);
            } catch (const std::invalid_argument& e) {
                throw BadInput("--guess = " + orbits_args.guess + ": " + e.what());
            }
            JsonObject start;
            start.string("kind", "file").string("file", orbits_args.guess).number("period", guess.period);
            start_json = start.str();
            start_line = "start      " + orbits_args.guess + " at " + par + " = " + rounded(o.from, 10) + ", period " + rounded(guess.period, 8) + "\n";
        }
        if (have) {
            o.progress = branch_progress_printer("orbits", "orbits", par, false);
            b = orbit_branch_from_guess(*built.system, guess, o);
            o.progress = nullptr;
        }
    }

    // the branch of twice the period from period doubling K (--period-doubling)
    OrbitBranch doubled;
    if (doubling) {
        if (b.period_doublings.empty())
            throw BadInput("--period-doubling = '" + orbits_args.period_doubling + "': the branch has no period doubling in " + par + " from " +
                           orbits_args.problem.from + " to " + orbits_args.problem.to + " (expected at least one to switch at)");
        if (doubling_index >= static_cast<int>(b.period_doublings.size()))
            throw BadInput("--period-doubling = '" + orbits_args.period_doubling + "': expected an index from 0 to " +
                           std::to_string(b.period_doublings.size() - 1) + " (the branch has " + counted(static_cast<long long>(b.period_doublings.size()), "period doubling") + ")");
        const OrbitCrossing& pd = b.period_doublings[static_cast<std::size_t>(doubling_index)];
        inputs.integer("period_doubling", doubling_index);
        if (!pd.located) {
            doubled.status = Status::NumericalIssue;
            doubled.stop = "first_orbit_failed";
            doubled.message = "period doubling " + std::to_string(doubling_index) + " was not located: no branch switched onto";
        } else {
            o.progress = branch_progress_printer("orbits", "orbits of twice the period", par, false);
            doubled = orbit_branch_from_period_doubling(*built.system, pd, o);
            o.progress = nullptr;
        }
        if (doubled.status != Status::Converged && b.status == Status::Converged) {
            b.status = doubled.status;
            b.message = "the branch of twice the period: " + doubled.message;
        }
    }

    // the curves of folds and of period doublings in (par, par2) through the branch's special points
    OrbitBranchCurves bc;
    if (two) {
        inputs.string("par2", fo.parameter2).number("from2", fo.from2).number("to2", fo.to2);
        fo.orbit = o;
        fo.orbit.progress = branch_progress_printer("orbits", "curve points", par, false);
        bc = orbit_curves_of_branch(*built.system, b, fo);
        fo.orbit.progress = nullptr;
        if (bc.status != Status::Converged && b.status == Status::Converged) {
            b.status = bc.status;
            b.message = bc.message;
        }
    }
    const std::vector<OrbitFoldCurve>& curves = bc.folds;
    const std::vector<OrbitFoldCurve>& pd_curves = bc.period_doublings;
    const std::vector<int>& curve_fold = bc.fold_index;
    const std::vector<int>& curve_pd = bc.period_doubling_index;
    const std::vector<OrbitFoldCurve>& torus_curves = bc.tori;
    const std::vector<int>& curve_torus = bc.torus_index;

    JsonEnvelope e;
    e.command = "orbits";
    e.inputs = inputs.str();
    e.status = to_string(b.status);
    e.message = b.message;
    std::string result = orbit_branch_json(b, variables);
    if (hp) {
        JsonObject hj;
        hj.integer("index", hopf_index).number("par", hp->par).number("omega", hp->omega).string("status", to_string(hp->status));
        result = "{\"hopf\":" + hj.str() + "," + result.substr(1);
    } else {
        result = "{\"start\":" + start_json + "," + result.substr(1);
    }
    if (two)
        result = result.substr(0, result.size() - 1) + ",\"fold_curves\":" + orbit_fold_curves_json(curves, variables) +
                 ",\"period_doubling_curves\":" + orbit_fold_curves_json(pd_curves, variables) +
                 ",\"torus_curves\":" + orbit_fold_curves_json(torus_curves, variables) + "}";
    if (doubling) {
        const OrbitCrossing& pd = b.period_doublings[static_cast<std::size_t>(doubling_index)];
        JsonObject from;
        from.integer("index", doubling_index).number("par", pd.par).number("period", pd.period);
        const std::string branch = orbit_branch_json(doubled, variables);
        result = result.substr(0, result.size() - 1) + ",\"period_doubled\":{\"from\":" + from.str() + "," + branch.substr(1) + "}";
    }
    e.result = result;
    const std::string csv = orbit_branch_csv(b, variables, built.units);
    std::vector<std::pair<std::string, std::string>> files;
    if (!prefix.empty()) {
        files.push_back({prefix + ".csv", csv});
        files.push_back({prefix + ".json", envelope_json(e)});
        if (two) files.push_back({prefix + "-folds.csv", orbit_fold_curves_csv(curves, variables, built.units)});
        if (two) files.push_back({prefix + "-doublings.csv", orbit_fold_curves_csv(pd_curves, variables, built.units)});
        if (two) files.push_back({prefix + "-tori.csv", orbit_fold_curves_csv(torus_curves, variables, built.units)});
        if (doubling) files.push_back({prefix + "-doubled.csv", orbit_branch_csv(doubled, variables, built.units)});
    }
    if (!svg_file.empty() && two) {
        // with --par2 the figure is the plane (par, par2) with the curves
        std::ostringstream title;
        title << "Bifurcation curves of periodic orbits in (" << par << ", " << fo.parameter2 << ")" << orbits_args.problem.ring_title();
        files.push_back({svg_file, two_parameter_svg(nullptr, nullptr, par, fo.parameter2, std::min(o.from, o.to), std::max(o.from, o.to),
                                                     std::min(fo.from2, fo.to2), std::max(fo.from2, fo.to2), built.unit(par), built.unit(fo.parameter2),
                                                     title.str(), &bc)});
    } else if (!svg_file.empty()) {
        const std::string punit = built.unit(par);
        const std::string vunit = built.unit(variables[static_cast<std::size_t>(variable)]);
        std::ostringstream title;
        if (hp) title << "Periodic orbits from the Hopf point at " << par << " = " << rounded(hp->par, 6);
        else title << "Periodic orbits from " << (from_simulation ? "a simulation" : "a given orbit") << " at " << par << " = " << rounded(o.from, 6);
        title << orbits_args.problem.ring_title();
        files.push_back({svg_file, bifurcation_svg(&eq, b, variable, variables[static_cast<std::size_t>(variable)], vunit, punit, title.str(),
                                                   doubling ? &doubled : nullptr)});
    }
    if (!files.empty()) write_files_atomic(files);
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        if (hp)
            out << "hopf       " << par << " = " << rounded(hp->par, 10) << ", omega = " << rounded(hp->omega, 10) << ", period 2 pi / omega = "
                << rounded(6.283185307179586 / hp->omega, 8) << " (Hopf point " << hopf_index << " of " << eq.hopf.size() << ")\n";
        else
            out << start_line;
        out << "branch     " << counted(static_cast<long long>(b.points.size()), "orbit") << ", degree " << b.degree << " on " << b.intervals << " intervals (ended: " << b.stop << ")\n";
        const std::string& v = variables[static_cast<std::size_t>(variable)];
        // a built-in ring: orbits in which a gap (or headway) falls below 0 (a collision) or a
        // speed below 0 (a car reversing) are solutions of the equations but not of traffic
        std::vector<int> gaps, speeds;
        if (!orbits_args.problem.model.empty())
            for (std::size_t k = 0; k < variables.size(); ++k) {
                const std::string unit = built.unit(variables[k]);
                if (unit == "m") gaps.push_back(static_cast<int>(k));
                if (unit == "m/s") speeds.push_back(static_cast<int>(k));
            }
        auto physical = [&](const PeriodicOrbit& p) {
            bool collision = false, reversing = false;
            for (int k : gaps) collision = collision || p.min[k] < 0.0;
            for (int k : speeds) reversing = reversing || p.min[k] < 0.0;
            return collision && reversing ? std::string(" (collision, reversing)") : collision ? std::string(" (collision)") : reversing ? std::string(" (reversing)") : std::string();
        };
        bool unphysical = false;
        auto table = [&](const OrbitBranch& br) {
            out << "  " << pad(par, 14) << pad("period", 14) << pad("amp " + v, 14) << pad("max|mu|", 12) << pad("|mu_1 - 1|", 12) << "stable\n";
            for (const PeriodicOrbit& p : br.points) {
                const std::string note = physical(p);
                unphysical = unphysical || !note.empty();
                out << "  " << pad(rounded(p.par, 8), 14) << pad(rounded(p.period, 8), 14) << pad(rounded(p.max[variable] - p.min[variable], 6), 14)
                    << pad(p.multipliers.empty() ? "-" : rounded(p.max_nontrivial, 4), 12) << pad(p.multipliers.empty() ? "-" : rounded(p.trivial_distance, 2), 12)
                    << (!p.undecided.empty() ? "undecided" : p.multipliers.empty() ? "not computed" : p.stable ? "yes" : "no") << note << "\n";
            }
            for (const OrbitFold& f : br.folds)
                out << "fold       " << par << " = " << rounded(f.par, 10) << ", period " << rounded(f.period, 8) << (f.located ? "" : " (not located)") << "\n";
            out << crossing_lines(br);
        };
        table(b);
        if (doubling) {
            const OrbitCrossing& pd = b.period_doublings[static_cast<std::size_t>(doubling_index)];
            out << "doubled    from the period doubling at " << par << " = " << rounded(pd.par, 10) << " (period " << rounded(pd.period, 8) << "): "
                << counted(static_cast<long long>(doubled.points.size()), "orbit") << " of twice the period, degree " << doubled.degree << " on "
                << doubled.intervals << " intervals (ended: " << doubled.stop << ")\n";
            table(doubled);
        }
        for (std::size_t k = 0; k < curves.size(); ++k) {
            const OrbitFoldCurve& c = curves[k];
            const OrbitFold& f = b.folds[static_cast<std::size_t>(curve_fold[k])];
            out << "fold curve " << k << " from the fold at " << par << " = " << rounded(f.par, 10) << ": " << counted(static_cast<long long>(c.points.size()), "point")
                << " in (" << par << ", " << c.parameter2 << "), ended: " << c.stop_backward << " and " << c.stop_forward << "\n";
            out << "  " << pad(par, 14) << pad(c.parameter2, 14) << pad("period", 14) << pad("amp " + v, 12) << pad("|g|", 10) << "|mu_2 - 1|\n";
            for (const OrbitFoldCurvePoint& q : c.points)
                out << "  " << pad(rounded(q.par, 8), 14) << pad(rounded(q.par2, 8), 14) << pad(rounded(q.orbit.period, 8), 14)
                    << pad(rounded(q.orbit.max[variable] - q.orbit.min[variable], 5), 12) << pad(rounded(q.test, 2), 10)
                    << (std::isfinite(q.second_distance) ? rounded(q.second_distance, 2) : std::string("-")) << "\n";
            if (!c.points.empty())  // (a curve whose first point failed has none)
            for (const auto& [end, stop] : {std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.front(), c.stop_backward},
                                            std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.back(), c.stop_forward}})
                if (stop == "hopf")
                    out << "  ends at a generalised Hopf point (the orbits shrink onto the Hopf curve) near " << par << " = " << rounded(end->par, 6) << ", "
                        << c.parameter2 << " = " << rounded(end->par2, 6) << " (amplitude " << rounded(end->orbit.max[variable] - end->orbit.min[variable], 3) << ")\n";
            out << "  accuracy max |g| = " << rounded(c.max_test, 2) << ", max residual = " << rounded(c.max_residual, 2);
            if (c.max_trivial_distance > 0.0) out << ", max |mu_trivial - 1| = " << rounded(c.max_trivial_distance, 2);
            out << "\n";
        }
        for (std::size_t k = 0; k < pd_curves.size(); ++k) {
            const OrbitFoldCurve& c = pd_curves[k];
            const OrbitCrossing& d = b.period_doublings[static_cast<std::size_t>(curve_pd[k])];
            out << "doubling curve " << k << " from the period doubling at " << par << " = " << rounded(d.par, 10) << ": "
                << counted(static_cast<long long>(c.points.size()), "point") << " in (" << par << ", " << c.parameter2 << "), ended: " << c.stop_backward
                << " and " << c.stop_forward << "\n";
            out << "  " << pad(par, 14) << pad(c.parameter2, 14) << pad("period", 14) << pad("amp " + v, 12) << pad("|g|", 10) << "min|mu + 1|\n";
            for (const OrbitFoldCurvePoint& q : c.points)
                out << "  " << pad(rounded(q.par, 8), 14) << pad(rounded(q.par2, 8), 14) << pad(rounded(q.orbit.period, 8), 14)
                    << pad(rounded(q.orbit.max[variable] - q.orbit.min[variable], 5), 12) << pad(rounded(q.test, 2), 10)
                    << (std::isfinite(q.second_distance) ? rounded(q.second_distance, 2) : std::string("-")) << "\n";
            out << "  accuracy max |g| = " << rounded(c.max_test, 2) << ", max residual = " << rounded(c.max_residual, 2);
            if (c.max_trivial_distance > 0.0) out << ", max |mu_trivial - 1| = " << rounded(c.max_trivial_distance, 2);
            out << "\n";
        }
        for (std::size_t k = 0; k < torus_curves.size(); ++k) {
            const OrbitFoldCurve& c = torus_curves[k];
            const OrbitCrossing& d = b.tori[static_cast<std::size_t>(curve_torus[k])];
            out << "torus curve " << k << " from the torus bifurcation at " << par << " = " << rounded(d.par, 10) << ": "
                << counted(static_cast<long long>(c.points.size()), "point") << " in (" << par << ", " << c.parameter2 << "), ended: " << c.stop_backward
                << " and " << c.stop_forward << "\n";
            out << "  " << pad(par, 14) << pad(c.parameter2, 14) << pad("period", 14) << pad("amp " + v, 12) << pad("phi [rad]", 12) << pad("|g|", 10)
                << "min|mu - e^(i phi)|\n";
            for (const OrbitFoldCurvePoint& q : c.points)
                out << "  " << pad(rounded(q.par, 8), 14) << pad(rounded(q.par2, 8), 14) << pad(rounded(q.orbit.period, 8), 14)
                    << pad(rounded(q.orbit.max[variable] - q.orbit.min[variable], 5), 12) << pad(rounded(q.rotation, 6), 12) << pad(rounded(q.test, 2), 10)
                    << (std::isfinite(q.second_distance) ? rounded(q.second_distance, 2) : std::string("-")) << "\n";
            if (!c.points.empty())
            for (const auto& [end, stop] : {std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.front(), c.stop_backward},
                                            std::pair<const OrbitFoldCurvePoint*, std::string>{&c.points.back(), c.stop_forward}})
                if (stop == "hopf")
                    out << "  ends at " << (orbit_curve_end_point(*end) == "ZH" ? "a zero-Hopf point (phi -> 0: the orbits shrink onto an equilibrium with a pair and a real root on the axis)"
                                                                                 : "a double Hopf point (the orbits shrink onto an equilibrium with two pairs on the axis)")
                        << " near " << par << " = " << rounded(end->par, 6) << ", " << c.parameter2 << " = " << rounded(end->par2, 6) << " (amplitude "
                        << rounded(end->orbit.max[variable] - end->orbit.min[variable], 3) << ")\n";
            out << "  accuracy max |g| = " << rounded(c.max_test, 2) << ", max residual = " << rounded(c.max_residual, 2);
            if (c.max_trivial_distance > 0.0) out << ", max |mu_trivial - 1| = " << rounded(c.max_trivial_distance, 2);
            out << "\n";
        }
        if (unphysical)
            out << "note       orbits marked (collision) have a gap below 0 somewhere, (reversing) a speed below 0: solutions of the equations, not of "
                   "traffic (JSON: min of every variable)\n";
        if (!b.points.empty()) {
            const double trivial = std::max(b.max_trivial_distance, doubled.max_trivial_distance);
            out << "accuracy   ";
            if (std::any_of(b.points.begin(), b.points.end(), [](const PeriodicOrbit& p) { return !p.multipliers.empty(); }))
                out << "max |mu_trivial - 1| = " << rounded(trivial, 2) << ", ";
            out << "max residual = " << rounded(std::max(b.max_residual, doubled.max_residual), 2) << (doubling ? " (both branches)" : "") << "\n";
        }
        if (b.status != Status::Converged) out << "verdict    UNDECIDED (" << to_string(b.status) << "): " << b.message << "\n";
        if (!files.empty()) {
            out << "wrote     ";
            for (const auto& f : files) out << " " << f.first;
            out << "\n";
        }
        std::cout << out.str();
    });
    return report_undecided(b.status, "orbits", b.message);
}

}  // namespace ddemap::cli
