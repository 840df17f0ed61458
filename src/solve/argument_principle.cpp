#include "ddemap/solve/argument_principle.hpp"

#include <cmath>

namespace ddemap {

namespace {
constexpr double kTwoPi = 6.283185307179586476925286766559;
}  // namespace

ZeroCount count_zeros(const CharacteristicFunction& d, double x0, double x1, double y0, double y1, double theta) {
    ZeroCount c;
    double total = 0.0;
    const cplx z00(x0, y0), z10(x1, y0), z11(x1, y1), z01(x0, y1);
    c.ok = d.arg_change(z00, z10, theta, total, c.evaluations) && d.arg_change(z10, z11, theta, total, c.evaluations) &&
           d.arg_change(z11, z01, theta, total, c.evaluations) && d.arg_change(z01, z00, theta, total, c.evaluations);
    if (!c.ok) return c;
    const double w = total / kTwoPi;
    c.zeros = static_cast<int>(std::lround(w));
    c.ok = std::abs(w - c.zeros) < 0.25 && c.zeros >= 0;
    return c;
}

ZeroCount count_zeros_symmetric(const CharacteristicFunction& d, double x0, double x1, double y, double theta) {
    ZeroCount c;
    double total = 0.0;
    const cplx a(x1, 0.0), b(x1, y), e(x0, y), f(x0, 0.0);
    c.ok = d.arg_change(a, b, theta, total, c.evaluations) && d.arg_change(b, e, theta, total, c.evaluations) &&
           d.arg_change(e, f, theta, total, c.evaluations);
    if (!c.ok) return c;
    const double w = 2.0 * total / kTwoPi;
    c.zeros = static_cast<int>(std::lround(w));
    c.ok = std::abs(w - c.zeros) < 0.25 && c.zeros >= 0;
    return c;
}

}  // namespace ddemap
