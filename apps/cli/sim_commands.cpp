#include "sim_commands.hpp"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common.hpp"
#include "ddemap/analysis/calibrate.hpp"
#include "ddemap/io/svg.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/analysis/classify.hpp"

namespace ddemap::cli {

namespace {

/// --lead-profile NAME (built in) or --lead FILE.csv
LeadProfile lead_from(const std::string& profile, const std::string& file, std::string& label) {
    if (!profile.empty() && !file.empty()) throw BadInput("give either --lead FILE.csv or --lead-profile NAME, not both");
    if (!file.empty()) {
        label = file;
        return LeadProfile::from_csv(read_input_file("--lead", file), file);
    }
    const std::string name = profile.empty() ? "dip" : profile;
    const auto names = LeadProfile::builtin_names();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
        throw BadInput("--lead-profile = '" + name + "': expected one of dip, oscillatory, step-low, step-high");
    }
    label = name;
    return LeadProfile::builtin(name);
}

/// --fleet "A_min*3,C_max" (built-in names, *K repeats) or a CSV file (name,k1,k2,th,tau[,eta][,min_acc_speed])
std::vector<SimCar> fleet_from(const std::string& text) {
    if (text.size() > 4 && text.substr(text.size() - 4) == ".csv")
        return platoon_from(read_vehicles_csv(read_input_file("--fleet", text), text));
    return platoon_from(vehicles_from_pattern(text));
}
}  // namespace

std::string growth_table(const std::vector<GrowthResult>& g) {
    std::ostringstream out;
    out << "name     amplification by position (speed drop / lead drop)                       platoon fails at\n";
    for (const auto& r : g) {
        char head[32];
        std::snprintf(head, sizeof head, "%-8s", r.name.c_str());
        out << head;
        for (std::size_t i = 0; i < r.amplification.size() && i < 8; ++i) out << " " << rounded(r.amplification[i], 3);
        if (r.amplification.size() > 8) out << " ...";
        out << "   ";
        if (r.failed_at) out << "car " << r.failed_at << " (" << r.failure << " at t = " << rounded(r.failure_time, 4) << " s)";
        else out << "none";
        out << "\n";
    }
    return out.str();
}

std::string growth_csv(const std::vector<GrowthResult>& g) {
    std::ostringstream out;
    out << "name,position,speed_drop,amplification,min_gap,failure\n";
    for (const auto& r : g) {
        for (std::size_t i = 0; i < r.amplification.size(); ++i) {
            out << r.name << "," << i + 1 << "," << exact(r.speed_drop[i]) << "," << exact(r.amplification[i]) << "," << exact(r.min_gap[i]) << ",\n";
        }
        if (r.failed_at) {
            out << r.name << "," << r.failed_at << ",," << exact(r.failure_amplification) << "," << exact(r.failure_gap) << "," << r.failure << "\n";
        }
    }
    return out.str();
}

std::string growth_svg(const std::vector<GrowthResult>& g, const std::string& lead_name) {
    PlotPanel gap{"Minimum gap", "position in the platoon", "minimum gap [m]", {}, {}};
    PlotPanel amp{"Disturbance amplification", "position in the platoon", "speed drop / lead's drop [1]", {}, {}};
    for (const auto& r : g) {
        PlotSeries a{r.name, {}, {}, "", r.name.find("max") != std::string::npos};
        PlotSeries b = a;
        for (std::size_t i = 0; i < r.amplification.size(); ++i) {
            a.x.push_back(i + 1.0);
            a.y.push_back(r.min_gap[i]);
            b.x.push_back(i + 1.0);
            b.y.push_back(r.amplification[i]);
        }
        if (r.failed_at) {
            const std::string colour = r.failure == "collision" ? "#d62728" : "#000000";
            a.x.push_back(r.failed_at);
            a.y.push_back(r.failure_gap);
            b.x.push_back(r.failed_at);
            b.y.push_back(r.failure_amplification);
            gap.markers.push_back({double(r.failed_at), r.failure_gap, colour, ""});
            amp.markers.push_back({double(r.failed_at), r.failure_amplification, colour, ""});
        }
        gap.series.push_back(a);
        amp.series.push_back(b);
    }
    PlotOptions o;
    o.title = "Disturbance growth behind the '" + lead_name + "' lead profile (calibrated OVRV platoons)";
    o.note = "black x: ACC disengages (speed below the minimum ACC speed); red x: gap reaches zero (collision); dashed: max setting";
    return render_line_plots_svg({gap, amp}, o);
}

namespace {

std::string base_name(const std::string& path) {
    std::string b = path.substr(path.find_last_of('/') == std::string::npos ? 0 : path.find_last_of('/') + 1);
    if (b.size() > 4 && b.substr(b.size() - 4) == ".csv") b.resize(b.size() - 4);
    return b;
}

json fit_json(const std::string& name, const CalibrationResult& r) {
    json j;
    j["name"] = name;
    for (const char* k : {"k1", "k2", "th", "tau", "eta"}) j[k] = r.parameters.at(k);
    j["rmse_speed"] = r.all.rmse_speed;
    j["rmse_gap"] = r.all.rmse_gap;
    j["train"] = {{"rmse_speed", r.train.rmse_speed}, {"rmse_gap", r.train.rmse_gap}, {"samples", r.train.samples}};
    if (r.test.samples > 0) j["test"] = {{"rmse_speed", r.test.rmse_speed}, {"rmse_gap", r.test.rmse_gap}, {"samples", r.test.samples}};
    j["naive_rmse_speed"] = r.naive.rmse_speed;
    j["naive_delay"] = r.naive_delay;
    j["status"] = r.status;
    j["evaluations"] = r.evaluations;
    j["seconds"] = r.seconds;
    return j;
}

}  // namespace

struct SimCommands::Impl {
    CLI::App* calibrate_cmd = nullptr;
    std::vector<std::string> c_files;
    std::string c_train, c_model = "ovrv", c_bounds, c_gap_weight = "0.02", c_out, c_format = "table";

    void run_calibrate() const {
        if (c_model != "ovrv") throw BadInput("--model = '" + c_model + "': calibration supports ovrv");
        const Format format = parse_format(c_format);
        if (!c_out.empty()) check_output("--out", c_out);
        CalibrationOptions o;
        o.gap_weight = parse_number("--gap-weight", c_gap_weight);
        if (!c_train.empty()) {
            const auto colon = c_train.find(':');
            if (colon == std::string::npos) throw BadInput("--train = '" + c_train + "': expected T0:T1 in seconds");
            o.train_start = parse_number("--train", c_train.substr(0, colon));
            o.train_end = parse_number("--train", c_train.substr(colon + 1));
            if (!(o.train_start >= 0 && o.train_end > o.train_start)) throw BadInput("--train = '" + c_train + "': expected 0 <= T0 < T1");
        }
        if (!c_bounds.empty()) {
            std::stringstream ss(c_bounds);
            std::string item;
            const char* names[5] = {"k1", "k2", "th", "tau", "eta"};
            while (std::getline(ss, item, ',')) {
                const auto eq = item.find('='), colon = item.find(':');
                if (eq == std::string::npos || colon == std::string::npos || colon < eq) {
                    throw BadInput("--bounds item '" + item + "': expected NAME=LO:HI, e.g. eta=0:15");
                }
                const std::string name = item.substr(0, eq);
                const auto it = std::find_if(std::begin(names), std::end(names), [&](const char* n) { return name == n; });
                if (it == std::end(names)) throw BadInput("--bounds item '" + item + "': expected one of k1, k2, th, tau, eta");
                const int i = static_cast<int>(it - std::begin(names));
                o.lower[i] = parse_number("--bounds " + name, item.substr(eq + 1, colon - eq - 1));
                o.upper[i] = parse_number("--bounds " + name, item.substr(colon + 1));
            }
        }
        o.validate();
        std::vector<Trace> traces;
        for (const auto& f : c_files) traces.push_back(read_trace_csv(read_input_file("DATA.csv", f), f));
        const std::vector<CalibrationResult> fits = calibrate_many(traces, o);

        std::ostringstream csv;
        csv << "name,k1,k2,th,tau,eta,rmse_speed,rmse_gap,train_rmse_speed,train_rmse_gap,test_rmse_speed,test_rmse_gap,"
               "naive_rmse_speed,status\n";
        for (std::size_t i = 0; i < fits.size(); ++i) {
            const auto& r = fits[i];
            csv << csv_field(base_name(c_files[i]));
            for (const char* k : {"k1", "k2", "th", "tau", "eta"}) csv << "," << exact(r.parameters.at(k));
            csv << "," << exact(r.all.rmse_speed) << "," << exact(r.all.rmse_gap) << "," << exact(r.train.rmse_speed) << ","
                << exact(r.train.rmse_gap) << ",";
            if (r.test.samples > 0) csv << exact(r.test.rmse_speed) << "," << exact(r.test.rmse_gap);
            else csv << ",";
            csv << "," << exact(r.naive.rmse_speed) << "," << r.status << "\n";
        }
        json j;
        if (fits.size() == 1) {
            j = fit_json(base_name(c_files[0]), fits[0]);
        } else {
            json arr = json::array();
            for (std::size_t i = 0; i < fits.size(); ++i) arr.push_back(fit_json(base_name(c_files[i]), fits[i]));
            j["fits"] = arr;
        }
        j["command"] = "calibrate";
        j["version"] = DDEMAP_VERSION;
        j["gap_weight"] = o.gap_weight;
        j["bounds"] = {{"k1", {o.lower[0], o.upper[0]}}, {"k2", {o.lower[1], o.upper[1]}}, {"th", {o.lower[2], o.upper[2]}},
                       {"tau", {o.lower[3], o.upper[3]}}, {"eta", {o.lower[4], o.upper[4]}}};
        if (!c_out.empty()) {
            std::vector<PlotPanel> panels;
            for (std::size_t i = 0; i < fits.size(); ++i) {
                const Trace& t = traces[i];
                const std::string name = base_name(c_files[i]);
                PlotPanel sp{name + ": speed", "time [s]", "speed [m/s]", {}, {}};
                sp.series.push_back({"lead (measured)", t.t, t.lead, "#7f7f7f", true});
                sp.series.push_back({"follower (measured)", t.t, t.speed, "#000000", false});
                sp.series.push_back({"follower (model)", t.t, fits[i].sim_speed, "#d62728", false});
                PlotPanel gp{name + ": gap", "time [s]", "gap [m]", {}, {}};
                gp.series.push_back({"follower (measured)", t.t, t.gap, "#000000", false});
                gp.series.push_back({"follower (model)", t.t, fits[i].sim_gap, "#d62728", false});
                panels.push_back(sp);
                panels.push_back(gp);
            }
            PlotOptions po;
            po.title = "Calibrated OVRV: measured and simulated follower";
            po.columns = 2;
            write_files_atomic({{c_out + ".csv", csv.str()}, {c_out + ".json", j.dump(2) + "\n"},
                                {c_out + ".svg", render_line_plots_svg(panels, po)}});
        }
        if (format == Format::Json) {
            std::cout << j.dump(2) << "\n";
        } else if (format == Format::Csv) {
            std::cout << csv.str();
        } else {
            std::ostringstream out;
            out << "file                                         k1      k2     th     tau    eta   rmse_v  rmse_gap  naive_v  status\n";
            for (std::size_t i = 0; i < fits.size(); ++i) {
                const auto& r = fits[i];
                const auto& p = r.parameters;
                char line[300];
                std::snprintf(line, sizeof line, "%-42.42s %7.4f %7.4f %6.3f %6.3f %6.2f %7.3f %8.3f %8.3f  %s\n",
                              base_name(c_files[i]).c_str(), p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"), p.at("eta"),
                              r.all.rmse_speed, r.all.rmse_gap, r.naive.rmse_speed, r.status.c_str());
                out << line;
            }
            std::cout << out.str();
        }
    }

    CLI::App* simulate = nullptr;
    std::string fleet, lead_file, lead_profile, out, on_event = "continue", t_end = "0", step = "0.05", output_dt = "0.1";
    CLI::App* growth = nullptr;
    std::string g_followers = "15", g_lead_profile, g_lead_file, g_out, g_format = "table";

    SimOptions options() const {
        SimOptions o;
        o.step = parse_number("--step", step);
        o.t_end = parse_number("--t-end", t_end);
        o.output_dt = parse_number("--output-dt", output_dt);
        if (on_event == "stop") o.on_event = OnEvent::Stop;
        else if (on_event != "continue") throw BadInput("--on-event = '" + on_event + "': expected stop or continue");
        o.validate();
        return o;
    }

    void run_simulate() const {
        if (fleet.empty()) throw BadInput("--fleet is required (e.g. --fleet A_min*7 or --fleet cars.csv)");
        check_output("--out", out);
        const SimOptions o = options();
        std::string label;
        const LeadProfile lead = lead_from(lead_profile, lead_file, label);
        const std::vector<SimCar> cars = fleet_from(fleet);
        const SimResult r = simulate_platoon(lead, cars, o);
        std::ostringstream csv;
        csv << "time,car,position,speed,gap\n";
        for (std::size_t k = 0; k < r.time.size(); ++k)
            for (std::size_t c = 0; c < r.speed.size(); ++c) {
                csv << exact(r.time[k]) << "," << c << "," << exact(r.position[c][k]) << "," << exact(r.speed[c][k]) << ",";
                if (c > 0) csv << exact(r.gap[c][k]);
                csv << "\n";
            }
        json j;
        j["command"] = "simulate";
        j["version"] = DDEMAP_VERSION;
        j["lead"] = label;
        j["initial_speed"] = r.initial_speed;
        j["t_end"] = r.t_end;
        j["stopped_at_event"] = r.stopped;
        j["steps"] = r.steps;
        json cs = json::array();
        for (const auto& c : r.cars) {
            json e = json::array();
            for (const auto& ev : c.events) e.push_back({{"type", ev.type}, {"time", ev.time}, {"speed", ev.speed}, {"gap", ev.gap}});
            cs.push_back({{"car", c.car}, {"name", c.name}, {"min_speed", c.min_speed}, {"speed_drop", c.speed_drop}, {"min_gap", c.min_gap}, {"events", e}});
        }
        j["cars"] = cs;
        PlotPanel p{"Speeds", "time [s]", "speed [m/s]", {}, {}};
        for (std::size_t c = 0; c < r.speed.size(); ++c) {
            PlotSeries sr{c == 0 ? "lead" : "car " + std::to_string(c) + " (" + r.cars[c - 1].name + ")", r.time, r.speed[c], c == 0 ? "#000000" : "", c == 0};
            p.series.push_back(sr);
        }
        for (const auto& ev : r.events)
            p.markers.push_back({ev.time, ev.speed, ev.type == "collision" ? "#d62728" : "#000000", ev.type + " car " + std::to_string(ev.car)});
        PlotOptions po;
        po.title = "Platoon behind the '" + label + "' lead profile";
        po.columns = 1;
        po.panel_width = 760;
        po.panel_height = 340;
        write_files_atomic({{out + ".csv", csv.str()}, {out + ".json", j.dump(2) + "\n"}, {out + ".svg", render_line_plots_svg({p}, po)}});
        std::ostringstream s;
        s << "simulated  " << cars.size() << " followers to t = " << rounded(r.t_end, 5) << " s (" << r.steps << " steps)\n";
        s << "car  name      min speed  speed drop  min gap   events\n";
        for (const auto& c : r.cars) {
            char line[160];
            std::snprintf(line, sizeof line, "%3d  %-8s %9.3f %11.3f %8.3f   ", c.car, c.name.c_str(), c.min_speed, c.speed_drop, c.min_gap);
            s << line;
            for (const auto& ev : c.events) s << ev.type << " at " << rounded(ev.time, 4) << " s  ";
            s << "\n";
        }
        s << "wrote      " << out << ".csv " << out << ".json " << out << ".svg\n";
        std::cout << s.str();
    }

    void run_growth() const {
        const int followers = static_cast<int>(parse_integer("--followers", g_followers, 1, 200, "an integer from 1 to 200"));
        const Format format = parse_format(g_format);
        if (!g_out.empty()) check_output("--out", g_out);
        std::string label;
        const LeadProfile lead = lead_from(g_lead_profile, g_lead_file, label);
        const auto g = disturbance_growth(paper_calibration_table(), lead, followers);
        if (!g_out.empty()) {
            write_files_atomic({{g_out + ".csv", growth_csv(g)}, {g_out + ".svg", growth_svg(g, label)}});
        }
        if (format == Format::Csv) {
            std::cout << growth_csv(g);
        } else if (format == Format::Json) {
            json arr = json::array();
            for (const auto& r : g) {
                arr.push_back({{"name", r.name}, {"speed_drop", r.speed_drop}, {"amplification", r.amplification}, {"min_gap", r.min_gap},
                               {"failed_at", r.failed_at}, {"failure", r.failure}, {"failure_time", r.failure_time}});
            }
            std::cout << json{{"command", "growth"}, {"version", DDEMAP_VERSION}, {"lead", label}, {"vehicles", arr}}.dump(2) << "\n";
        } else {
            std::cout << growth_table(g);
        }
    }
};

void SimCommands::add_to(CLI::App& app) {
    m = std::make_shared<Impl>();
    m->calibrate_cmd = app.add_subcommand("calibrate", "fit OVRV (k1, k2, th, tau, eta) to measured car-following traces (NLopt: DIRECT-L, then BOBYQA)");
    m->calibrate_cmd->add_option("DATA.csv", m->c_files, "traces with columns time_s, lead_speed_mps, follower_speed_mps, gap_m")->required();
    m->calibrate_cmd->add_option("--train", m->c_train, "training window T0:T1 [s] (default: the whole file; the rest is the test part)");
    m->calibrate_cmd->add_option("--model", m->c_model, "the model to fit (ovrv)")->capture_default_str();
    m->calibrate_cmd->add_option("--bounds", m->c_bounds, "bounds NAME=LO:HI,... (default: the paper's k1=0:1,k2=0:1,th=0:3,tau=0:1,eta=5:15)");
    m->calibrate_cmd->add_option("--gap-weight", m->c_gap_weight, "objective = MSE(speed) + W * MSE(gap) [W in 1/s^2]")->capture_default_str();
    m->calibrate_cmd->add_option("--out", m->c_out, "write PREFIX.csv (a table for classify), PREFIX.json, PREFIX.svg");
    m->calibrate_cmd->add_option("--format", m->c_format, "table, json or csv")->capture_default_str();
    m->simulate = app.add_subcommand("simulate", "nonlinear platoon simulation behind a lead speed profile; writes PREFIX.csv, .json, .svg");
    m->simulate->add_option("--fleet", m->fleet, "followers in platoon order: built-in names with repeats (A_min*7,C_max) or a CSV name,k1,k2,th,tau[,eta]");
    m->simulate->add_option("--lead", m->lead_file, "lead speed CSV with columns time_s, lead_speed_mps (piecewise linear)");
    m->simulate->add_option("--lead-profile", m->lead_profile, "built-in lead profile: dip (22.4 -> 19.7 -> 22.4 m/s), oscillatory, step-low, step-high");
    m->simulate->add_option("--out", m->out, "output prefix");
    m->simulate->add_option("--on-event", m->on_event, "stop or continue at the first disengagement or collision")->capture_default_str();
    m->simulate->add_option("--t-end", m->t_end, "end time [s] (0: the profile's last breakpoint + 30 s)")->capture_default_str();
    m->simulate->add_option("--step", m->step, "largest integration step [s]")->capture_default_str();
    m->simulate->add_option("--output-dt", m->output_dt, "output sampling [s]")->capture_default_str();

    m->growth = app.add_subcommand("growth", "disturbance growth for every setting of the calibration table: platoons of 1 to 15 followers");
    m->growth->add_option("--followers", m->g_followers, "longest platoon")->capture_default_str();
    m->growth->add_option("--lead-profile", m->g_lead_profile, "built-in lead profile (default dip)");
    m->growth->add_option("--lead", m->g_lead_file, "lead speed CSV (time_s, lead_speed_mps)");
    m->growth->add_option("--out", m->g_out, "also write PREFIX.csv and PREFIX.svg");
    m->growth->add_option("--format", m->g_format, "table, json or csv")->capture_default_str();
}

bool SimCommands::run() const {
    if (m->calibrate_cmd->parsed()) {
        m->run_calibrate();
        return true;
    }
    if (m->simulate->parsed()) {
        m->run_simulate();
        return true;
    }
    if (m->growth->parsed()) {
        m->run_growth();
        return true;
    }
    return false;
}

}  // namespace ddemap::cli
