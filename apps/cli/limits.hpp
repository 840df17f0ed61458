#pragma once
// Bounded and visible work (README "Limits and progress"): the size guard that refuses work
// whose estimated memory, output or time exceeds a limit before it starts (--allow-large lifts
// the soft limits, never the machine's memory), and the one progress printer on stderr.
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "ddemap/core/execution.hpp"
#include "ddemap/solve/roots.hpp"

namespace ddemap::cli {

/// Soft limits (README "Limits and progress"); --allow-large lifts them.
constexpr double limit_memory_bytes = 2e9;   ///< estimated memory of one command
constexpr double limit_output_bytes = 1e8;   ///< estimated size of the files written
constexpr double limit_seconds = 600.0;      ///< estimated run time (one core)

/// --allow-large and --quiet on a command.
struct RunFlags {
    bool allow_large = false;
    bool quiet = false;
    /// `sizes`: the command has a size guard (adds --allow-large).
    void add_to(CLI::App& app, bool sizes);
};

/// The flags of the command being run (one command runs per process).
RunFlags& run_flags();

/// Refuses (BadInput, one line naming `what`, the estimate and the limit) when `estimate` is
/// above `limit` unless --allow-large was given; with it, announces the estimate on stderr.
/// Memory above the machine's physical memory is refused even with --allow-large.
/// `kind`: "memory", "output" or "time" (bytes, bytes, seconds).
void check_size(const std::string& command, const std::string& what, const std::string& kind, double estimate);

/// Above 10 s (and without --quiet): `ddemap: COMMAND: note: WHAT: estimated run time 3.6 min`
/// on stderr, so that long work is sized before it starts. Called when every input has been
/// checked (an error after it would make the error two lines).
/// `always`: whatever the time (a revision of an estimate announced before).
void announce_estimate(const std::string& command, const std::string& what, double seconds, bool always = false);

/// A note about the input found while parsing it ("ddemap: note: TEXT" on stderr), held back
/// until the input has passed every check: printed before the first progress line or estimate,
/// or when the command returns; dropped when it ends with an error (whose one line is then the
/// only one).
void defer_note(const std::string& text);
/// Prints the notes held back (main, the progress printers and announce_estimate call it).
void flush_notes();

/// The size guard of a root search (RootOptions::before): check_size on the predicted memory and
/// run time of `what` (estimate_root_work, "a ring of 20000 cars"), named with how the prediction
/// was made.
std::function<void(const RootWorkEstimate&)> root_size_guard(const std::string& command, const std::string& what);

/// The size guard of work made of `units` root searches alike (the points of an equilibrium
/// branch, the modes of a ring), each predicted by `one` (estimate_root_work of the first) and
/// made `runs` times at most on average: check_size on the memory of one and on units x runs x
/// its time, then announce_estimate. `what`: "the roots at 24 points of the branch".
void check_repeated_roots(const std::string& command, const std::string& what, double units, double runs, const RootWorkEstimate& one);

/// RingOptions::before of `command` (the per-mode path of a ring of `cars` cars): check_repeated_roots
/// on the modes, each predicted by the first nonzero mode's estimate times 0.35 (measured on
/// rings of 2 x 10^4 and 4 x 10^4 cars: 0.31).
std::function<void(long, const RootWorkEstimate&)> ring_modes_guard(const std::string& command, int cars);

/// EquilibriumBranchOptions::before_roots of `command`: before any root, check_size on the
/// branch's points x 2 searches (equilibrium_roots asks again when the first did not certify the
/// strip it needs) x the predicted one, and announce_estimate; after each pilot point check_size
/// on the points x their mean measured time (refused above the limit), announced after the last
/// pilot ("revised") when it is off the first announcement by more than a factor 2. `stage` names the branch in the note ("" = "the
/// branch"), `branches` the number of branches like it (bistability's slices).
std::function<void(long, const RootWorkEstimate&, int)> branch_roots_guard(const std::string& command, const std::string& stage = "", double branches = 1.0);

/// "1.5 GB", "340 MB", "12 kB"; "2.5 min", "3.1 h".
std::string human_bytes(double bytes);
std::string human_seconds(double seconds);

/// The one progress printer: `command: LABEL 12/200 (3.1 s, about 48 s left)` on stderr.
/// On a terminal one line redrawn in place; otherwise a line at most every 3 s (at most one
/// per percent of the work) and the last one. Silent for the first second (short runs print nothing) and with
/// --quiet. Returns an empty callback when quiet.
Progress progress_printer(const std::string& command, const std::string& unit);

/// The same printer with a label for the unit just finished (calibrate's fits):
/// `command: fits 3/12 done, NAME in 0.41 s (4.2 s, about 12 s left)`, `label` = "NAME in 0.41 s".
using LabelledProgress = std::function<void(long done, long total, const std::string& label)>;
LabelledProgress labelled_progress_printer(const std::string& command, const std::string& unit);

/// The same printer for a branch (a continuation), one line per finished point:
/// `command: 37 orbits (at most 100), headway = 2.81 (4.2 s)`, or with `exact_total` (the
/// number of points is known) `command: points 37/80, gap = 12.5 (4.2 s, about 3 s left)`.
/// `heartbeat`: a call that repeats the last count (a report from within a long unit, as
/// bistability's stages make) is shown every few seconds ("time left unknown") instead of dropped.
BranchProgress branch_progress_printer(const std::string& command, const std::string& unit, const std::string& par, bool exact_total,
                                       bool heartbeat = false);

/// The printer of a search that ends when it has found what it looks for, within a budget of
/// steps (the root searches of roots --fleet and --system): the budget is a bound, not the work
/// to come, so no time left is estimated and the line says so:
/// `command: step 37 of at most 200000, Re = -0.41 (4.2 s; time left unknown)`. On a terminal
/// one line redrawn in place; otherwise one line per finished step, at most one a second, and
/// within a long step one every 10 s.
BranchProgress search_progress_printer(const std::string& command, const std::string& par);

/// A root search's progress callback with the run-time limit: a search bounded only by its step
/// count (roots --fleet --solver sparse on 10^5 cars, a --system with extreme coefficients)
/// is stopped after limit_seconds (10 min; DDEMAP_TEST_TIME_LIMIT seconds in the tests; none
/// with --allow-large) by throwing ddemap::Cancelled, so that it ends undecided (exit 4) and
/// says why (time_limit_message) instead of running on. `inner` (the printer) may be empty.
BranchProgress with_time_limit(BranchProgress inner);
/// Non-empty when with_time_limit stopped the search: "stopped at the run-time limit ...".
std::string time_limit_message();

}  // namespace ddemap::cli
