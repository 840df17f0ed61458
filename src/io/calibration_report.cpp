#include "ddemap/io/calibration_report.hpp"

#include "ddemap/core/units.hpp"
#include "ddemap/traffic/model.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/internal/json_values.hpp"

#include "core/internal/text.hpp"
#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"

namespace ddemap {

namespace {

using json = nlohmann::ordered_json;

const auto num = detail::json_value;

std::string round3(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3g", v == 0.0 ? 0.0 : v);
    return buf;
}

/// accumulates an RMSE pooled over runs
struct Pool {
    double sv = 0.0, sg = 0.0, nv = 0.0;
    int n = 0;
    void add(const FitErrors& e, double naive_speed) {
        sv += e.rmse_speed * e.rmse_speed * e.samples;
        sg += e.rmse_gap * e.rmse_gap * e.samples;
        nv += naive_speed * naive_speed * e.samples;
        n += e.samples;
    }
    FitErrors errors() const { return n > 0 ? FitErrors{std::sqrt(sv / n), std::sqrt(sg / n), n} : FitErrors{}; }
    FitErrors naive() const { return n > 0 ? FitErrors{std::sqrt(nv / n), 0.0, n} : FitErrors{}; }
};

std::string join(const std::vector<std::string>& v, const std::string& sep) {
    std::string out;
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
    return out;
}

std::string base_name(const std::string& path) {
    std::string b = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
    if (b.size() > 4 && b.substr(b.size() - 4) == ".csv") b.resize(b.size() - 4);
    return b;
}

}  // namespace

std::vector<RunListEntry> read_run_list_csv(const std::string& text, const std::string& source) {
    detail::CsvReader csv(text, source, "car,file,role[,type]");
    const int ci = csv.column("car"), fi = csv.column("file"), ri = csv.column("role"), ti = csv.column("type", false);
    std::vector<RunListEntry> out;
    while (csv.next()) {
        const auto& f = csv.fields();
        auto field = [&](int c) { return c >= 0 && static_cast<std::size_t>(c) < f.size() ? f[static_cast<std::size_t>(c)] : std::string(); };
        RunListEntry e{field(ci), field(fi), field(ri), field(ti)};
        if (e.car.empty()) csv.fail("column 'car' is empty: expected a name");
        if (e.file.empty()) csv.fail("column 'file' is empty: expected a trace file");
        if (e.role != "train" && e.role != "test") csv.fail("column 'role' = " + detail::quoted(e.role) + ": expected train or test");
        if (e.type.empty()) e.type = "test";
        // each run once: a repeated one would fit (and write its report figures) twice, and a
        // run both trained on and tested against is no test
        for (const RunListEntry& o : out)
            if (o.car == e.car && o.file == e.file)
                csv.fail("car " + detail::quoted(e.car) + " with file " + detail::quoted(e.file) + " is listed before (role " + o.role +
                         "): expected each run once, as train or as test");
        out.push_back(e);
    }
    if (out.empty()) throw std::invalid_argument(source + ": no runs listed: expected lines car,file,role[,type]");
    return out;
}

CalibrationReport calibration_report(const std::vector<CarCalibration>& cars) {
    CalibrationReport rep;
    auto type_index = [&](const std::string& t) {
        for (std::size_t i = 0; i < rep.test_types.size(); ++i)
            if (rep.test_types[i] == t) return i;
        rep.test_types.push_back(t);
        return rep.test_types.size() - 1;
    };
    for (const CarCalibration& c : cars) {
        for (const TestRun& t : c.tests) type_index(t.type);
        if (c.tests.empty() && c.fit.test.samples > 0) type_index("held out");
    }
    for (const CarCalibration& c : cars) {
        CalibrationReportRow row;
        row.car = c.car;
        row.train_sources = c.train_sources;
        row.fit = &c.fit;
        std::vector<Pool> pools(rep.test_types.size());
        for (const TestRun& t : c.tests) pools[type_index(t.type)].add(t.evaluation.errors, t.evaluation.naive.rmse_speed);
        if (c.tests.empty() && c.fit.test.samples > 0) pools[type_index("held out")].add(c.fit.test, std::nan(""));
        for (const Pool& p : pools) {
            row.test.push_back(p.errors());
            row.naive_test.push_back(p.naive());
        }
        rep.rows.push_back(row);
    }
    return rep;
}

std::string calibration_report_csv(const CalibrationReport& rep) {
    std::ostringstream csv;
    csv << "car,train_runs";
    for (const auto& n : calibration_parameter_names()) {
        const std::string u = unit_suffix(parameter_unit(n));
        csv << "," << n << u << "," << n << "_lo" << u << "," << n << "_hi" << u;
    }
    csv << ",train_rmse_speed_mps,train_rmse_gap_m,naive_rmse_speed_mps";
    for (const auto& t : rep.test_types)
        csv << "," << csv_field(t + "_rmse_speed_mps") << "," << csv_field(t + "_rmse_gap_m") << "," << csv_field(t + "_naive_rmse_speed_mps") << ","
            << csv_field(t + "_samples");
    csv << ",warnings,status\n";
    auto opt = [](double v) { return std::isfinite(v) ? format_exact(v) : std::string(); };
    for (const auto& row : rep.rows) {
        const CalibrationResult& f = *row.fit;
        csv << csv_field(row.car) << "," << csv_field(join(row.train_sources, ";"));
        for (const auto& e : f.estimates) csv << "," << format_exact(e.value) << "," << opt(e.lower95) << "," << opt(e.upper95);
        csv << "," << format_exact(f.train.rmse_speed) << "," << format_exact(f.train.rmse_gap) << "," << format_exact(f.naive.rmse_speed);
        for (std::size_t k = 0; k < rep.test_types.size(); ++k) {
            const FitErrors& e = row.test[k];
            if (e.samples > 0)
                csv << "," << format_exact(e.rmse_speed) << "," << format_exact(e.rmse_gap) << "," << opt(row.naive_test[k].rmse_speed) << ","
                    << e.samples;
            else
                csv << ",,,,0";
        }
        csv << "," << f.warnings.size() << "," << f.status << "\n";
    }
    return csv.str();
}

std::string calibration_report_json(const CalibrationReport& rep) {
    json cars = json::array();
    for (const auto& row : rep.rows) {
        const CalibrationResult& f = *row.fit;
        json c;
        c["car"] = row.car;
        c["train_runs"] = row.train_sources;
        json par = json::object();
        for (const auto& e : f.estimates) par[e.name] = {{"value", num(e.value)}, {"ci95", {num(e.lower95), num(e.upper95)}}, {"at_bound", e.at_bound}};
        c["parameters"] = par;
        c["train"] = {{"rmse_speed", num(f.train.rmse_speed)}, {"rmse_gap", num(f.train.rmse_gap)}, {"samples", f.train.samples}};
        c["naive_rmse_speed"] = num(f.naive.rmse_speed);
        json test = json::object();
        for (std::size_t k = 0; k < rep.test_types.size(); ++k) {
            const FitErrors& e = row.test[k];
            if (e.samples == 0) continue;
            test[rep.test_types[k]] = {{"rmse_speed", num(e.rmse_speed)},
                                       {"rmse_gap", num(e.rmse_gap)},
                                       {"naive_rmse_speed", num(row.naive_test[k].rmse_speed)},
                                       {"samples", e.samples}};
        }
        c["test"] = test;
        c["warnings"] = f.warnings;
        c["status"] = f.status;
        cars.push_back(c);
    }
    json j;
    j["test_types"] = rep.test_types;
    j["cars"] = cars;
    return detail::json_text(j, 2) + "\n";
}

std::string calibration_report_markdown(const CalibrationReport& rep, const CalibrationOptions& o) {
    // the runs by file name without the part all of them share at the start (up to a '_')
    std::vector<std::string> all;
    for (const auto& row : rep.rows)
        for (const auto& f : row.train_sources) all.push_back(base_name(f));
    std::size_t common = all.empty() ? 0 : all[0].size();
    for (const auto& f : all) {
        std::size_t k = 0;
        while (k < common && k < f.size() && f[k] == all[0][k]) ++k;
        common = k;
    }
    if (!all.empty()) common = all[0].rfind('_', common == 0 ? 0 : common - 1) == std::string::npos ? 0 : all[0].rfind('_', common == 0 ? 0 : common - 1) + 1;
    if (all.size() < 2) common = 0;
    std::ostringstream md;
    md << "| car | train runs | k1 [1/s^2] | k2 [1/s] | th [s] | tau [s] | eta [m] | train RMSE speed / naive [m/s] | warnings |\n";
    md << "|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& row : rep.rows) {
        const CalibrationResult& f = *row.fit;
        std::vector<std::string> runs;
        for (const auto& s : row.train_sources) runs.push_back(base_name(s).substr(common));
        md << "| " << row.car << " | " << join(runs, ", ") << " |";
        for (const auto& e : f.estimates) {
            const BoundedParameter b = o.bound(e.name);
            std::string cell = e.at_bound ? "**" + round3(e.value) + "**" : round3(e.value);
            if (e.fixed) cell += " (fixed)";
            else if (std::isfinite(e.lower95) && std::isfinite(e.upper95) && e.upper95 - e.lower95 <= b.upper - b.lower)
                cell += " [" + round3(e.lower95) + ", " + round3(e.upper95) + "]";
            else
                cell += " n.d.";
            md << " " << cell << " |";
        }
        md << " " << round3(f.train.rmse_speed) << " / " << round3(f.naive.rmse_speed) << " | " << f.warnings.size() << " |\n";
    }
    md << "\n| car | speed train [m/s]";
    for (const auto& t : rep.test_types) md << " | speed " << t << " / naive";
    md << " | spacing train [m]";
    for (const auto& t : rep.test_types) md << " | spacing " << t;
    md << " |\n|---|---";
    for (std::size_t k = 0; k < 2 * rep.test_types.size() + 1; ++k) md << "|---";
    md << "|\n";
    for (const auto& row : rep.rows) {
        const CalibrationResult& f = *row.fit;
        md << "| " << row.car << " | " << round3(f.train.rmse_speed);
        for (std::size_t k = 0; k < row.test.size(); ++k) {
            const FitErrors& e = row.test[k];
            const double nv = row.naive_test[k].rmse_speed;
            md << " | " << (e.samples > 0 ? round3(e.rmse_speed) + (std::isfinite(nv) ? " / " + round3(nv) : std::string()) : std::string("-"));
        }
        md << " | " << round3(f.train.rmse_gap);
        for (const auto& e : row.test) md << " | " << (e.samples > 0 ? round3(e.rmse_gap) : "-");
        md << " |\n";
    }
    return md.str();
}

std::string calibration_fit_svg(const std::string& title, const Trace& t, const FitEvaluation& ev, const std::string& note) {
    PlotPanel sp{"Speed (model RMSE " + round3(ev.errors.rmse_speed) + " m/s, naive " + round3(ev.naive.rmse_speed) + " m/s)", "time [s]",
                 "speed [m/s]", {}, {}};
    sp.series.push_back({"lead (measured)", t.t, t.lead, "#7f7f7f", true});
    sp.series.push_back({"follower (measured)", t.t, t.speed, "#000000", false});
    sp.series.push_back({"follower (simulated)", t.t, ev.sim_speed, "#d62728", false});
    PlotPanel gp{"Gap (model RMSE " + round3(ev.errors.rmse_gap) + " m)", "time [s]", "gap [m]", {}, {}};
    gp.series.push_back({"follower (measured)", t.t, t.gap, "#000000", false});
    gp.series.push_back({"follower (simulated)", t.t, ev.sim_gap, "#d62728", false});
    PlotOptions po;
    po.title = title;
    po.note = note;
    po.columns = 1;
    po.panel_width = 760.0;
    po.panel_height = 260.0;
    return render_line_plots_svg({sp, gp}, po);
}

std::vector<CarRuns> cars_from_run_list(const std::vector<RunListEntry>& entries, const std::function<Trace(const std::string& file)>& read,
                                        const std::string& source) {
    std::vector<CarRuns> cars;
    for (const RunListEntry& e : entries) {
        auto it = std::find_if(cars.begin(), cars.end(), [&](const CarRuns& c) { return c.car == e.car; });
        if (it == cars.end()) {
            cars.push_back(CarRuns{e.car, {}, {}, {}});
            it = cars.end() - 1;
        }
        Trace tr = read(e.file);
        if (e.role == "train") {
            it->train.push_back(std::move(tr));
        } else {
            it->test.push_back(std::move(tr));
            it->test_types.push_back(e.type);
        }
    }
    for (const CarRuns& c : cars)
        if (c.train.empty()) throw std::invalid_argument(source + ": car '" + c.car + "' has no run with role train");
    return cars;
}

std::vector<std::pair<std::string, std::string>> calibration_report_files(const std::vector<CarCalibration>& results, const std::vector<CarRuns>& cars,
                                                                          const CalibrationOptions& options, bool per_file) {
    if (results.size() != cars.size()) throw std::invalid_argument("calibration report: expected one result per car");
    std::vector<std::pair<std::string, std::string>> files;
    const CalibrationReport rep = calibration_report(results);
    files.push_back({"table.csv", calibration_report_csv(rep)});
    files.push_back({"table.json", calibration_report_json(rep)});
    files.push_back({"table.md", calibration_report_markdown(rep, options)});
    auto base_name = [](const std::string& path) {
        const auto slash = path.find_last_of('/');
        std::string b = path.substr(slash == std::string::npos ? 0 : slash + 1);
        if (b.size() > 4 && b.substr(b.size() - 4) == ".csv") b.resize(b.size() - 4);
        return b;
    };
    auto figure = [&](const std::string& car, const std::string& title, const Trace& tr, const FitEvaluation& ev) {
        std::string slug;
        for (char ch : car) slug += std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.' ? ch : '_';
        files.push_back({"fit_" + (per_file ? std::string() : slug + "_") + base_name(tr.source) + ".svg", calibration_fit_svg(title, tr, ev, "run: " + tr.source)});
    };
    for (std::size_t i = 0; i < results.size(); ++i) {
        const CarCalibration& r = results[i];
        for (std::size_t k = 0; k < cars[i].train.size() && k < r.fit.runs.size(); ++k)
            figure(r.car, r.car + ": training run " + std::to_string(k + 1) + " of " + std::to_string(cars[i].train.size()), cars[i].train[k], r.fit.runs[k]);
        for (std::size_t k = 0; k < r.tests.size() && k < cars[i].test.size(); ++k)
            figure(r.car, r.car + ": test run (" + r.tests[k].type + ")", cars[i].test[k], r.tests[k].evaluation);
    }
    return files;
}

}  // namespace ddemap
