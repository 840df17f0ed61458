#pragma once
// Shared test fixture: an OVRV (k1, k2) chart over [0.01, 1]^2.
#include <string>

#include "ddemap/study/sweep.hpp"

namespace ddemap::test {

inline SweepSpec ovrv_chart(int n, int cars, double th, double tau) {
    SweepSpec s;
    s.fixed = {{"th", th}, {"tau", tau}};
    s.x = parse_axis("k1", "0.01:1:" + std::to_string(n));
    s.y = parse_axis("k2", "0.01:1:" + std::to_string(n));
    s.cars = cars;
    return s;
}

}  // namespace ddemap::test
