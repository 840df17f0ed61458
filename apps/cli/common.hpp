#pragma once
// Shared pieces of the command-line front: strict number parsing, the shared flag groups
// (model flags, --ring, --format, --out) and the exit codes. Parsing and formatting only.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <initializer_list>
#include <iostream>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "ddemap/io/json.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "format.hpp"

namespace ddemap::cli {

/// Exit codes (README "Exit codes").
enum ExitCode : int {
    exit_ok = 0,             ///< success
    exit_bad_input = 2,      ///< bad input: one line on stderr, nothing on stdout, nothing written
    exit_internal = 3,       ///< internal error (a bug)
    exit_not_converged = 4,  ///< the output is printed (and written), but a computation did not converge: undecided
    exit_write_failed = 5,   ///< the computation ran, but a file could not be written (none is left half-written)
};

struct BadInput : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// The whole file as text (io read_text_file: a byte-order mark and CRLF line ends accepted); a
/// folder or a file that cannot be opened is bad input naming the flag and path.
std::string read_input_file(const std::string& flag, const std::string& path);
double parse_number(const std::string& flag, const std::string& text);
long parse_integer(const std::string& flag, const std::string& text, long lo, long hi, const std::string& what);

/// 0 when `s` converged, else exit_not_converged.
inline int exit_code(Status s) { return s == Status::Converged ? exit_ok : exit_not_converged; }

/// The verdict word of the human tables: STABLE, MARGINAL, UNSTABLE or UNDECIDED.
inline std::string verdict_word(Verdict v) {
    std::string w = to_string(v);
    for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return w;
}

/// When `s` is not converged, says why on stderr ("ddemap: WHAT undecided (status): reason")
/// and returns exit_not_converged; else exit_ok.
inline int report_undecided(Status s, const std::string& what, const std::string& reason) {
    if (s == Status::Converged) return exit_ok;
    std::string line = reason;
    for (char& c : line)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';  // one line
    std::cerr << "ddemap: " << what << " undecided (" << to_string(s) << "): " << line << "\n";
    return exit_not_converged;
}

/// --solver NAME to the library's root method: auto, dense, sparse (shift_invert) or product
/// (contour); the library's own names are accepted too. BadInput otherwise.
std::string root_method(const std::string& solver);
/// A method in --solver words (shift_invert -> sparse, contour -> product).
std::string solver_name(const std::string& method);

/// The built-in model names from the model table, joined ("ovrv, idm or ccc").
std::string model_list(const std::string& separator, const std::string& last_separator);

/// Sets the value kind shown in --help (NUMBER, INTEGER, FILE, PREFIX, ...) of every flag of
/// `app` still shown as TEXT, from one table of the shared flag names.
void annotate_option_types(CLI::App& app, const std::string& command);

/// The model flags: --model and one flag per model parameter (generated from the model table:
/// unit, required or default per model).
struct ModelArgs {
    std::string model = "ovrv";
    std::map<std::string, std::string> raw;  // parameter name -> text, only those given

    void add_to(CLI::App& app);
    bool given() const { return !raw.empty() || model != "ovrv"; }
    /// Fixed values and swept axes ("LO:HI[:COUNT]") for sweeps.
    void split(ParameterMap& fixed, std::vector<std::pair<std::string, std::string>>& axes) const;
    void check_model() const;
    std::unique_ptr<CarModel> build() const;
};

/// {"model": name, "parameters": {...}}
JsonObject model_inputs(const CarModel& m);

/// --ring N|inf: the number of cars of a ring (N >= 2), or inf.
struct RingArg {
    std::string text;
    CLI::Option* option = nullptr;
    /// `fallback`: the value when not given ("" = none).
    void add_to(CLI::App& app, const std::string& fallback, const std::string& help);
    bool given() const { return option && option->count() > 0; }
    bool empty() const { return text.empty(); }
    /// N, or 0 for inf (when `allow_inf`); N at most `max_cars`.
    int parse(bool allow_inf = true, int max_cars = 1000000) const;
};

enum class Format { Table, Json, Csv };

/// --format table|json|csv; a command accepts the formats that make sense for it.
struct FormatArg {
    std::string text = "table";
    std::vector<Format> accepted{Format::Table, Format::Json, Format::Csv};
    void add_to(CLI::App& app, std::initializer_list<Format> accepted = {Format::Table, Format::Json, Format::Csv});
    Format parse() const;
};

/// --out PREFIX: the prefix of every file the command writes (PREFIX.csv, PREFIX.svg, ...).
/// A trailing .csv, .json or .svg is dropped (so --out curves.csv writes curves.csv); a folder
/// (an existing one, or a trailing '/') means FOLDER/<command>. Missing folders are created.
struct OutArg {
    std::string text;
    CLI::Option* option = nullptr;
    void add_to(CLI::App& app, const std::string& writes, bool required);
    /// True when --out was given, even as '' (which prepare() refuses: never "nothing written, exit 0").
    bool given() const { return !text.empty() || (option && option->count() > 0); }
    /// Resolves the prefix and prepares its folder (created as needed, must be writable) and
    /// checks PREFIX + each suffix (not a folder, writable; check_output_file): bad input
    /// otherwise, before any work.
    std::string prepare(const std::string& command, std::initializer_list<const char*> suffixes = {".csv", ".json", ".svg"}) const;
};

/// A file the command writes under its own flag (e.g. classify --svg FILE), checked before any
/// work (check_output_file): bad input naming the flag otherwise. Returns `path`.
std::string output_file(const std::string& flag, const std::string& path);

/// A command's cars, given the same way everywhere (io/cars.hpp): built-in names (A_min), every
/// car of a table or fit file (FILE.csv, FILE.json), one car of it (FILE.csv:NAME), inline cars
/// (ovrv:k1=0.1,k2=0.3,th=1.5,tau=0.5), each with *K, joined by commas; in order, expanded.
std::vector<CalibratedVehicle> cars_argument(const std::string& flag, const std::string& list);
/// The car syntax in a flag's help: "CARS: ..." (the same words in every command).
inline const char* cars_help() {
    return "built-in names (A_min .. G_max), FILE.csv (every car of a car table: name/vehicle/model, count, parameters; or what calibrate "
           "writes, CSV or JSON), FILE.csv:NAME (one car of it), MODEL:k1=..,k2=..,... (a car of a law: ovrv, idm, ccc; name=NAME names it), "
           "each with *K to repeat, joined by commas";
}
/// The same as a fleet; `cars` > 0 repeats the cars to that many (the last repetition cut short).
Fleet fleet_argument(const std::string& flag, const std::string& list, int cars = 0);
/// The same, every car of the paper's law (ovrv): classify, simulate, growth.
std::vector<CalibratedVehicle> vehicles_argument(const std::string& flag, const std::string& list);
/// Exactly one distinct car (mix --x/--y).
FleetCar car_argument(const std::string& flag, const std::string& list);

/// Prints the envelope of a command's JSON output.
void print_json(const JsonEnvelope& e);
/// The command's output on stdout in the chosen format: the JSON envelope, the CSV text, or
/// the human table (print_table writes it).
void print_output(Format format, const JsonEnvelope& e, const std::string& csv, const std::function<void()>& print_table);

}  // namespace ddemap::cli
