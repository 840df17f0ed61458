#pragma once
// The number of zeros of an analytic function in a rectangle by the argument principle, for tests
// that check a root finder's "nothing to the right of this" independently.
#include <cmath>
#include <complex>
#include <functional>

namespace ddemap::test {

/// Zeros of f in [x0, x1] x [y0, y1]: the change of arg f along the boundary summed over `steps`
/// equal steps per side. Each step must move arg by less than pi: true when the steps are short
/// against the distance of every zero from the boundary (a zero at distance d turns arg by about
/// h / d in a step h).
inline int zeros_in_rectangle(const std::function<std::complex<double>(std::complex<double>)>& f, double x0, double x1, double y0, double y1,
                              int steps) {
    using cplx = std::complex<double>;
    const cplx corner[5] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
    double total = 0.0;
    for (int side = 0; side < 4; ++side) {
        const cplx a = corner[side], b = corner[side + 1];
        cplx fa = f(a);
        for (int i = 1; i <= steps; ++i) {
            const cplx fb = f(a + (static_cast<double>(i) / steps) * (b - a));
            total += std::arg(fb / fa);
            fa = fb;
        }
    }
    return static_cast<int>(std::lround(total / (2.0 * M_PI)));
}

}  // namespace ddemap::test
