#pragma once
// The simulation commands of the command-line front: simulate, growth, calibrate.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "ddemap/study/growth.hpp"

namespace ddemap::cli {

class SimCommands {
public:
    void add_to(CLI::App& app);
    bool run() const;

private:
    struct Impl;
    std::shared_ptr<Impl> m;
};

/// The growth study's table (stdout), CSV and figure (for `paper`).
std::string growth_table(const std::vector<GrowthResult>& g);
std::string growth_csv(const std::vector<GrowthResult>& g);
std::string growth_svg(const std::vector<GrowthResult>& g, const std::string& lead_name);

}  // namespace ddemap::cli
