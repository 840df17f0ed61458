#include <doctest/doctest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "ddemap/core/execution.hpp"

using namespace ddemap;

TEST_SUITE_BEGIN("fast");

TEST_CASE("parallel_for runs every task once and reports progress once per task") {
    for (int threads : {1, 2, 3}) {
        ExecutionPolicy policy;
        policy.threads = threads;
        std::vector<int> hits(1000, 0);
        long calls = 0, last = 0;
        policy.progress = [&](long done, long total) {
            ++calls;
            CHECK(total == 1000);
            CHECK(done == last + 1);  // serialised and counting up
            last = done;
        };
        parallel_for(1000, [&](long i) { hits[i] += 1; }, policy);
        for (int h : hits) CHECK(h == 1);
        CHECK(calls == 1000);
    }
}

TEST_CASE("parallel_for rethrows the exception of the lowest failing task on the caller's thread") {
    for (int threads : {1, 2, 4}) {
        ExecutionPolicy policy;
        policy.threads = threads;
        try {
            parallel_for(200, [](long i) {
                if (i == 37 || i == 150) throw std::invalid_argument("task " + std::to_string(i));
            }, policy);
            FAIL("no exception");
        } catch (const std::invalid_argument& e) {
            CHECK(std::string(e.what()) == "task 37");
        }
    }
}

TEST_CASE("a throwing progress callback or a non-standard exception never leaves the parallel region") {
    for (int threads : {1, 2, 4}) {
        ExecutionPolicy policy;
        policy.threads = threads;
        policy.progress = [](long done, long) {
            if (done == 5) throw std::runtime_error("progress 5");
        };
        CHECK_THROWS_WITH_AS(parallel_for(100, [](long) {}, policy), "progress 5", std::runtime_error);
        ExecutionPolicy plain;
        plain.threads = threads;
        CHECK_THROWS_AS(parallel_for(100, [](long i) {
            if (i == 60) throw 42;  // not derived from std::exception
        }, plain), int);
    }
}

TEST_CASE("a throwing progress callback cancels the tasks not yet started") {
    for (int threads : {1, 2, 4}) {
        ExecutionPolicy policy;
        policy.threads = threads;
        policy.progress = [](long done, long) {
            if (done == 3) throw std::runtime_error("stop");
        };
        std::atomic<long> started{0};
        CHECK_THROWS_WITH_AS(parallel_for(10000, [&](long) { ++started; }, policy), "stop", std::runtime_error);
        // the tasks already running when the callback threw finish (at most one per thread)
        CHECK(started.load() <= 3 + threads);
    }
}

TEST_CASE("parallel_reduce is bitwise the same for any number of threads") {
    // a sum whose value depends on the order of the additions
    std::mt19937 rng(7);
    std::vector<double> x(100000);
    for (auto& v : x) v = std::ldexp(std::uniform_real_distribution<double>(-1.0, 1.0)(rng), static_cast<int>(rng() % 60) - 30);
    auto sum_with = [&](int threads) {
        ExecutionPolicy policy;
        policy.threads = threads;
        return parallel_reduce(
            static_cast<long>(x.size()), 1000, 0.0,
            [&](long b, long e) {
                double s = 0.0;
                for (long i = b; i < e; ++i) s += x[i];
                return s;
            },
            [](double a, double b) { return a + b; }, policy);
    };
    const double one = sum_with(1);
    for (int threads : {2, 3, 8}) {
        const double many = sum_with(threads);
        CHECK(std::memcmp(&one, &many, sizeof(double)) == 0);
    }
    // and it is the sum, within the recursive-summation bound (n - 1) eps sum |x_i|
    long double exact = 0.0L, magnitude = 0.0L;
    for (double v : x) {
        exact += v;
        magnitude += std::abs(v);
    }
    CHECK(std::abs(one - static_cast<double>(exact)) <= (x.size() - 1) * 2.220446049250313e-16 * static_cast<double>(magnitude));
}

TEST_CASE("execution policy validation names the field") {
    ExecutionPolicy policy;
    policy.threads = -1;
    std::string why;
    CHECK_FALSE(policy.is_valid(&why));
    CHECK(why.find("threads = -1") != std::string::npos);
    CHECK_THROWS_AS(parallel_for(3, [](long) {}, policy), std::invalid_argument);
    CHECK_THROWS_AS(parallel_for(-1, [](long) {}), std::invalid_argument);
}

TEST_SUITE_END();
