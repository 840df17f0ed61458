// calibrate: fit OVRV to measured car-following traces (analysis/calibrate: calibrate_cars):
// one fit per file, one joint fit of all files (--joint), or one joint fit per car of a run
// list with test runs (--runs); --report DIR writes the Tables 1/2 report and fit figures.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <sstream>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/io/calibration_report.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/figures.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap::cli {

namespace {
struct CalibrateArgs {
    std::vector<std::string> files;
    std::string train, model = "ovrv", bounds, gap_weight = "0.02", runs, report, car = "joint", data_dir, follower, lead_noise = "auto", lead_noise_correction = "on";
    bool joint = false;
    FormatArg format;
    OutArg out;
} calibrate_args;

std::string base_name(const std::string& path) {
    std::string b = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
    if (b.size() > 4 && b.substr(b.size() - 4) == ".csv") b.resize(b.size() - 4);
    return b;
}

CalibrationOptions options() {
    if (calibrate_args.model != "ovrv") throw BadInput("--model = '" + calibrate_args.model + "': calibration supports ovrv");
    CalibrationOptions o;
    o.gap_weight = parse_number("--gap-weight", calibrate_args.gap_weight);
    o.lead_noise_correction = calibrate_args.lead_noise_correction == "on";
    if (calibrate_args.lead_noise != "auto") {
        o.lead_noise = parse_number("--lead-noise", calibrate_args.lead_noise);
        if (!(o.lead_noise >= 0.0 && o.lead_noise <= 10.0))
            throw BadInput("--lead-noise = " + calibrate_args.lead_noise + ": expected auto, or 0 to 10 m/s (0: the lead speed is exact)");
    }
    if (!calibrate_args.train.empty()) {
        const auto colon = calibrate_args.train.find(':');
        if (colon == std::string::npos) throw BadInput("--train = '" + calibrate_args.train + "': expected T0:T1 in seconds");
        o.train_start = parse_number("--train", calibrate_args.train.substr(0, colon));
        o.train_end = parse_number("--train", calibrate_args.train.substr(colon + 1));
        if (!(o.train_start >= 0 && o.train_end > o.train_start)) throw BadInput("--train = '" + calibrate_args.train + "': expected 0 <= T0 < T1");
    }
    if (!calibrate_args.bounds.empty()) {
        std::stringstream ss(calibrate_args.bounds);
        std::string item;
        const char* names[5] = {"k1", "k2", "th", "tau", "eta"};
        while (std::getline(ss, item, ',')) {
            const auto eq = item.find('='), colon = item.find(':');
            if (eq == std::string::npos || colon == std::string::npos || colon < eq)
                throw BadInput("--bounds item '" + item + "': expected NAME=LO:HI, e.g. eta=0:15");
            const std::string name = item.substr(0, eq);
            const auto it = std::find_if(std::begin(names), std::end(names), [&](const char* n) { return name == n; });
            if (it == std::end(names)) throw BadInput("--bounds item '" + item + "': expected one of k1, k2, th, tau, eta");
            o.set_bounds(name, parse_number("--bounds " + name, item.substr(eq + 1, colon - eq - 1)),
                         parse_number("--bounds " + name, item.substr(colon + 1)));
        }
    }
    o.validate();
    return o;
}
}  // namespace

void add_calibrate_flags(CLI::App& app) {
    app.add_option("DATA.csv", calibrate_args.files,
                   "traces with columns time_s, lead_speed_mps, follower_speed_mps, gap_m (one fit per file), or the CSV that simulate "
                   "writes (one fit per follower; FILE.csv:K fits follower K only)");
    app.add_option("--follower", calibrate_args.follower, "in the CSVs that simulate writes, fit follower K only (1 = the first behind the lead)")->type_name("K");
    app.add_flag("--joint", calibrate_args.joint, "fit one parameter set to all DATA files (runs of the same car)");
    app.add_option("--car", calibrate_args.car, "the car's name for --joint")->capture_default_str();
    app.add_option("--runs", calibrate_args.runs,
                   "RUNS.csv with columns car,file,role[,type]: each car fitted jointly on its role=train files, "
                   "tested on its role=test files (errors per type; files relative to the current folder)");
    app.add_option("--data-dir", calibrate_args.data_dir, "folder the relative file names of RUNS.csv are read from (default: the current folder)");
    app.add_option("--report", calibrate_args.report, "folder: table.csv, table.json, table.md (parameters, train and test errors) and fit_FILE.svg per run");
    app.add_option("--train", calibrate_args.train, "training window T0:T1 [s] (default: the whole file; the rest is the test part)");
    app.add_option("--model", calibrate_args.model, "the model to fit (ovrv)")->capture_default_str();
    app.add_option("--bounds", calibrate_args.bounds, "bounds NAME=LO:HI,... (default: the paper's k1=0:1,k2=0:1,th=0:3,tau=0:1,eta=5:15)");
    app.add_option("--gap-weight", calibrate_args.gap_weight, "objective = MSE(speed) + W * MSE(gap) [W in 1/s^2, 0 to 1e6]")->capture_default_str();
    app.add_option("--lead-noise", calibrate_args.lead_noise,
                   "white noise on the measured lead speed that the fit corrects its bias for and the intervals allow for [m/s]: auto "
                   "estimates it from each trace's lead speed (its second differences), 0 takes the lead speed as exact")
        ->type_name("M/S")
        ->capture_default_str();
    app.add_option("--lead-noise-correction", calibrate_args.lead_noise_correction,
                   "on: minimise the objective less the lead noise's expected share of it, P(theta) (corrected least squares: the "
                   "noise would otherwise pull quick cars' gains and delay down); off: plain least squares (the intervals still "
                   "allow for the noise)")
        ->check(CLI::IsMember({"on", "off"}))
        ->type_name("on|off")
        ->capture_default_str();
    calibrate_args.out.add_to(app, "PREFIX.csv (a vehicle table for classify), PREFIX.json, PREFIX.svg", false);
    calibrate_args.format.add_to(app);
    run_flags().add_to(app, true);
}

namespace {

/// the cars of --runs RUNS.csv (car,file,role[,type]), in order of first appearance
std::vector<CarRuns> read_runs(const std::string& path) {
    auto read = [&](const std::string& name) {
        const std::string file = calibrate_args.data_dir.empty() || name.front() == '/' ? name : (std::filesystem::path(calibrate_args.data_dir) / name).string();
        return read_trace_csv(read_input_file("--runs " + path + ": file", file), file);
    };
    return cars_from_run_list(read_run_list_csv(read_input_file("--runs", path), path), read, "--runs " + path);
}

/// The traces of one DATA.csv argument with their car names: a trace file (named after the file),
/// every follower of simulate's CSV (FILE-K), or one follower (FILE.csv:K or --follower K).
bool append_traces(const std::string& arg, int follower, std::vector<std::pair<std::string, Trace>>& out) {
    namespace fs = std::filesystem;
    std::string file = arg;
    std::error_code ec;
    const auto colon = arg.rfind(':');
    if (!fs::exists(arg, ec) && colon != std::string::npos && colon + 1 < arg.size() &&
        arg.find_first_not_of("0123456789", colon + 1) == std::string::npos) {
        file = arg.substr(0, colon);
        const double k = parse_number("DATA.csv " + arg, arg.substr(colon + 1));
        if (!(k >= 1 && k <= 1e6)) throw BadInput("DATA.csv = '" + arg + "': follower " + arg.substr(colon + 1) + ": expected 1, 2, ...");
        if (follower != 0 && follower != static_cast<int>(k))
            throw BadInput("DATA.csv = '" + arg + "': follower " + arg.substr(colon + 1) + " and --follower " + std::to_string(follower) + " disagree");
        follower = static_cast<int>(k);
    }
    const std::string text = read_input_file("DATA.csv", file);
    if (file != arg && !is_platoon_csv(text))
        throw BadInput("DATA.csv = '" + arg + "': ':K' picks a follower of a platoon CSV (simulate's), and " + file + " is one trace");
    const bool platoon = is_platoon_csv(text);
    for (Trace& t : read_traces_csv(text, file, platoon ? follower : 0)) {
        const std::string name = platoon ? base_name(file) + "-" + t.source.substr(t.source.rfind(':') + 1) : base_name(file);
        out.emplace_back(name, std::move(t));
    }
    return platoon;
}

/// the --report folder, created as needed and writable (bad input otherwise, before any work)
std::string prepare_report_dir(const std::string& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) {
        fs::create_directories(dir, ec);
        if (ec || !fs::is_directory(dir)) throw BadInput("--report = '" + dir + "': the folder does not exist and cannot be created");
    }
    if (access(dir.c_str(), W_OK) != 0) throw BadInput("--report = '" + dir + "': the folder is not writable");
    return dir.back() == '/' ? dir : dir + "/";
}

}  // namespace

int run_calibrate() {
    const Format format = calibrate_args.format.parse();
    const CalibrationOptions o = options();
    const int modes = (calibrate_args.joint ? 1 : 0) + (!calibrate_args.runs.empty() ? 1 : 0);
    if (!calibrate_args.runs.empty() && !calibrate_args.files.empty()) throw BadInput("--runs " + calibrate_args.runs + ": give the files in RUNS.csv, not also as DATA.csv");
    if (calibrate_args.runs.empty() && calibrate_args.files.empty()) throw BadInput("DATA.csv: expected at least one trace (or --runs RUNS.csv)");
    if (!calibrate_args.data_dir.empty() && calibrate_args.runs.empty()) throw BadInput("--data-dir " + calibrate_args.data_dir + ": only with --runs RUNS.csv");
    if (modes > 1) throw BadInput("--joint: not with --runs (RUNS.csv groups the runs into cars)");
    const std::string prefix = calibrate_args.out.given() ? calibrate_args.out.prepare("calibrate") : std::string();
    const std::string report_dir = calibrate_args.report.empty() ? std::string() : prepare_report_dir(calibrate_args.report);
    std::vector<CarRuns> cars;
    if (!calibrate_args.runs.empty()) {
        cars = read_runs(calibrate_args.runs);
    } else {
        int follower = 0;
        if (!calibrate_args.follower.empty()) {
            const double k = parse_number("--follower", calibrate_args.follower);
            if (!(k >= 1 && k <= 1e6 && k == std::floor(k))) throw BadInput("--follower = '" + calibrate_args.follower + "': expected a follower number 1, 2, ...");
            follower = static_cast<int>(k);
        }
        std::vector<std::pair<std::string, Trace>> traces;  // (name, trace)
        bool platoon = false;
        for (const auto& f : calibrate_args.files) platoon = append_traces(f, follower, traces) || platoon;
        if (follower != 0 && !platoon) throw BadInput("--follower " + calibrate_args.follower + ": none of the DATA files is a platoon CSV (the CSV that simulate writes)");
        if (calibrate_args.joint) {
            cars.push_back(CarRuns{calibrate_args.car, {}, {}, {}});
            for (auto& [name, t] : traces) cars[0].train.push_back(std::move(t));
        } else {
            for (auto& [name, t] : traces) cars.push_back(CarRuns{name, {std::move(t)}, {}, {}});
        }
    }
    // sized before the work: about 0.008 s of CPU per second of trace and fit (the design's 64
    // simulations, the Levenberg-Marquardt iterations with sensitivities and the 200 simulations
    // of the lead noise; measured on simulated 236 s traces at 10 Hz, about 1 s a fit before the
    // lead noise, 0.3 s for it on 150 s traces; the lead-noise correction's second simulation
    // per evaluation adds about half: 0.30 s -> 0.45 s on a 225 s OpenACC trace)
    {
        double seconds = 0.0, duration = 0.0;
        for (const auto& c : cars)
            for (const auto& list : {&c.train, &c.test})
                for (const Trace& t : *list) duration += t.t.back() - t.t.front();
        seconds = 0.008 * duration;
        check_size("calibrate", counted(static_cast<long long>(cars.size()), "fit") + " over " + rounded(duration / 3600.0, 3) + " h of traces", "time",
                   seconds / std::max(1, std::min<int>(thread_count(), static_cast<int>(cars.size()))));
    }
    // one fit: its stages as they run (the design's simulations, then the Levenberg-Marquardt
    // iterations of its starts, from several threads)
    CalibrationOptions fit_options = o;
    if (cars.size() == 1) {
        const Progress design = progress_printer("calibrate", "design points");
        const Progress iterations = progress_printer("calibrate", "Levenberg-Marquardt iterations (at most)");
        if (design) {
            auto lock = std::make_shared<std::mutex>();
            const long points = o.design_points;
            fit_options.progress = [design, iterations, lock, points](long done, long total) {
                std::lock_guard<std::mutex> guard(*lock);
                if (total == points) design(done, total);
                else iterations(done + 1, total);
            };
        }
    }
    // one progress line per finished fit: ddemap: calibrate: fits 3/12 done, NAME in 0.41 s (4.2 s, about 12 s left)
    CarFinished finished;
    if (cars.size() > 1)
        if (const LabelledProgress line = labelled_progress_printer("calibrate", "fits"))
            finished = [line](const CarCalibration& c, long done, long total) { line(done, total, c.car + " in " + rounded(c.fit.seconds, 2) + " s"); };
    const std::vector<CarCalibration> results = calibrate_cars(cars, fit_options, ExecutionPolicy{}, finished);
    std::vector<CalibrationResult> fits;
    std::vector<std::string> names;
    std::vector<Trace> traces;  // one per fit for the overview figure (its first training run)
    for (std::size_t i = 0; i < results.size(); ++i) {
        fits.push_back(results[i].fit);
        names.push_back(results[i].car);
        traces.push_back(cars[i].train.front());
        if (fits.back().sim_speed.empty() && !fits.back().runs.empty()) {
            fits.back().sim_speed = fits.back().runs.front().sim_speed;
            fits.back().sim_gap = fits.back().runs.front().sim_gap;
        }
    }
    JsonEnvelope e;
    e.command = "calibrate";
    std::vector<std::string> files;
    for (const auto& c : cars)
        for (const auto& t : c.train) files.push_back(json_string(t.source));
    JsonObject in;
    in.json("traces", json_array(files)).string("model", calibrate_args.model).number("gap_weight", o.gap_weight);
    if (o.lead_noise >= 0.0) in.number("lead_noise", o.lead_noise);
    if (!o.lead_noise_correction) in.boolean("lead_noise_correction", false);
    if (!calibrate_args.runs.empty()) in.string("runs", calibrate_args.runs);
    if (calibrate_args.joint) in.string("joint", calibrate_args.car);
    if (o.train_start >= 0) in.json("train", json_array({json_number(o.train_start), json_number(o.train_end)}));
    e.inputs = in.str();
    e.result = calibration_json(names, fits, o, &results);
    Status status = Status::Converged;
    for (std::size_t i = 0; i < fits.size(); ++i) {
        if (fits[i].status_code != Status::Converged) {
            if (status == Status::Converged) status = fits[i].status_code;  // the first, as the message
        }
        for (const auto& w : fits[i].warnings) std::cerr << "ddemap: calibrate: " << names[i] << ": warning: " << w << "\n";
    }
    e.status = to_string(status);
    e.message = calibration_message(names, fits);
    const std::string csv = calibration_csv(names, fits, o);
    std::vector<std::pair<std::string, std::string>> outputs;
    if (!prefix.empty())
        outputs = {{prefix + ".csv", csv}, {prefix + ".json", envelope_json(e)}, {prefix + ".svg", calibration_svg(names, traces, fits)}};
    if (!report_dir.empty())
        for (auto& [name, text] : calibration_report_files(results, cars, o, calibrate_args.runs.empty() && !calibrate_args.joint))
            outputs.push_back({report_dir + name, std::move(text)});
    if (!outputs.empty()) write_files_atomic(outputs);
    print_output(format, e, csv, [&] {
        std::ostringstream out;
        // the name column as wide as the longest name (names are never cut: two runs of one
        // campaign differ only at their ends)
        std::size_t width = 4;
        for (const auto& n : names) width = std::max(width, n.size());
        char head[300];
        std::snprintf(head, sizeof head, " %8s %7s %6s %6s %6s %7s %8s %8s  %s\n", "k1", "k2", "th", "tau", "eta", "rmse_v", "rmse_gap", "naive_v", "status");
        char units[300];
        std::snprintf(units, sizeof units, " %8s %7s %6s %6s %6s %7s %8s %8s\n", "[1/s^2]", "[1/s]", "[s]", "[s]", "[m]", "[m/s]", "[m]", "[m/s]");
        out << std::string("file") + std::string(width - 4, ' ') << head << std::string(width, ' ') << units;
        for (std::size_t i = 0; i < fits.size(); ++i) {
            const auto& r = fits[i];
            const auto& p = r.parameters;
            char line[300];
            std::snprintf(line, sizeof line, " %8.4f %7.4f %6.3f %6.3f %6.2f %7.3f %8.3f %8.3f  %s\n", p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"),
                          p.at("eta"), r.all.rmse_speed, r.all.rmse_gap, r.naive.rmse_speed, r.status.c_str());
            out << names[i] << std::string(width - names[i].size(), ' ') << line;
        }
        for (std::size_t i = 0; i < fits.size(); ++i) {
            double noise = 0.0;
            for (double x : fits[i].lead_noise) noise = std::max(noise, x);
            out << names[i] << ": lead-speed noise " << (fits[i].lead_noise_corrected ? "corrected for in the fit and " : "") << "allowed for in the intervals "
                << rounded(noise, 3) << " m/s"
                << (calibrate_args.lead_noise == "auto" ? " (estimated from the lead speed)" : "") << "\n";
            out << names[i] << ": 95 % intervals";
            for (const auto& est : fits[i].estimates)
                out << "  " << est.name << " "
                    << (std::isfinite(est.lower95) && std::isfinite(est.upper95) ? "[" + rounded(est.lower95, 3) + ", " + rounded(est.upper95, 3) + "]"
                                                                                  : std::string("undetermined"));
            out << "\n";
        }
        std::cout << out.str();
    });
    return exit_code(status);
}

}  // namespace ddemap::cli
