#pragma once
// Small numerical helpers shared by the tests (independent of the library's own solvers).
#include <algorithm>
#include <cmath>

namespace ddemap::test {

constexpr double pi = 3.14159265358979323846;

/// The root of a continuous g on [lo, hi] with g(lo) g(hi) < 0, by bisection to rounding.
template <class G>
double bisect(G g, double lo, double hi) {
    double glo = g(lo);
    for (int i = 0; i < 200 && hi - lo > 1e-15 * std::max(1.0, std::abs(lo)); ++i) {
        const double mid = 0.5 * (lo + hi), gm = g(mid);
        if ((gm < 0) == (glo < 0)) lo = mid, glo = gm;
        else hi = mid;
    }
    return 0.5 * (lo + hi);
}

}  // namespace ddemap::test
