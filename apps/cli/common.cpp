#include <cctype>
#include "common.hpp"
#include "limits.hpp"

#include <cerrno>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include <unistd.h>

#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/io/files.hpp"
#include "ddemap/io/cars.hpp"

namespace ddemap::cli {

std::string read_input_file(const std::string& flag, const std::string& path) {
    try {
        return read_text_file(path);
    } catch (const std::invalid_argument& e) {
        throw BadInput(flag + " = " + e.what());
    }
}

double parse_number(const std::string& flag, const std::string& text) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s, &end);
    // ERANGE on underflow (1e-310: a subnormal or 0) is a finite number, judged by the flag's range
    const bool overflow = errno == ERANGE && !(std::abs(v) <= std::numeric_limits<double>::min());
    if (text.empty() || end == s || *end != '\0' || overflow || !std::isfinite(v)) {
        throw BadInput(flag + " = '" + text + "': expected a finite number" + (overflow ? " (beyond the range of doubles, about 1.8e308)" : ""));
    }
    return v;
}

long parse_integer(const std::string& flag, const std::string& text, long lo, long hi, const std::string& what) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(s, &end, 10);
    if (text.empty() || end == s || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        throw BadInput(flag + " = '" + text + "': expected " + what);
    }
    return v;
}

namespace {
std::string detail_number(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%g", v);
    return b;
}
}  // namespace

std::string model_list(const std::string& separator, const std::string& last_separator) {
    const auto names = model_names();
    std::string list;
    for (std::size_t i = 0; i < names.size(); ++i) list += (i == 0 ? "" : i + 1 == names.size() ? last_separator : separator) + names[i];
    return list;
}

void annotate_option_types(CLI::App& app, const std::string& command) {
    // the kind of value of every flag that is not a model parameter (those are NUMBER, set where
    // they are added); sweeps and boundaries take ranges for the model parameters
    static const std::map<std::string, std::string> kinds = {
        {"count", "INTEGER"}, {"degree", "INTEGER"}, {"draws", "INTEGER"}, {"followers", "INTEGER"}, {"seed", "INTEGER"},
        {"seed-grid", "INTEGER"}, {"gap-weight", "NUMBER"}, {"output-dt", "NUMBER"}, {"step", "NUMBER"}, {"t-end", "NUMBER"},
        {"length", "NUMBER"}, {"fleet", "FILE|PATTERN"}, {"fleet-pattern", "FILE|PATTERN"}, {"cars", "N"}, {"lead", "FILE"},
        {"system", "FILE"}, {"svg", "FILE"}, {"lead-profile", "NAME"}, {"on-event", "stop|continue"}, {"out", "PREFIX"},
        {"p", "LO:HI:COUNT"}, {"ring", "N|inf"}, {"solver", "auto|product|dense|sparse"}, {"train", "T0:T1"},
        {"bounds", "NAME=LO:HI,..."}, {"speed", "NUMBER"}, {"model", "NAME"}, {"x", "NAME"}, {"y", "CAR"}, {"car", "NAME"}, {"runs", "FILE"},
        {"data-dir", "FOLDER"}, {"report", "FOLDER"}, {"par", "NAME"}, {"from", "NUMBER"}, {"to", "NUMBER"},
        {"samples", "INTEGER"}, {"ring-samples", "INTEGER"}, {"max-points", "INTEGER"}, {"alpha", "NUMBER"},
        {"tau", "NUMBER"}, {"v0", "NUMBER"}, {"h-st", "NUMBER"}, {"headway", "NUMBER"}, {"a", "NUMBER"}, {"b", "NUMBER"},
        {"delta", "NUMBER"}, {"th", "NUMBER"}, {"eta", "NUMBER"}, {"gap", "NUMBER"}, {"k1", "NUMBER"}, {"k2", "NUMBER"}, {"a-max", "NUMBER"},
        {"a-min", "NUMBER"}};
    for (CLI::Option* o : app.get_options()) {
        if (o->get_lnames().empty()) {  // a positional argument: a file
            if (o->get_type_name() == "TEXT") o->type_name("FILE");
            continue;
        }
        const std::string name = o->get_lnames().front();
        if (name == "ring" && (command == "equilibria" || command == "hopf" || command == "orbits")) {  // --model ov|idm: finite rings only
            o->type_name("N");
            continue;
        }
        if (o->get_group() == "Model" && name != "model" && (command == "sweep" || command == "boundary"))
            o->type_name(command == "sweep" ? "NUMBER|LO:HI:COUNT" : "NUMBER|LO:HI");
        if (o->get_type_name() != "TEXT") continue;
        const auto k = kinds.find(name);
        if (k == kinds.end()) continue;
        if (command == "mix" && (name == "ring" || name == "x")) o->type_name(name == "ring" ? "N" : "CAR");  // a finite ring; a car
        else o->type_name(k->second);
    }
}

namespace {
/// The help of one model flag, from the model table: what it is, its unit, and per model
/// whether it is required or its default ("required for ovrv, ccc; idm: default 2").
std::string parameter_help(const std::string& name) {
    std::string description, unit, required, defaults, absent;
    for (const auto& m : model_names()) {
        bool found = false;
        for (const auto& p : model_parameters(m)) {
            if (p.name != name) continue;
            found = true;
            if (description.empty()) {
                description = p.description;
                unit = p.unit;
            }
            if (p.required) required += (required.empty() ? "" : ", ") + m;
            else defaults += (defaults.empty() ? "" : ", ") + m + " " + detail_number(p.default_value);
        }
        if (!found) absent += (absent.empty() ? "" : ", ") + m;
    }
    if (name == "speed") description = "equilibrium speed (idm is linearised about it; ovrv and ccc do not depend on it)";
    std::string h = description + " [" + unit + "]";
    if (!required.empty()) h += "; required for " + required;
    if (!defaults.empty()) h += "; default: " + defaults;
    if (!absent.empty()) h += "; not a parameter of " + absent;
    if (name == "speed") h += " (for a fleet: the common speed)";
    return h;
}
}  // namespace

void ModelArgs::add_to(CLI::App& app) {
    app.add_option("--model", model, "car-following model: " + model_list(", ", " or ") + " (the model flags below say which parameters each needs)")
        ->capture_default_str()
        ->type_name(model_list("|", "|"))
        ->group("Model");
    std::vector<std::string> names;  // every parameter of every model, in the order of first appearance
    for (const auto& m : model_names())
        for (const auto& p : model_parameters(m))
            if (std::find(names.begin(), names.end(), p.name) == names.end()) names.push_back(p.name);
    for (const auto& name : names) {
        app.add_option_function<std::string>("--" + name, [this, name](const std::string& v) { raw[name] = v; }, parameter_help(name))
            ->type_name("NUMBER")
            ->group("Model");
    }
}

void ModelArgs::split(ParameterMap& fixed, std::vector<std::pair<std::string, std::string>>& axes) const {
    for (const auto& [name, text] : raw) {
        if (text.find(':') != std::string::npos) axes.emplace_back(name, text);
        else fixed[name] = parse_number("--" + name, text);
    }
    check_model();
}

void ModelArgs::check_model() const {
    const auto names = model_names();
    if (std::find(names.begin(), names.end(), model) == names.end()) throw BadInput("--model = '" + model + "': expected one of " + model_list(", ", ", "));
}

std::unique_ptr<CarModel> ModelArgs::build() const {
    ParameterMap values;
    for (const auto& [name, text] : raw) values[name] = parse_number("--" + name, text);
    check_model();
    return make_model(model, values);
}

JsonObject model_inputs(const CarModel& m) {
    JsonObject o;
    o.string("model", m.name()).json("parameters", json_parameters(m.parameters()));
    return o;
}

void RingArg::add_to(CLI::App& app, const std::string& fallback, const std::string& help) {
    text = fallback;
    option = app.add_option("--ring", text, help);
    if (!fallback.empty()) option->capture_default_str();
}

int RingArg::parse(bool allow_inf, int max_cars) const {
    std::string lower = text;
    for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (allow_inf && (lower == "inf" || lower == "infinity")) return 0;
    const std::string most = "(at most " + std::to_string(max_cars) + ")";
    return static_cast<int>(parse_integer("--ring", text, 2, max_cars,
                                          allow_inf ? "an integer N >= 2 " + most + " or 'inf'"
                                                    : "an integer N >= 2 " + most + "; this ring is finite"));
}

namespace {
const char* format_name(Format f) { return f == Format::Table ? "table" : f == Format::Json ? "json" : "csv"; }
std::string format_list(const std::vector<Format>& fs) {
    std::string s;
    for (std::size_t i = 0; i < fs.size(); ++i) s += std::string(i == 0 ? "" : i + 1 == fs.size() ? " or " : ", ") + format_name(fs[i]);
    return s;
}
}  // namespace

void FormatArg::add_to(CLI::App& app, std::initializer_list<Format> formats) {
    accepted = formats;
    app.add_option("--format", text, "output on stdout: " + format_list(accepted))->capture_default_str()->type_name([&] {
        std::string t;
        for (Format f : accepted) t += (t.empty() ? "" : "|") + std::string(format_name(f));
        return t;
    }());
}

Format FormatArg::parse() const {
    for (Format f : {Format::Table, Format::Json, Format::Csv}) {
        if (text != format_name(f)) continue;
        if (std::find(accepted.begin(), accepted.end(), f) == accepted.end())
            throw BadInput("--format = '" + text + "': this command has no " + text + " output; expected " + format_list(accepted));
        return f;
    }
    throw BadInput("--format = '" + text + "': expected " + format_list(accepted));
}

void OutArg::add_to(CLI::App& app, const std::string& writes, bool required) {
    option = app.add_option("--out", text, "output prefix PREFIX (folders created as needed): writes " + writes);
    if (required) option->required();
}

std::string OutArg::prepare(const std::string& command, std::initializer_list<const char*> suffixes) const {
    namespace fs = std::filesystem;
    if (text.empty() && option && option->count() > 0) throw BadInput("--out = '': expected an output prefix (e.g. --out results/run1)");
    if (text.empty()) throw BadInput("--out PREFIX is required");
    std::string prefix = text;
    std::error_code ec;
    if (prefix.back() == '/' || fs::is_directory(prefix, ec)) {
        if (prefix.back() != '/') prefix += '/';
        prefix += command;
    } else {
        for (const char* ext : {".csv", ".json", ".svg"}) {
            const std::string e = ext;
            if (prefix.size() > e.size() && prefix.compare(prefix.size() - e.size(), e.size(), e) == 0) {
                prefix.resize(prefix.size() - e.size());
                break;
            }
        }
    }
    const auto slash = prefix.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : prefix.substr(0, slash));
    // a regular file where a folder is needed: refused before anything is created
    for (fs::path p = fs::path(dir); !p.empty(); p = p.parent_path()) {
        if (fs::exists(p, ec) && !fs::is_directory(p, ec))
            throw BadInput("--out = '" + text + "': '" + p.string() + "' is a file, not a folder");
        if (p == p.parent_path()) break;
    }
    if (!fs::is_directory(dir, ec)) {
        fs::create_directories(dir, ec);
        if (ec || !fs::is_directory(dir))
            throw BadInput("--out = '" + text + "': the folder '" + dir + "' does not exist and cannot be created" +
                           (ec ? " (" + ec.message() + ")" : std::string()));
    }
    if (access(dir.c_str(), W_OK | X_OK) != 0) throw BadInput("--out = '" + text + "': the folder '" + dir + "' is not writable");
    for (const char* suffix : suffixes) {
        try {
            check_output_file(prefix + suffix);
        } catch (const std::invalid_argument& e) {
            throw BadInput("--out = '" + text + "': " + e.what());
        }
    }
    return prefix;
}

std::string output_file(const std::string& flag, const std::string& path) {
    if (path.empty()) throw BadInput(flag + " = '': expected a file name");
    // its folder is created as needed, as --out's is
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    std::error_code ec;
    if (!folder.empty() && !std::filesystem::exists(folder, ec)) {
        std::filesystem::create_directories(folder, ec);
        if (ec) throw BadInput(flag + " = '" + path + "': the folder '" + folder.string() + "' does not exist and cannot be created (" + ec.message() + ")");
    }
    try {
        check_output_file(path);
    } catch (const std::invalid_argument& e) {
        throw BadInput(flag + " = " + e.what());
    }
    return path;
}

std::vector<CalibratedVehicle> cars_argument(const std::string& flag, const std::string& list) {
    if (list.empty()) throw BadInput(flag + " = '': expected cars (A_min, FILE.csv, FILE.csv:NAME, MODEL:NAME=VALUE,...)");
    try {
        return read_cars(list);
    } catch (const std::invalid_argument& e) {
        throw BadInput(flag + ": " + e.what());
    }
}

Fleet fleet_argument(const std::string& flag, const std::string& list, int cars) {
    const Fleet unit = to_fleet(cars_argument(flag, list));
    if (cars <= 0) return unit;
    // the fleet repeated to N cars: never fewer than the fleet (its last cars would be dropped
    // silently); a last repetition that is cut short is said on stderr
    if (static_cast<std::size_t>(cars) < unit.size())
        throw BadInput("--ring " + std::to_string(cars) + ": fewer cars than " + flag + " has (" + std::to_string(unit.size()) +
                       "): expected at least " + std::to_string(unit.size()) + " (the fleet repeated to N cars), or no --ring for the fleet once");
    if (static_cast<std::size_t>(cars) % unit.size() != 0)
        defer_note("--ring " + std::to_string(cars) + " is not a multiple of the fleet's " + std::to_string(unit.size()) +
                   " cars: the last repetition has only its first " + std::to_string(static_cast<std::size_t>(cars) % unit.size()));
    Fleet out;
    out.reserve(static_cast<std::size_t>(cars));
    for (int i = 0; i < cars; ++i) out.push_back(unit[static_cast<std::size_t>(i) % unit.size()]);
    return out;
}

std::vector<CalibratedVehicle> vehicles_argument(const std::string& flag, const std::string& list) {
    std::vector<CalibratedVehicle> cars = cars_argument(flag, list);
    try {
        require_ovrv(cars, flag);
    } catch (const std::invalid_argument& e) {
        throw BadInput(e.what());
    }
    return cars;
}

FleetCar car_argument(const std::string& flag, const std::string& list) {
    const std::vector<CalibratedVehicle> cars = distinct_cars(cars_argument(flag, list));
    if (cars.size() != 1) {
        std::string names;
        for (const auto& c : cars) names += (names.empty() ? "" : ", ") + c.name;
        throw BadInput(flag + " = '" + list + "': " + std::to_string(cars.size()) + " different cars (" + names + "): expected one car (e.g. FILE.csv:NAME)");
    }
    return to_fleet(cars).front();
}

void print_json(const JsonEnvelope& e) { std::cout << envelope_json(e); }

void print_output(Format format, const JsonEnvelope& e, const std::string& csv, const std::function<void()>& print_table) {
    if (format == Format::Json) print_json(e);
    else if (format == Format::Csv) std::cout << csv;
    else print_table();
}

std::string root_method(const std::string& solver) {
    if (solver == "sparse") return "shift_invert";
    if (solver == "product") return "contour";
    if (solver == "auto" || solver == "dense" || solver == "shift_invert" || solver == "contour") return solver;
    throw BadInput("--solver = '" + solver + "': expected auto, dense, sparse or product");
}

std::string solver_name(const std::string& method) {
    if (method == "shift_invert") return "sparse";
    if (method == "contour") return "product";
    return method;
}

}  // namespace ddemap::cli
