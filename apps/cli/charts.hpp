#pragma once
// The chart commands of the command-line front: sweep, boundary, chart, paper.
#include <CLI/CLI.hpp>

namespace ddemap::cli {

/// Registers the commands on `app`; run() executes the one that was parsed (false if none).
class ChartCommands {
public:
    void add_to(CLI::App& app);
    bool run() const;

private:
    struct Impl;
    std::shared_ptr<Impl> m;
};

}  // namespace ddemap::cli
