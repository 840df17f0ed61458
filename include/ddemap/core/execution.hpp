#pragma once
/// \file execution.hpp
/// The one execution policy. Every parallel loop of ddemap runs through parallel_for or
/// parallel_reduce, so threads are chosen in one place, an exception thrown by a task is
/// rethrown on the caller's thread (it never escapes a parallel region), and results do not
/// depend on the number of threads:
///   * parallel_for: each task i writes only its own outputs, so any schedule gives the same
///     outputs;
///   * parallel_reduce: [0, count) is cut into fixed blocks of `block` indices (a partition that
///     does not depend on the thread count), each block reduced on its own, and the block
///     results combined left to right in block order: bitwise the same for 1 or 64 threads.
/// A later distributed (MPI) policy plugs in here.

#include <exception>
#include <functional>
#include <string>
#include <vector>

namespace ddemap {

/// Progress callback: (tasks done, tasks in all); called from one thread at a time.
using Progress = std::function<void(long done, long total)>;

/// Progress of a branch (a continuation): after every finished point, (points done, total,
/// the free parameter at that point). `total` is the number of points when it is known, else
/// the most the branch may have (its max_points budget). Called on the caller's thread; it may
/// throw to stop the work, and the exception then reaches the caller (no partial result).
using BranchProgress = std::function<void(long done, long total, double par)>;

/// Thrown by a progress callback to cancel the work. The computations that document it
/// (rightmost_roots and the analyses built on it: analyse_system, analyse_mixed_ring) catch it
/// on the caller's thread (never inside a parallel region) and return their result with
/// Status::Cancelled, no roots and a verdict of Undecided; any other exception a callback throws
/// reaches the caller as it is.
struct Cancelled : std::exception {
    const char* what() const noexcept override { return "cancelled by the progress callback"; }
};

struct ExecutionPolicy {
    int threads = 0;    ///< 0: the default (OMP_NUM_THREADS, else every core); 1: serial
    Progress progress;  ///< after each finished task of a parallel_for (may be empty)
    /// True when usable; otherwise `why` (if given) names the field.
    bool is_valid(std::string* why = nullptr) const;
};

/// The number of threads a loop under `policy` uses (1 without OpenMP).
int thread_count(const ExecutionPolicy& policy = {});

/// Runs task(i) for every i in [0, count), dynamically scheduled over the policy's threads.
/// Tasks must be independent (each writes only its own outputs). If tasks throw, the exception
/// of the lowest index is rethrown after every task has ended. A progress callback that throws
/// cancels the loop: tasks not yet started are skipped and its exception is rethrown likewise.
/// Throws std::invalid_argument for an invalid policy or count < 0.
void parallel_for(long count, const std::function<void(long)>& task, const ExecutionPolicy& policy = {});

/// Deterministic reduction: partial(begin, end) -> T for every block [begin, end) of at most
/// `block` indices, then init = combine(init, partial_b) for b = 0, 1, ... in order. Progress
/// is not reported (blocks are internal).
template <class T, class Partial, class Combine>
T parallel_reduce(long count, long block, T init, Partial&& partial, Combine&& combine,
                  const ExecutionPolicy& policy = {}) {
    if (count <= 0) return init;
    if (block < 1) block = 1;
    const long blocks = (count + block - 1) / block;
    std::vector<T> parts(static_cast<std::size_t>(blocks));
    ExecutionPolicy quiet = policy;
    quiet.progress = nullptr;
    parallel_for(
        blocks,
        [&](long b) {
            const long begin = b * block;
            const long end = begin + block < count ? begin + block : count;
            parts[static_cast<std::size_t>(b)] = partial(begin, end);
        },
        quiet);
    for (auto& p : parts) init = combine(init, p);
    return init;
}

}  // namespace ddemap
