#include "ddemap/traffic/vehicles.hpp"

#include "ddemap/core/units.hpp"

#include "core/internal/text.hpp"
#include "ddemap/traffic/model.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace ddemap {

const std::vector<CalibratedVehicle>& paper_calibration_table() {
    struct Row {
        const char* vehicle;
        const char* setting;
        double k1, k2, th, tau, eta;
    };
    // transcribed from the paper's calibration table
    static const Row rows[] = {
        {"A", "min", 0.052, 0.338, 0.819, 0.948, 8.030}, {"A", "max", 0.012, 0.167, 2.054, 0.992, 5.960},
        {"B", "min", 0.052, 0.190, 0.725, 0.468, 6.849}, {"B", "max", 0.022, 0.116, 2.020, 0.153, 8.210},
        {"C", "min", 0.029, 0.269, 0.907, 0.368, 10.070}, {"C", "max", 0.018, 0.152, 1.986, 0.324, 13.814},
        {"D", "min", 0.051, 0.280, 0.544, 0.284, 13.400}, {"D", "max", 0.022, 0.221, 1.853, 0.935, 14.956},
        {"E", "min", 0.051, 0.165, 1.127, 0.419, 5.170}, {"E", "max", 0.053, 0.142, 1.785, 0.839, 9.370},
        {"F", "min", 0.071, 0.191, 0.696, 0.582, 10.090}, {"F", "max", 0.041, 0.164, 1.734, 0.922, 6.033},
        {"G", "min", 0.070, 0.253, 0.549, 0.993, 14.500}, {"G", "max", 0.046, 0.129, 1.764, 0.994, 5.131},
    };
    static const std::vector<CalibratedVehicle> table = [] {
        std::vector<CalibratedVehicle> t;
        for (const auto& r : rows) {
            CalibratedVehicle v;
            v.vehicle = r.vehicle;
            v.setting = r.setting;
            v.name = v.vehicle + "_" + v.setting;
            v.make = (v.vehicle < "E") ? 1 : 2;
            v.min_acc_speed = v.make == 1 ? 11.176 : 0.0;  // 25 mph
            v.parameters = {{"k1", r.k1}, {"k2", r.k2}, {"th", r.th}, {"tau", r.tau}, {"eta", r.eta}};
            t.push_back(v);
        }
        return t;
    }();
    return table;
}

const CalibratedVehicle& builtin_vehicle(const std::string& name) {
    for (const auto& v : paper_calibration_table())
        if (v.name == name) return v;
    throw std::invalid_argument("vehicle " + detail::quoted(name) + ": expected a name of the calibration table (A_min .. G_max)");
}

std::vector<std::string> covariance_column_names() {
    static const char* names[] = {"k1", "k2", "th", "tau", "eta"};
    std::vector<std::string> out;
    for (int a = 0; a < 5; ++a)
        for (int b = a; b < 5; ++b) out.push_back(std::string("cov_") + names[a] + "_" + names[b]);
    return out;
}

std::vector<std::string> bounds_column_names() {
    std::vector<std::string> out;
    for (const char* n : {"k1", "k2", "th", "tau", "eta"}) {
        out.push_back(std::string("lo_") + n);
        out.push_back(std::string("hi_") + n);
    }
    return out;
}

namespace {

/// The columns `calibrate` writes besides the parameters, the covariance and the bounds: part of
/// the format, not read.
const std::set<std::string>& calibration_report_columns() {
    // with their units (rmse_speed_mps) and, as written before 2026-11-29, without
    static const std::set<std::string> names = [] {
        std::set<std::string> n = {"status"};
        for (const char* split : {"", "train_", "test_", "naive_"}) {
            for (const char* q : {"rmse_speed", "rmse_gap"}) {
                const std::string c = std::string(split) + q;
                n.insert(c);
                n.insert(c + (q == std::string("rmse_speed") ? "_mps" : "_m"));
            }
        }
        return n;
    }();
    return names;
}

/// Every parameter name of the built-in models but speed (set by the ring or the simulation).
const std::vector<std::string>& model_parameter_columns() {
    static const std::vector<std::string> names = [] {
        std::set<std::string> all;
        for (const auto& m : model_names())
            for (const auto& spec : model_parameters(m))
                if (spec.name != "speed") all.insert(spec.name);
        return std::vector<std::string>(all.begin(), all.end());
    }();
    return names;
}

const CalibratedVehicle* paper_vehicle(const std::string& name) {
    for (const auto& v : paper_calibration_table())
        if (v.name == name) return &v;
    return nullptr;
}

std::string joined(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

}  // namespace

ParameterMap complete_car_parameters(const std::string& model, const ParameterMap& parameters) {
    ParameterMap p = parameters;
    p["speed"] = 20.0;  // any valid speed: the car's own is set by the ring or the simulation
    p = make_model(model, p)->parameters();
    p.erase("speed");
    return p;
}

std::vector<CalibratedVehicle> read_car_table(const std::string& text, const std::string& source) {
    const std::string expected = "name and/or vehicle and/or model, the parameters (k1,k2,th,tau[,eta] for ovrv), [count]";
    detail::CsvReader csv(text, source, expected);
    const std::vector<std::string>& params = model_parameter_columns();
    const std::vector<std::string> cov_names = covariance_column_names();
    const std::vector<std::string> bound_names = bounds_column_names();
    // a parameter column may carry its unit (k1_per_s2, lo_th_s: what classify and calibrate
    // write): read as the parameter's name
    for (int i = 0; i < csv.columns(); ++i) {
        const std::string h = csv.header()[static_cast<std::size_t>(i)];
        for (const std::string prefix : {"", "lo_", "hi_"}) {
            if (h.rfind(prefix, 0) != 0) continue;
            const std::string rest = h.substr(prefix.size());
            for (const auto& p : params)
                if (rest != p && strip_unit(rest, parameter_unit(p)) == p) csv.rename_column(i, prefix + p);
        }
    }
    // every column known, and none twice
    std::set<std::string> seen;
    for (const auto& h : csv.header()) {
        if (!seen.insert(h).second) throw std::invalid_argument(source + ": column " + detail::quoted(h) + " appears twice in the header");
        if (h == "speed") throw std::invalid_argument(source + ": column 'speed': a car's speed is set by the ring or the simulation, not by its table");
        const bool known = h == "name" || h == "vehicle" || h == "model" || h == "count" || h == "min_acc_speed" ||
                           std::find(params.begin(), params.end(), h) != params.end() ||
                           std::find(cov_names.begin(), cov_names.end(), h) != cov_names.end() ||
                           std::find(bound_names.begin(), bound_names.end(), h) != bound_names.end() || calibration_report_columns().count(h);
        if (!known) {
            std::vector<std::string> names = {"name", "vehicle", "model", "count", "min_acc_speed"};
            names.insert(names.end(), params.begin(), params.end());
            const std::string hint = csv.header_hint(h, names);
            throw std::invalid_argument(source + ": column " + detail::quoted(h) + " is not a column of a car table" +
                                        (hint.empty() ? ": expected name, vehicle, model, count, " + joined(params) +
                                                            ", min_acc_speed, cov_k1_k1 .. cov_eta_eta, lo_k1 .. hi_eta (remove or rename it)"
                                                      : hint));
        }
    }
    const int c_name = csv.column("name", false), c_vehicle = csv.column("vehicle", false), c_model = csv.column("model", false),
              c_count = csv.column("count", false), c_min_speed = csv.column("min_acc_speed", false);
    if (c_name < 0 && c_vehicle < 0 && c_model < 0) throw std::invalid_argument(source + ": the header needs a 'name', 'vehicle' or 'model' column (" + expected + ")");
    std::vector<std::pair<std::string, int>> c_params;
    for (const auto& p : params) {
        const int c = csv.column(p, false);
        if (c >= 0) c_params.emplace_back(p, c);
    }
    std::vector<int> c_cov;
    for (const auto& n : cov_names) c_cov.push_back(csv.column(n, false));
    const auto cov_given = static_cast<int>(std::count_if(c_cov.begin(), c_cov.end(), [](int c) { return c >= 0; }));
    if (cov_given > 0 && cov_given < 15)
        throw std::invalid_argument(source + ": the header has " + std::to_string(cov_given) +
                                    " of the 15 covariance columns cov_k1_k1 .. cov_eta_eta: expected all or none");
    // the calibration's bounds: for each parameter lo_NAME and hi_NAME, both or neither
    static const char* fitted[] = {"k1", "k2", "th", "tau", "eta"};
    std::vector<int> c_bound;
    for (const auto& n : bound_names) c_bound.push_back(csv.column(n, false));
    for (std::size_t i = 0; i < 5; ++i)
        if ((c_bound[2 * i] >= 0) != (c_bound[2 * i + 1] >= 0))
            throw std::invalid_argument(source + ": the header has " + (c_bound[2 * i] >= 0 ? bound_names[2 * i] : bound_names[2 * i + 1]) +
                                        " without " + (c_bound[2 * i] >= 0 ? bound_names[2 * i + 1] : bound_names[2 * i]) +
                                        ": expected both bounds of " + fitted[i] + " or neither");
    std::vector<CalibratedVehicle> out;
    std::map<std::string, std::pair<CalibratedVehicle, std::string>> by_name;  // a name's car and where it was first given
    while (csv.next()) {
        const auto& f = csv.fields();
        auto field = [&](int c) { return c >= 0 ? f[static_cast<std::size_t>(c)] : std::string(); };
        CalibratedVehicle v;
        const std::string vehicle = field(c_vehicle), model = field(c_model);
        if (!vehicle.empty()) {
            const CalibratedVehicle* b = paper_vehicle(vehicle);
            if (!b)
                csv.fail("column 'vehicle' = " + detail::quoted(vehicle) + ": expected a setting of the paper's table (A_min .. G_max), or a blank with a name or a model");
            v = *b;
        } else {
            v.vehicle.clear();
            v.setting.clear();
            v.make = 0;
        }
        if (!model.empty()) {
            const auto names = model_names();
            if (std::find(names.begin(), names.end(), model) == names.end())
                csv.fail("column 'model' = " + detail::quoted(model) + ": expected one of " + joined(names));
            v.model = model;
        }
        v.name = field(c_name);
        if (v.name.empty()) v.name = !vehicle.empty() ? vehicle : c_name >= 0 ? std::string() : v.model + "@" + csv.where();
        if (v.name.empty()) csv.fail("column 'name' is empty: expected a car name");
        if (detail::has_control(v.name)) csv.fail("column 'name' = " + detail::quoted(v.name) + ": expected a name without control characters");
        if (v.vehicle.empty()) v.vehicle = v.name;
        for (const auto& [name, c] : c_params)
            if (!field(c).empty()) v.parameters[name] = csv.number(c, name);
        if (c_min_speed >= 0 && !field(c_min_speed).empty()) {
            v.min_acc_speed = csv.number(c_min_speed, "min_acc_speed");
            if (v.min_acc_speed < 0.0 || v.min_acc_speed > 100.0) csv.fail("min_acc_speed = " + field(c_min_speed) + ": expected 0 to 100 m/s");
        }
        if (cov_given == 15) {
            int filled = 0;
            for (int c : c_cov) filled += field(c).empty() ? 0 : 1;
            if (filled != 0 && filled != 15) csv.fail(std::to_string(filled) + " of the 15 covariance columns are filled: expected all or none");
            if (filled == 15) {
                std::size_t k = 0;
                for (int a = 0; a < 5; ++a)
                    for (int b = a; b < 5; ++b, ++k) {
                        const double x = csv.number(c_cov[k], cov_names[k]);
                        if (a == b && x < 0.0) csv.fail("column '" + cov_names[k] + "' = " + field(c_cov[k]) + ": expected a variance >= 0");
                        if (!(std::abs(x) <= kMaxCovarianceEntry))
                            csv.fail("column '" + cov_names[k] + "' = " + field(c_cov[k]) + ": expected a magnitude at most 1e6 (a standard deviation of 1000)");
                        v.covariance(a, b) = v.covariance(b, a) = x;
                    }
                v.has_covariance = true;
            }
        }
        for (std::size_t i = 0; i < 5; ++i) {
            const int cl = c_bound[2 * i], ch = c_bound[2 * i + 1];
            if (cl < 0) continue;
            const bool fl = !field(cl).empty(), fh = !field(ch).empty();
            if (fl != fh) csv.fail(bound_names[2 * i] + " and " + bound_names[2 * i + 1] + ": expected both filled or both empty");
            if (!fl) continue;
            const double lo = csv.number(cl, bound_names[2 * i]), hi = csv.number(ch, bound_names[2 * i + 1]);
            if (lo < 0.0) csv.fail(bound_names[2 * i] + " = " + field(cl) + ": expected >= 0 (the model's domain)");
            if (!(lo <= hi))
                csv.fail(bound_names[2 * i] + " = " + detail::format_number(lo) + " above " + bound_names[2 * i + 1] + " = " + detail::format_number(hi) +
                         ": expected lower <= upper");
            v.bounds.push_back({fitted[i], lo, hi});
        }
        if (v.model != "ovrv" && (v.has_covariance || !v.bounds.empty() || v.min_acc_speed > 0.0))
            csv.fail("a covariance, bounds or min_acc_speed belong to a fit of the ovrv law; this car's model is " + v.model);
        // the model's defaults filled in, its ranges checked (speed: any valid one; it is not kept)
        try {
            v.parameters = complete_car_parameters(v.model, v.parameters);
        } catch (const std::invalid_argument& e) {
            csv.fail(std::string("car ") + detail::quoted(v.name) + ": " + e.what());
        }
        long count = 1;
        if (!field(c_count).empty()) {
            const double k = csv.number(c_count, "count");
            if (!(k >= 1 && k <= 1000000 && k == std::floor(k))) csv.fail("column 'count' = " + detail::quoted(field(c_count)) + ": expected an integer 1..1000000");
            count = static_cast<long>(k);
        }
        const auto it = by_name.find(v.name);
        if (it == by_name.end()) {
            by_name.emplace(v.name, std::make_pair(v, csv.where()));
        } else if (it->second.first.model != v.model || it->second.first.parameters != v.parameters ||
                   it->second.first.has_covariance != v.has_covariance || it->second.first.min_acc_speed != v.min_acc_speed) {
            csv.fail("car name " + detail::quoted(v.name) + " is given twice with different values (first at " + it->second.second +
                     "): expected distinct names");
        }
        if (out.size() + static_cast<std::size_t>(count) > 1000000) csv.fail("more than 1000000 cars");
        for (long r = 0; r < count; ++r) out.push_back(v);
    }
    if (out.empty()) throw std::invalid_argument(source + ": no cars after the header");
    return out;
}

std::vector<CalibratedVehicle> read_vehicles_csv(const std::string& text, const std::string& source) {
    std::vector<CalibratedVehicle> cars = read_car_table(text, source);
    for (const auto& v : cars)
        if (v.model != "ovrv")
            throw std::invalid_argument(source + ": car " + detail::quoted(v.name) + " has model " + detail::quoted(v.model) +
                                        ": expected cars of the ovrv law here");
    return cars;
}

}  // namespace ddemap
