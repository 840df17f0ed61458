#pragma once
// Shared pieces of the command-line front: strict number parsing, the model options and the
// output formats. Parsing and formatting only.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "ddemap/traffic/model.hpp"
#include "format.hpp"

namespace ddemap::cli {

using json = nlohmann::ordered_json;

struct BadInput : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// The whole file as text; a file that cannot be opened is bad input naming the flag and path.
inline std::string read_input_file(const std::string& flag, const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadInput(flag + " = '" + path + "': cannot open the file");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

inline double parse_number(const std::string& flag, const std::string& text) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s, &end);
    if (text.empty() || end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
        throw BadInput(flag + " = '" + text + "': expected a finite number");
    }
    return v;
}

inline long parse_integer(const std::string& flag, const std::string& text, long lo, long hi, const std::string& what) {
    const char* s = text.c_str();
    char* end = nullptr;
    errno = 0;
    const long v = std::strtol(s, &end, 10);
    if (text.empty() || end == s || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
        throw BadInput(flag + " = '" + text + "': expected " + what);
    }
    return v;
}

/// --ring N|inf -> N (0 for infinity)
inline int parse_ring(const std::string& text) {
    if (text == "inf" || text == "infinity") return 0;
    return static_cast<int>(parse_integer("--ring", text, 2, 1000000, "an integer N >= 2 (at most 1000000) or 'inf'"));
}

/// The model options shared by the analysis commands.
struct ModelArgs {
    std::string model = "ovrv";
    std::map<std::string, std::string> raw;  // flag name -> text, only those given

    void add_to(CLI::App* app) {
        app->add_option("--model", model, "car-following model: ovrv (paper eq. 3), idm (intelligent driver model) or ccc (connected cruise control: ovrv + the car two ahead)")
            ->capture_default_str();
        struct P {
            const char* name;
            const char* help;
        };
        static const P params[] = {
            {"k1", "OVRV gain on the gap error [1/s^2]"},
            {"k2", "OVRV gain on the speed difference [1/s]"},
            {"th", "time headway [s]"},
            {"tau", "sensing delay [s] (0 gives the ODE)"},
            {"eta", "jam gap [m] (ovrv default 10, idm default 2; does not enter the linearisation of ovrv)"},
            {"speed", "equilibrium speed [m/s] (idm linearises about it; default 20; for a fleet: the common speed)"},
            {"a", "IDM maximum acceleration [m/s^2] (default 1)"},
            {"b", "IDM comfortable deceleration [m/s^2] (default 1.5)"},
            {"v0", "IDM desired speed [m/s] (default 33.3)"},
            {"delta", "IDM acceleration exponent [1] (default 4)"},
            {"k3", "CCC gain on the speed difference to the car two ahead [1/s]"},
            {"tau2", "CCC delay of the V2V signal from the car two ahead [s]"},
        };
        for (const auto& p : params) {
            const std::string name = p.name;
            app->add_option_function<std::string>(
                "--" + name, [this, name](const std::string& v) { raw[name] = v; }, p.help);
        }
    }

    /// Fixed values and swept axes ("LO:HI:COUNT") for sweeps.
    void split(ParameterMap& fixed, std::vector<std::pair<std::string, std::string>>& axes) const {
        for (const auto& [name, text] : raw) {
            if (text.find(':') != std::string::npos) {
                axes.emplace_back(name, text);
            } else {
                fixed[name] = parse_number("--" + name, text);
            }
        }
        check_model();
    }

    void check_model() const {
        const auto names = model_names();
        if (std::find(names.begin(), names.end(), model) == names.end()) {
            throw BadInput("--model = '" + model + "': expected one of ovrv, idm");
        }
    }

    std::unique_ptr<CarModel> build() const {
        ParameterMap values;
        for (const auto& [name, text] : raw) values[name] = parse_number("--" + name, text);
        const auto names = model_names();
        if (std::find(names.begin(), names.end(), model) == names.end()) {
            throw BadInput("--model = '" + model + "': expected one of ovrv, idm");
        }
        return make_model(model, values);
    }
};

/// The folder of an output path must exist and be writable (checked before any work).
inline void check_output(const std::string& flag, const std::string& path) {
    if (path.empty()) throw BadInput(flag + " is required");
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    if (access(dir.c_str(), W_OK) != 0) {
        throw BadInput(flag + " = '" + path + "': the folder '" + dir + "' does not exist or is not writable");
    }
}

enum class Format { Table, Json, Csv };

inline Format parse_format(const std::string& text) {
    if (text == "table") return Format::Table;
    if (text == "json") return Format::Json;
    if (text == "csv") return Format::Csv;
    throw BadInput("--format = '" + text + "': expected table, json or csv");
}

/// A finite double for JSON, or null (never NaN or inf in the output).
inline json num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

inline json parameters_json(const CarModel& m) {
    json p = json::object();
    for (const auto& [k, v] : m.parameters()) p[k] = v;
    return p;
}

inline std::string describe(const CarModel& m) {
    std::ostringstream os;
    os << m.name();
    for (const auto& [k, v] : m.parameters()) os << " " << k << "=" << rounded(v, 6);
    return os.str();
}

inline std::string ring_name(int cars) { return cars == 0 ? "inf" : std::to_string(cars); }

}  // namespace ddemap::cli
