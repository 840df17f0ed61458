// ddemap: a thin command-line front. It parses, calls the library, formats.
// main builds the app from the command table, runs the parsed command and maps exceptions to
// the exit codes of common.hpp (README "Exit codes").
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <streambuf>

#include <unistd.h>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "limits.hpp"
#include "ddemap/io/svg.hpp"

using namespace ddemap::cli;

namespace {
/// A message on one line: line breaks and other control characters become spaces.
std::string one_line(std::string s) {
    for (auto& c : s)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
    return s;
}
/// The buffer of std::cout: writes to file descriptor 1 and keeps the reason of the first failed
/// write (a full disk, /dev/full, a closed pipe), so that it can be reported at the end.
class StdoutBuffer : public std::streambuf {
public:
    StdoutBuffer() { setp(m_buf, m_buf + sizeof m_buf); }
    int error() const { return m_error; }

protected:
    int_type overflow(int_type c) override {
        if (!flush_buffer()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    int sync() override { return flush_buffer() ? 0 : -1; }
    /// Line by line: a write that ends a line goes out at once.
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        std::streamsize done = 0;
        while (done < n) {
            if (pptr() == epptr() && !flush_buffer()) return done;
            const std::streamsize k = std::min<std::streamsize>(n - done, epptr() - pptr());
            traits_type::copy(pptr(), s + done, static_cast<std::size_t>(k));
            pbump(static_cast<int>(k));
            done += k;
        }
        if (n > 0 && traits_type::find(s, static_cast<std::size_t>(n), '\n') != nullptr && !flush_buffer()) return n;
        return n;
    }

private:
    bool flush_buffer() {
        const char* p = pbase();
        while (p < pptr()) {
            const ssize_t n = ::write(1, p, static_cast<std::size_t>(pptr() - p));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                if (m_error == 0) m_error = n < 0 ? errno : EIO;
                setp(m_buf, m_buf + sizeof m_buf);
                return false;
            }
            p += n;
        }
        setp(m_buf, m_buf + sizeof m_buf);
        return true;
    }
    char m_buf[1 << 16];
    int m_error = 0;
};

/// Never destroyed: the standard streams are flushed into it at exit.
StdoutBuffer& stdout_buffer() {
    static StdoutBuffer* buffer = new StdoutBuffer;
    return *buffer;
}

/// `code`, unless stdout could not be written: then the error with the system's reason and
/// exit_write_failed.
int finish_stdout(int code) {
    std::cout.flush();
    if (stdout_buffer().error() != 0 || !std::cout) {
        std::cerr << "ddemap: error: cannot write standard output: " << std::strerror(stdout_buffer().error() != 0 ? stdout_buffer().error() : EIO) << "\n";
        return exit_write_failed;
    }
    return code;
}
}  // namespace

namespace {
/// Edit distance with transpositions (optimal string alignment; for "did you mean": --tua is
/// one step from --tau).
std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}

/// " (did you mean --tau?)" for the first --flag of the command line that the command does not
/// have and that is close to one it has; empty otherwise.
std::string did_you_mean(const CLI::App* sub, int argc, char** argv) {
    std::vector<std::string> names;
    for (const CLI::Option* o : sub->get_options())
        for (const std::string& n : o->get_lnames()) names.push_back("--" + n);
    for (int i = 2; i < argc; ++i) {
        std::string a = argv[i];
        if (a.rfind("--", 0) != 0 || a.size() < 3) continue;
        a = a.substr(0, a.find('='));
        if (std::find(names.begin(), names.end(), a) != names.end()) continue;
        std::string best;
        std::size_t best_d = std::string::npos;
        for (const std::string& n : names) {
            const std::size_t d = edit_distance(a, n);
            if (d < best_d) {
                best_d = d;
                best = n;
            }
        }
        if (!best.empty() && best_d <= std::max<std::size_t>(2, (a.size() - 2) / 3)) return " (did you mean " + best + "?)";
        return "";
    }
    return "";
}
}  // namespace

int main(int argc, char** argv) {
    std::cout.rdbuf(&stdout_buffer());
    CLI::App app{"ddemap: stability of delay differential car-following models.\n"
                 "Rightmost characteristic roots of rings of cars, string stability verdicts."};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(DDEMAP_VERSION));
    app.footer("Exit codes: 0 success, 2 bad input, 3 internal error, 4 not converged (undecided), 5 a file could not be written; "
               "Ctrl-C ends a command by SIGINT (130 in a shell), its files as before.");
    std::vector<std::pair<CLI::App*, const Command*>> commands;
    for (const Command& c : command_table()) {
        CLI::App* sub = app.add_subcommand(c.name, c.description);
        c.add_flags(*sub);
        annotate_option_types(*sub, c.name);
        commands.emplace_back(sub, &c);
    }
    // a first word that is neither a flag nor a command: name it and list the commands
    std::string command_names;
    for (const Command& c : command_table()) command_names += (command_names.empty() ? "" : ", ") + std::string(c.name);
    if (argc > 1 && argv[1][0] != '-') {
        bool known = false;
        for (const Command& c : command_table()) known = known || std::strcmp(c.name, argv[1]) == 0;
        if (!known) {
            std::cerr << "ddemap: error: unknown command '" << one_line(argv[1]) << "': expected one of " << command_names << " (see ddemap --help)\n";
            return exit_bad_input;
        }
    }
    if (argc == 1) {
        std::cerr << "ddemap: error: expected a command: one of " << command_names << " (see ddemap --help)\n";
        return exit_bad_input;
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
        for (const auto& [sub, command] : commands)
            if (std::strcmp(command->name, argv[1]) == 0) {
                std::cerr << "ddemap: error: " << one_line(e.what()) << did_you_mean(sub, argc, argv) << " (see ddemap " << command->name << " --help)\n";
                return exit_bad_input;
            }
        std::cerr << "ddemap: error: " << one_line(e.what()) << " (see ddemap --help)\n";
        return exit_bad_input;
    }
    // a value given as '' (`--ring ''`, `--cars ''` from an empty shell variable) is bad input,
    // never taken as absent
    for (const auto& [sub, command] : commands) {
        if (!sub->parsed()) continue;
        for (const CLI::Option* opt : sub->get_options()) {
            // absent, a flag, or --out (its own message: an output prefix)
            if (opt->count() == 0 || opt->get_expected_min() == 0 || opt->check_lname("out")) continue;
            for (const std::string& r : opt->results())
                if (r.empty()) {
                    std::cerr << "ddemap: error: " << (opt->get_lnames().empty() ? opt->get_name() : "--" + opt->get_lnames().front()) << " = '': expected a value (see ddemap " << command->name << " --help)\n";
                    return exit_bad_input;
                }
        }
    }
    try {
        // test hook: the exit code of an internal error (tests/cli/test_cli.sh)
        const char* fault = std::getenv("DDEMAP_TEST_FAULT");
        if (fault && std::strcmp(fault, "internal") == 0) throw std::logic_error("DDEMAP_TEST_FAULT=internal");
        for (const auto& [sub, command] : commands)
            if (sub->parsed()) {
                const int code = command->run();
                ddemap::cli::flush_notes();  // notes about the input not yet shown (none on an error)
                return finish_stdout(code);
            }
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
