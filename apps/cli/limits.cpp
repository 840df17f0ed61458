#include "limits.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>

#include "common.hpp"

namespace ddemap::cli {

void RunFlags::add_to(CLI::App& app, bool sizes) {
    if (sizes)
        app.add_flag("--allow-large", allow_large,
                     "run even when the estimated memory (2 GB), output (100 MB) or time (10 min) is above its limit, and let a root search run past 10 min "
                     "(docs/reference/outputs.md, \"Limits and progress\")")
            ->group("Run");
    app.add_flag("--quiet", quiet, "no progress lines on stderr")->group("Run");
}

RunFlags& run_flags() {
    static RunFlags flags;
    return flags;
}

std::string human_bytes(double bytes) {
    char b[48];
    if (bytes >= 1e9) std::snprintf(b, sizeof b, "%.3g GB", bytes / 1e9);
    else if (bytes >= 1e6) std::snprintf(b, sizeof b, "%.3g MB", bytes / 1e6);
    else std::snprintf(b, sizeof b, "%.3g kB", bytes / 1e3);
    return b;
}

std::string human_seconds(double s) {
    char b[48];
    if (s >= 3600) std::snprintf(b, sizeof b, "%.3g h", s / 3600);
    else if (s >= 60) std::snprintf(b, sizeof b, "%.3g min", s / 60);
    else std::snprintf(b, sizeof b, "%.2g s", s);
    return b;
}

namespace {
double physical_memory() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? static_cast<double>(pages) * static_cast<double>(size) : 0.0;
}
}  // namespace

void check_size(const std::string& command, const std::string& what, const std::string& kind, double estimate) {
    const bool time = kind == "time";
    const double limit = kind == "memory" ? limit_memory_bytes : kind == "output" ? limit_output_bytes : limit_seconds;
    auto show = [&](double v) { return time ? human_seconds(v) : human_bytes(v); };
    const std::string noun = kind == "memory" ? "memory" : kind == "output" ? "output files" : "run time";
    if (kind == "memory") {
        const double machine = physical_memory();
        if (machine > 0 && estimate > machine)
            throw BadInput(what + ": needs about " + show(estimate) + " of memory, more than this machine has (" + show(machine) + ")");
    }
    if (!(estimate > limit)) return;
    if (!run_flags().allow_large)
        throw BadInput(what + ": estimated " + noun + " " + show(estimate) + " is above the limit " + show(limit) +
                       " (--allow-large runs it anyway)");
    std::fprintf(stderr, "ddemap: %s: note: %s: estimated %s %s (above the limit %s; --allow-large given)\n", command.c_str(),
                 what.c_str(), noun.c_str(), show(estimate).c_str(), show(limit).c_str());
}

namespace {
std::vector<std::string>& pending_notes() {
    static std::vector<std::string> notes;
    return notes;
}
}  // namespace

void defer_note(const std::string& text) { pending_notes().push_back(text); }

void flush_notes() {
    for (const std::string& n : pending_notes()) std::fprintf(stderr, "ddemap: note: %s\n", n.c_str());
    pending_notes().clear();
}

void announce_estimate(const std::string& command, const std::string& what, double seconds, bool always) {
    flush_notes();
    if ((seconds > 10.0 || always) && !run_flags().quiet)
        std::fprintf(stderr, "ddemap: %s: note: %s: estimated run time %s\n", command.c_str(), what.c_str(), human_seconds(seconds).c_str());
}

std::function<void(const RootWorkEstimate&)> root_size_guard(const std::string& command, const std::string& what) {
    return [command, what](const RootWorkEstimate& e) {
        const std::string method = e.method == "shift_invert" ? "sparse" : e.method == "contour" ? "product" : e.method;
        const std::string full = "the " + method + " root search of " + what + " (" + e.basis + ")";
        check_size(command, full, "memory", e.bytes);
        check_size(command, full, "time", e.seconds);
        announce_estimate(command, full, e.seconds);
    };
}

void check_repeated_roots(const std::string& command, const std::string& what, double units, double runs, const RootWorkEstimate& one) {
    const std::string method = one.method == "shift_invert" ? "sparse" : one.method == "contour" ? "product" : one.method;
    const std::string full = what + " (" + method + " root searches of about " + human_seconds(runs * one.seconds) + " each: " + one.basis + ")";
    check_size(command, full, "memory", one.bytes);
    check_size(command, full, "time", units * runs * one.seconds);
    announce_estimate(command, full, units * runs * one.seconds);
}

std::function<void(long, const RootWorkEstimate&)> ring_modes_guard(const std::string& command, int cars) {
    return [command, cars](long modes, const RootWorkEstimate& one) {
        // a mode's search ran in 0.31 of its prediction (the modes of rings of 2 x 10^4 and
        // 4 x 10^4 ovrv, idm and ccc cars: 0.43 ms against 1.4 ms; small complex collocation
        // matrices, where Eigen's solver beats the c r^3 fitted on large ones)
        check_repeated_roots(command, "the " + std::to_string(modes) + " modes of a ring of " + std::to_string(cars) + " cars", static_cast<double>(modes), 0.35, one);
    };
}

std::function<void(long, const RootWorkEstimate&, int)> branch_roots_guard(const std::string& command, const std::string& stage, double branches) {
    auto announced = std::make_shared<double>(0.0);  // the run time announced so far (0: none)
    return [command, stage, branches, announced](long points, const RootWorkEstimate& one, int measured) {
        const std::string what = "the roots at " + std::to_string(points) + " points of " + (stage.empty() ? "the branch" : stage);
        const double units = branches * static_cast<double>(points);
        if (!measured) {
            // predicted from the first point's root problem: refused above the limit, announced
            const std::string method = one.method == "shift_invert" ? "sparse" : one.method == "contour" ? "product" : one.method;
            const std::string full = what + " (" + method + " root searches of about " + human_seconds(one.seconds) + " each, one or two per point: " + one.basis + ")";
            const double seconds = units * 2.0 * one.seconds;
            check_size(command, full, "memory", one.bytes);
            check_size(command, full, "time", seconds);
            announce_estimate(command, full, seconds);
            *announced = seconds > 10.0 ? seconds : 0.0;  // this branch's (a command may follow several)
            return;
        }
        // measured at the pilot points: refused above the limit; announced at the last pilot when
        // above 10 s and not within a factor 2 of the prediction announced before
        const std::string full = what + " (about " + human_seconds(one.seconds) + " each: " + one.basis + ")";
        const double seconds = units * one.seconds;
        check_size(command, full, "time", seconds);
        if (measured != std::min(5L, points)) return;
        if (*announced == 0.0) announce_estimate(command, full, seconds);
        else if (seconds > 2.0 * *announced || 2.0 * seconds < *announced) announce_estimate(command, full + ", revised", seconds, true);
    };
}

namespace {

/// What the printers share: quiet for the first second (short runs print nothing), on a
/// terminal one line redrawn in place, otherwise a line at most every 3 s (and at most one per
/// percent of `total`) and the last one, the elapsed time and, when `estimate`, the time left.
class Printer {
public:
    explicit Printer(std::string command) : m_command(std::move(command)) {
        // test hook (tests/cli/test_cli.sh): progress from the first unit on
        const char* hook = std::getenv("DDEMAP_TEST_PROGRESS_AT_ONCE");
        m_delay = hook && hook[0] == '1' ? 0.0 : 1.0;
    }
    Printer(const Printer&) = delete;
    Printer& operator=(const Printer&) = delete;
    /// A line left open on a terminal (a branch ends before its budget) is ended.
    ~Printer() {
        if (m_tty && m_open) {
            std::fputc('\n', stderr);
            std::fflush(stderr);
        }
    }
    /// `what`: the line between the command and the times ("rows 3/200", "37 orbits (at most 100), par = 2.8").
    /// `estimate`: the time left follows from done / total; otherwise with `unknown_left` the
    /// line says "time left unknown" (a search whose total is only a budget), and off a
    /// terminal lines come at most once a second instead of once per percent of the budget.
    /// `repeat`: a report from within a unit (the count unchanged): off a terminal shown at most
    /// every 3 s whatever the percent, never once the count is complete.
    void operator()(long done, long total, const std::string& what, bool estimate, bool unknown_left = false, bool repeat = false) {
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
        if (elapsed < m_delay && !m_shown) return;
        if (repeat && done >= total) return;
        const long percent = total > 0 ? done * 100 / total : 100;
        // off a terminal (a log file): at most one line every 3 s, and one per percent at most
        const double interval = m_delay > 0.0 ? 3.0 : 0.0;
        if (!m_tty && m_shown && done != total &&
            (elapsed - m_last_line < interval ||
             (repeat ? false : unknown_left ? elapsed - m_last_line < m_delay : percent == m_last_percent)))
            return;
        flush_notes();
        m_last_percent = percent;
        m_last_line = elapsed;
        m_shown = true;
        char left[64] = "";
        if (estimate && done > 0 && done < total) {
            const double rest = elapsed / static_cast<double>(done) * static_cast<double>(total - done);
            std::snprintf(left, sizeof left, ", about %s left", human_seconds(rest).c_str());
        } else if (unknown_left) {
            std::snprintf(left, sizeof left, "; time left unknown");
        }
        std::fprintf(stderr, "%sddemap: %s: %s (%s%s)%s", m_tty ? "\r" : "", m_command.c_str(), what.c_str(), human_seconds(elapsed).c_str(), left,
                     !m_tty ? "\n" : done == total ? "\033[K\n" : "\033[K");
        std::fflush(stderr);
        m_open = m_tty && done != total;
    }

private:
    std::string m_command;
    std::chrono::steady_clock::time_point m_start = std::chrono::steady_clock::now();
    bool m_tty = isatty(2) != 0;
    double m_delay = 1.0;
    long m_last_percent = -1;
    double m_last_line = 0.0;  ///< elapsed time of the last line
    bool m_shown = false;
    bool m_open = false;  ///< a terminal line without its newline
};

}  // namespace

Progress progress_printer(const std::string& command, const std::string& unit) {
    if (run_flags().quiet) return nullptr;
    auto printer = std::make_shared<Printer>(command);
    return [=](long done, long total) { (*printer)(done, total, unit + " " + std::to_string(done) + "/" + std::to_string(total), true); };
}

LabelledProgress labelled_progress_printer(const std::string& command, const std::string& unit) {
    if (run_flags().quiet) return nullptr;
    auto printer = std::make_shared<Printer>(command);
    return [=](long done, long total, const std::string& label) {
        (*printer)(done, total, unit + " " + std::to_string(done) + "/" + std::to_string(total) + " done, " + label, true);
    };
}

BranchProgress branch_progress_printer(const std::string& command, const std::string& unit, const std::string& par, bool exact_total, bool heartbeat) {
    if (run_flags().quiet) return nullptr;
    auto printer = std::make_shared<Printer>(command);
    // with `heartbeat`, a call before the first unit is finished (0 done) is a repeat too
    auto last = std::make_shared<long>(heartbeat ? 0 : -1);
    auto changed = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
    return [=](long done, long total, double value) {
        const auto now = std::chrono::steady_clock::now();
        // a repeat within a unit is shown only once the unit has run 3 s (the regular lines,
        // with their time left, are not crowded out by a unit's many short repeats)
        if (heartbeat && done == *last && std::chrono::duration<double>(now - *changed).count() < 3.0) return;
        if (done != *last) *changed = now;
        char v[32];
        std::snprintf(v, sizeof v, "%.6g", value);
        const std::string count = exact_total ? unit + " " + std::to_string(done) + "/" + std::to_string(total)
                                              : std::to_string(done) + " " + (done == 1 && unit.size() > 1 && unit.back() == 's' ? unit.substr(0, unit.size() - 1) : unit) +
                                                    " (at most " + std::to_string(total) + ")";
        // with `heartbeat`, the same count again: a report from within a long unit (bistability's
        // stages), shown every few seconds like a search's, so that the log shows the work is alive
        const bool within = heartbeat && done == *last;
        *last = done;
        // a repeat keeps the time left where the count is exact (and one unit is done)
        (*printer)(done, total, count + ", " + par + " = " + v, exact_total, within && !(exact_total && done > 0), within);
    };
}

BranchProgress search_progress_printer(const std::string& command, const std::string& par) {
    if (run_flags().quiet) return nullptr;
    auto printer = std::make_shared<Printer>(command);
    auto last = std::make_shared<long>(-1);
    auto last_time = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::steady_clock::now());
    const bool tty = isatty(2) != 0;
    return [=](long done, long total, double value) {
        // a step repeated from within a long one (the dense eigenvalues, the Arnoldi steps of a
        // shift): on a terminal the time is redrawn, otherwise one line per finished step and,
        // within a long step, one every 10 s (the log shows the search is alive)
        const auto now = std::chrono::steady_clock::now();
        if (!tty && done == *last && std::chrono::duration<double>(now - *last_time).count() < 10.0) return;
        if (!tty) *last_time = now;
        *last = done;
        char v[32];
        std::snprintf(v, sizeof v, "%.6g", value);
        const std::string at = std::isfinite(value) ? ", " + par + " = " + v : std::string();  // NaN: before the first step
        (*printer)(done, total, "step " + std::to_string(done) + " of at most " + std::to_string(total) + at, false, true);
    };
}

namespace {
std::string& time_limit_note() {
    static std::string note;
    return note;
}
}  // namespace

BranchProgress with_time_limit(BranchProgress inner) {
    double limit = run_flags().allow_large ? 0.0 : limit_seconds;
    if (const char* t = std::getenv("DDEMAP_TEST_TIME_LIMIT")) limit = std::atof(t);
    if (!(limit > 0.0)) return inner;
    const auto start = std::chrono::steady_clock::now();
    return [inner, limit, start](long done, long total, double value) {
        if (inner) inner(done, total, value);
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (elapsed > limit) {
            time_limit_note() = "stopped at the run-time limit of " + human_seconds(limit) + " after step " + std::to_string(done) + " of at most " +
                                std::to_string(total) + " (--allow-large lets it run on)";
            throw Cancelled();
        }
    };
}

std::string time_limit_message() { return time_limit_note(); }

}  // namespace ddemap::cli
