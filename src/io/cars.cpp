#include "ddemap/io/cars.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>

#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "core/internal/text.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

namespace {

using detail::trim;

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

bool is_model(const std::string& name) {
    const auto names = model_names();
    return std::find(names.begin(), names.end(), name) != names.end();
}

/// An inline car's first item: MODEL:NAME=VALUE with a built-in model.
bool starts_inline(const std::string& token) {
    const auto colon = token.find(':');
    return colon != std::string::npos && is_model(trim(token.substr(0, colon))) && token.find('=', colon) != std::string::npos;
}

/// One item of the list with its repeat (*K).
struct Item {
    std::string text;
    long repeat = 1;
};

/// Splits the list at its commas and joins an inline car's parameters back into one item.
std::vector<Item> split_items(const std::string& list) {
    std::vector<std::string> tokens;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = list.find(',', start);
        tokens.push_back(trim(list.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
        start = comma == std::string::npos ? list.size() + 1 : comma + 1;
    }
    std::vector<Item> items;
    for (std::size_t i = 0; i < tokens.size(); ++i) {
        if (tokens[i].empty())
            throw std::invalid_argument("car list " + detail::quoted(list) + ": an empty item: expected cars separated by commas (A_min, FILE.csv, FILE.csv:NAME, MODEL:NAME=VALUE,...)");
        Item item{tokens[i]};
        if (starts_inline(tokens[i]))
            while (i + 1 < tokens.size() && tokens[i + 1].find('=') != std::string::npos && tokens[i + 1].find(':') == std::string::npos)
                item.text += "," + tokens[++i];
        // *K at the end: the item K times
        const auto star = item.text.rfind('*');
        if (star != std::string::npos) {
            const std::string k = trim(item.text.substr(star + 1));
            char* end = nullptr;
            const long repeat = std::strtol(k.c_str(), &end, 10);
            if (k.empty() || *end != '\0' || repeat < 1 || repeat > static_cast<long>(kMaxCars))
                throw std::invalid_argument("car " + detail::quoted(item.text) + ": expected CAR*K with K an integer 1.." + std::to_string(kMaxCars));
            item.text = trim(item.text.substr(0, star));
            item.repeat = repeat;
        }
        items.push_back(item);
    }
    return items;
}

CalibratedVehicle inline_car(const std::string& spec) {
    const auto colon = spec.find(':');
    CalibratedVehicle v;
    v.model = trim(spec.substr(0, colon));
    v.vehicle.clear();
    v.setting.clear();
    v.make = 0;
    std::size_t start = colon + 1;
    while (start < spec.size()) {
        const std::size_t comma = spec.find(',', start);
        const std::string entry = trim(spec.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        start = comma == std::string::npos ? spec.size() : comma + 1;
        const auto eq = entry.find('=');
        if (eq == std::string::npos)
            throw std::invalid_argument("car " + detail::quoted(spec) + ": entry " + detail::quoted(entry) + ": expected NAME=VALUE");
        const std::string key = trim(entry.substr(0, eq)), text = trim(entry.substr(eq + 1));
        const bool identifier = !key.empty() && !std::isdigit(static_cast<unsigned char>(key[0])) &&
                                std::all_of(key.begin(), key.end(), [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
        if (!identifier)
            throw std::invalid_argument("car " + detail::quoted(spec) + ": entry " + detail::quoted(entry) +
                                        ": expected NAME=VALUE with NAME a parameter (letters, digits, _)");
        if (key == "name") {
            if (text.empty()) throw std::invalid_argument("car " + detail::quoted(spec) + ": name= is empty: expected a name");
            detail::require_utf8(text, "car " + detail::quoted(spec) + ": name");
            if (detail::has_control(text))
                throw std::invalid_argument("car " + detail::quoted(spec) + ": name = " + detail::quoted(text) + ": expected a name without control characters");
            v.name = text;
            continue;
        }
        double value = 0.0;
        if (!detail::parse_finite(text, value))
            throw std::invalid_argument("car " + detail::quoted(spec) + ": " + key + " = " + detail::quoted(text) + ": expected a finite number");
        if (key == "speed") throw std::invalid_argument("car " + detail::quoted(spec) + ": a car's speed is set by the ring or the simulation, not per car");
        if (key == "min_acc_speed") {
            if (v.model != "ovrv" || value < 0.0 || value > 100.0)
                throw std::invalid_argument("car " + detail::quoted(spec) + ": min_acc_speed = " + text + ": expected 0 to 100 m/s on an ovrv car");
            v.min_acc_speed = value;
            continue;
        }
        if (v.parameters.count(key)) throw std::invalid_argument("car " + detail::quoted(spec) + ": " + key + " is given twice");
        v.parameters[key] = value;
    }
    if (v.name.empty()) v.name = spec;
    v.vehicle = v.name;
    try {
        v.parameters = complete_car_parameters(v.model, v.parameters);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument("car " + detail::quoted(spec) + ": " + e.what());
    }
    return v;
}

std::vector<CalibratedVehicle> read_file_cars(const std::string& file) {
    const std::string text = read_text_file(file);
    const std::string t = trim(text.substr(0, std::min<std::size_t>(text.size(), 64)));
    const bool json = ends_with(file, ".json") || (!t.empty() && t[0] == '{');
    if (json) return read_calibration_json(text, file);
    return read_car_table(text, file);
}

std::string names_of(const std::vector<CalibratedVehicle>& cars) {
    std::string s;
    std::vector<std::string> seen;
    for (const auto& c : cars) {
        if (std::find(seen.begin(), seen.end(), c.name) != seen.end()) continue;
        seen.push_back(c.name);
        if (seen.size() > 12) {
            s += ", ...";
            break;
        }
        s += (s.empty() ? "" : ", ") + c.name;
    }
    return s;
}

bool same_car(const CalibratedVehicle& a, const CalibratedVehicle& b) {
    return a.model == b.model && a.parameters == b.parameters && a.has_covariance == b.has_covariance && a.min_acc_speed == b.min_acc_speed &&
           (!a.has_covariance || a.covariance == b.covariance);
}

}  // namespace

bool names_a_file(const std::string& item) {
    struct stat st {};
    return ends_with(item, ".csv") || ends_with(item, ".json") || ::stat(item.c_str(), &st) == 0;
}

std::vector<CalibratedVehicle> read_calibration_json(const std::string& text, const std::string& source) {
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        throw std::invalid_argument(source + ": not JSON (" + detail::escaped(e.what(), 120) + "): expected what `calibrate --format json` writes");
    }
    const nlohmann::json* result = &j;
    if (j.is_object() && j.contains("command")) {
        if (!j["command"].is_string() || j["command"].get<std::string>() != "calibrate")
            throw std::invalid_argument(source + ": the output of `" + (j["command"].is_string() ? j["command"].get<std::string>() : std::string("?")) +
                                        "`: expected what `calibrate --format json` writes (a car table is a CSV file)");
        result = &j["result"];
    }
    if (!result->is_object() || !result->contains("fits") || !(*result)["fits"].is_array())
        throw std::invalid_argument(source + ": no \"fits\": expected what `calibrate --format json` writes");
    static const char* names[] = {"k1", "k2", "th", "tau", "eta"};
    std::vector<CalibratedVehicle> out;
    const nlohmann::json& fits = (*result)["fits"];
    for (std::size_t i = 0; i < fits.size(); ++i) {
        const nlohmann::json& f = fits[i];
        const std::string where = source + ": fit " + std::to_string(i + 1);
        if (!f.is_object() || !f.contains("name") || !f["name"].is_string()) throw std::invalid_argument(where + ": no name");
        CalibratedVehicle v;
        v.name = f["name"].get<std::string>();
        if (v.name.empty() || detail::has_control(v.name))
            throw std::invalid_argument(where + ": name " + detail::quoted(v.name) + ": expected a non-empty name without control characters");
        v.vehicle = v.name;
        v.setting.clear();
        v.make = 0;
        if (f.contains("status") && f["status"].is_string() && f["status"].get<std::string>() != "converged")
            throw std::invalid_argument(where + " (" + v.name + "): status " + detail::quoted(f["status"].get<std::string>()) +
                                        ": expected a converged fit (its parameters are not an estimate)");
        for (const char* n : names) {
            if (!f.contains(n) || !f[n].is_number()) throw std::invalid_argument(where + " (" + v.name + "): no number " + n);
            v.parameters[n] = f[n].get<double>();
        }
        if (f.contains("covariance") && f["covariance"].is_array() && f["covariance"].size() == 5) {
            bool ok = true;
            for (int a = 0; a < 5 && ok; ++a) {
                const auto& row = f["covariance"][static_cast<std::size_t>(a)];
                if (!row.is_array() || row.size() != 5) ok = false;
                for (int b = 0; b < 5 && ok; ++b) {
                    if (!row[static_cast<std::size_t>(b)].is_number()) ok = false;
                    else v.covariance(a, b) = row[static_cast<std::size_t>(b)].get<double>();
                }
            }
            if (!ok) throw std::invalid_argument(where + " (" + v.name + "): the covariance is not a 5 x 5 matrix of numbers");
            for (int a = 0; a < 5; ++a)
                if (!(v.covariance(a, a) >= 0.0)) throw std::invalid_argument(where + " (" + v.name + "): a negative variance of " + names[a]);
            if (!(v.covariance.cwiseAbs().maxCoeff() <= kMaxCovarianceEntry))
                throw std::invalid_argument(where + " (" + v.name + "): a covariance entry of magnitude " + detail::significant(v.covariance.cwiseAbs().maxCoeff(), 6) +
                                            ": expected at most 1e6 (a standard deviation of 1000)");
            v.has_covariance = true;
        }
        const nlohmann::json* bounds = f.contains("bounds") ? &f["bounds"] : result->contains("bounds") ? &(*result)["bounds"] : nullptr;
        if (bounds && bounds->is_object())
            for (const char* n : names)
                if (bounds->contains(n)) {
                    const auto& b = (*bounds)[n];
                    if (!b.is_array() || b.size() != 2 || !b[0].is_number() || !b[1].is_number() || !(b[0].get<double>() <= b[1].get<double>()))
                        throw std::invalid_argument(where + ": the bounds of " + n + ": expected [lower, upper]");
                    v.bounds.push_back({n, b[0].get<double>(), b[1].get<double>()});
                }
        try {
            (void)complete_car_parameters("ovrv", v.parameters);  // the law's ranges checked
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument(where + " (" + v.name + "): " + e.what());
        }
        out.push_back(v);
    }
    if (out.empty()) throw std::invalid_argument(source + ": no fits");
    return distinct_cars(out);
}

std::vector<CalibratedVehicle> read_cars(const std::string& list, std::size_t max_cars, const std::string& base_dir, const CarTables* tables) {
    if (trim(list).empty()) throw std::invalid_argument("an empty car list: expected cars separated by commas (A_min, FILE.csv, FILE.csv:NAME, MODEL:NAME=VALUE,...)");
    std::vector<CalibratedVehicle> out;
    for (const Item& item : split_items(list)) {
        std::vector<CalibratedVehicle> unit;
        if (tables && tables->count(item.text)) {
            const std::string& text = tables->at(item.text);
            const std::string t = trim(text.substr(0, std::min<std::size_t>(text.size(), 64)));
            unit = !t.empty() && t[0] == '{' ? read_calibration_json(text, item.text) : read_car_table(text, item.text);
        } else if (starts_inline(item.text)) {
            unit.push_back(inline_car(item.text));
        } else {
            std::string file = item.text, name;
            for (const char* ext : {".csv:", ".json:"}) {
                const auto at = item.text.rfind(ext);
                if (at != std::string::npos && !names_a_file(item.text)) {
                    file = item.text.substr(0, at + std::string(ext).size() - 1);
                    name = trim(item.text.substr(at + std::string(ext).size()));
                    break;
                }
            }
            if (names_a_file(file)) {
                struct stat st {};
                if (!base_dir.empty() && !file.empty() && file[0] != '/' && ::stat(file.c_str(), &st) != 0 &&
                    ::stat((base_dir + "/" + file).c_str(), &st) == 0)
                    file = base_dir + "/" + file;
                std::vector<CalibratedVehicle> cars = read_file_cars(file);
                if (!name.empty()) {
                    auto it = std::find_if(cars.begin(), cars.end(), [&](const CalibratedVehicle& c) { return c.name == name; });
                    if (it == cars.end())
                        throw std::invalid_argument("car " + detail::quoted(item.text) + ": no car named " + detail::quoted(name) + " in " + file + " (it has " +
                                                    names_of(cars) + ")");
                    unit.push_back(*it);
                } else {
                    unit = std::move(cars);
                }
            } else {
                bool found = false;
                for (const auto& v : paper_calibration_table())
                    if (v.name == item.text) {
                        unit.push_back(v);
                        found = true;
                    }
                if (!found)
                    throw std::invalid_argument("car " + detail::quoted(item.text) +
                                                ": expected a setting of the paper's table (A_min .. G_max), a file (FILE.csv, FILE.csv:NAME, FILE.json) or "
                                                "a car of a law (MODEL:NAME=VALUE,..., e.g. ovrv:k1=0.1,k2=0.3,th=1.5,tau=0.5)");
            }
        }
        const double total = static_cast<double>(out.size()) + static_cast<double>(unit.size()) * static_cast<double>(item.repeat);
        if (total > static_cast<double>(max_cars))
            throw std::invalid_argument("car list " + detail::quoted(list) + ": more than " + std::to_string(max_cars) + " cars");
        for (long r = 0; r < item.repeat; ++r) out.insert(out.end(), unit.begin(), unit.end());
    }
    (void)distinct_cars(out);  // a name given twice with other values is refused
    return out;
}

std::vector<CalibratedVehicle> distinct_cars(const std::vector<CalibratedVehicle>& cars) {
    std::vector<CalibratedVehicle> out;
    std::map<std::string, std::size_t> index;
    for (const auto& c : cars) {
        const auto it = index.find(c.name);
        if (it == index.end()) {
            index.emplace(c.name, out.size());
            out.push_back(c);
        } else if (!same_car(out[it->second], c)) {
            throw std::invalid_argument("car name " + detail::quoted(c.name) + " names two different cars: expected distinct names");
        }
    }
    return out;
}

Fleet to_fleet(const std::vector<CalibratedVehicle>& cars) {
    Fleet out;
    out.reserve(cars.size());
    for (const auto& c : cars) out.push_back({c.name, c.model, c.parameters});
    return out;
}

void require_ovrv(const std::vector<CalibratedVehicle>& cars, const std::string& what) {
    for (const auto& c : cars)
        if (c.model != "ovrv")
            throw std::invalid_argument(what + " takes cars of the paper's law (ovrv); car " + detail::quoted(c.name) + " has model " + c.model);
}

}  // namespace ddemap
