// ddemap: a thin command-line front. It parses, calls the library, formats.
// main builds the app from the command table, runs the parsed command and maps exceptions to
// the exit codes of common.hpp (README "Exit codes").
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "ddemap/io/svg.hpp"

using namespace ddemap::cli;

namespace {
/// A message on one line: line breaks and other control characters become spaces.
std::string one_line(std::string s) {
    for (auto& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
    return s;
}
}  // namespace

int main(int argc, char** argv) {
    std::cout.setf(std::ios::unitbuf);  // stdout flushed as it is written (a pipe sees each line when it is done)
    CLI::App app{"ddemap: stability of delay differential car-following models.\n"
                 "Rightmost characteristic roots of rings of cars, string stability verdicts."};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(DDEMAP_VERSION));
    app.footer("Exit codes: 0 success, 2 bad input, 3 internal error, 4 not converged (undecided), 5 a file could not be written.");
    std::vector<std::pair<CLI::App*, const Command*>> commands;
    for (const Command& c : command_table()) {
        CLI::App* sub = app.add_subcommand(c.name, c.description);
        c.add_flags(*sub);
        commands.emplace_back(sub, &c);
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << "ddemap: error: " << one_line(e.what()) << " (see ddemap --help)\n";
        return exit_bad_input;
    }
    try {
        // test hook: the exit code of an internal error (tests/cli/test_cli.sh)
        const char* fault = std::getenv("DDEMAP_TEST_FAULT");
        if (fault && std::strcmp(fault, "internal") == 0) throw std::logic_error("DDEMAP_TEST_FAULT=internal");
        for (const auto& [sub, command] : commands)
            if (sub->parsed()) return command->run();
        throw std::logic_error("no command was parsed");
    } catch (const ddemap::WriteError& e) {
        std::cerr << "ddemap: error: " << one_line(e.what()) << "\n";
        return exit_write_failed;
    } catch (const std::invalid_argument& e) {
        std::cerr << "ddemap: error: " << one_line(e.what()) << "\n";
        return exit_bad_input;
    } catch (const std::exception& e) {
        std::cerr << "ddemap: internal error: " << one_line(e.what()) << "\n";
        return exit_internal;
    }
}
