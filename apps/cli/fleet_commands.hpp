#pragma once
// Mixed fleets on the command line: roots --fleet / --fleet-pattern, and mix.
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

namespace ddemap::cli {

/// The fleet options of `roots`.
struct FleetArgs {
    std::string fleet, pattern, cars, length, solver = "auto", degree = "0";
    void add_to(CLI::App* roots);
    bool given() const { return !fleet.empty() || !pattern.empty(); }
};

/// --solver NAME to the library's root method: auto, dense, sparse (shift_invert) or product
/// (contour); the library's own names are accepted too. BadInput otherwise.
std::string root_method(const std::string& solver);
/// The method a result used, in --solver words (shift_invert -> sparse, contour -> product).
std::string solver_name(const std::string& method);

/// roots --fleet/--fleet-pattern: prints the result in `format` (table, json or csv).
void run_fleet_roots(const FleetArgs& args, const std::string& speed, const std::string& count, const std::string& format);

class MixCommand {
public:
    void add_to(CLI::App& app);
    bool run() const;

private:
    struct Impl;
    std::shared_ptr<Impl> m;
};

}  // namespace ddemap::cli
