#pragma once
// The command table: one entry per command (name, one-line description, the function that adds
// its flags, the function that runs it). Each command lives in its own file, <name>.cpp.
#include <vector>

#include <CLI/CLI.hpp>

namespace ddemap::cli {

struct Command {
    const char* name;
    const char* description;
    void (*add_flags)(CLI::App& app);  ///< registers the command's flags on its subcommand
    int (*run)();                      ///< runs the parsed command; returns the exit code (ExitCode)
};

const std::vector<Command>& command_table();

#define DDEMAP_COMMAND(name)        \
    void add_##name##_flags(CLI::App& app); \
    int run_##name();
DDEMAP_COMMAND(roots)
DDEMAP_COMMAND(string)
DDEMAP_COMMAND(classify)
DDEMAP_COMMAND(design)
DDEMAP_COMMAND(sweep)
DDEMAP_COMMAND(boundary)
DDEMAP_COMMAND(chart)
DDEMAP_COMMAND(paper)
DDEMAP_COMMAND(simulate)
DDEMAP_COMMAND(growth)
DDEMAP_COMMAND(calibrate)
DDEMAP_COMMAND(mix)
DDEMAP_COMMAND(equilibria)
DDEMAP_COMMAND(hopf)

DDEMAP_COMMAND(atlas)

DDEMAP_COMMAND(orbits)
DDEMAP_COMMAND(bistability)
#undef DDEMAP_COMMAND

}  // namespace ddemap::cli
