#include "ddemap/core/execution.hpp"

#include <atomic>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>

#ifdef DDEMAP_WITH_OPENMP
#include <omp.h>
#endif

namespace ddemap {

bool ExecutionPolicy::is_valid(std::string* why) const {
    if (threads < 0 || threads > 4096) {
        if (why) *why = "threads = " + std::to_string(threads) + ": expected 0 (the default) or 1..4096";
        return false;
    }
    return true;
}

int thread_count(const ExecutionPolicy& policy) {
#ifdef DDEMAP_WITH_OPENMP
    return policy.threads > 0 ? policy.threads : omp_get_max_threads();
#else
    (void)policy;
    return 1;
#endif
}

void parallel_for(long count, const std::function<void(long)>& task, const ExecutionPolicy& policy) {
    std::string why;
    if (!policy.is_valid(&why)) throw std::invalid_argument(why);
    if (count < 0) throw std::invalid_argument("count = " + std::to_string(count) + ": expected >= 0");
    std::mutex lock;
    long done = 0;
    long failed_at = std::numeric_limits<long>::max();
    std::exception_ptr failure;
    // Nothing may leave run(): an exception escaping an OpenMP region terminates the program.
    // The task's and the progress callback's exceptions are kept (the lowest index wins). A
    // progress callback that throws cancels the loop: tasks not yet started are skipped (how a
    // front end stops a long loop, e.g. on Ctrl-C).
    std::atomic<bool> cancelled{false};
    auto run = [&](long i) noexcept {
        if (cancelled.load()) return;
        try {
            task(i);
            if (policy.progress) {
                std::lock_guard<std::mutex> guard(lock);
                try {
                    policy.progress(++done, count);
                } catch (...) {
                    cancelled.store(true);
                    throw;
                }
            }
        } catch (...) {
            std::lock_guard<std::mutex> guard(lock);
            if (i < failed_at) {
                failed_at = i;
                failure = std::current_exception();
            }
        }
    };
    const int threads = thread_count(policy);
    if (threads <= 1 || count <= 1) {
        for (long i = 0; i < count && !failure; ++i) run(i);
    } else {
#ifdef DDEMAP_WITH_OPENMP
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
        for (long i = 0; i < count; ++i) run(i);
#endif
    }
    if (failure) std::rethrow_exception(failure);
}

}  // namespace ddemap
