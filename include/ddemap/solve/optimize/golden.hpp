#pragma once
/// \file golden.hpp
/// Golden-section minimisation of a function of one variable on an interval.
#include <algorithm>
#include <cmath>

namespace ddemap {

/// The minimum of a unimodal h on [a, b] by golden-section search: the bracket shrinks by
/// r = (sqrt 5 - 1) / 2 per evaluation until it is below `tolerance` max(1, |a|) or after
/// `max_iterations` steps. Returns the abscissa of the least value seen at the end and writes
/// that value; `evaluations` counts the calls of h.
template <class F>
double golden_minimize(const F& h, double a, double b, double& value, int& evaluations, double tolerance = 1e-12, int max_iterations = 80) {
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double c = b - r * (b - a), d = a + r * (b - a);
    double fc = h(c), fd = h(d);
    evaluations += 2;
    for (int it = 0; it < max_iterations && (b - a) > tolerance * std::max(1.0, std::abs(a)); ++it) {
        if (fc <= fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - r * (b - a);
            fc = h(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + r * (b - a);
            fd = h(d);
        }
        ++evaluations;
    }
    if (fc <= fd) {
        value = fc;
        return c;
    }
    value = fd;
    return d;
}

}  // namespace ddemap
