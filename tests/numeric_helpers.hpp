#pragma once
// Small numerical helpers shared by the tests (independent of the library's own solvers).
#include <algorithm>
#include <cmath>
#include <complex>

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

/// The distance from z to the nearest point of a set of complex numbers or of roots (their .value).
inline std::complex<double> point_of(const std::complex<double>& z) { return z; }
template <class R>
auto point_of(const R& r) -> decltype(std::complex<double>(r.value)) {
    return r.value;
}
template <class Set>
double nearest(const Set& set, std::complex<double> z) {
    double d = 1e300;
    for (const auto& w : set) d = std::min(d, std::abs(point_of(w) - z));
    return d;
}

}  // namespace ddemap::test
