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
