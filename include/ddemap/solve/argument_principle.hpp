#pragma once
/// \file argument_principle.hpp
/// The one argument-principle tracker of ddemap: the continuous change of arg f along a path,
/// followed with bounded steps. The number of zeros of an analytic f inside a closed contour C
/// is (1 / 2 pi) times the change of arg f around C; the change is the sum of the wrapped phase
/// increments arg(f(z_{j+1}) / f(z_j)) provided every step turns the phase by less than pi.
///
/// The tracker owns the step control; the caller's path owns the evaluation and the test of a
/// step. A path provides
///     double cap() const;                    // the largest step the rates at the current point allow
///     bool trial(double t, double& darg);    // evaluate at arclength t, darg = phase change from
///                                            // the current point; false rejects the step
///     void accept();                         // the trial point becomes the current one
/// Accepted steps grow by 1.6 (up to cap()), rejected ones shrink by 0.35; a step below `tiny`
/// ends the tracking as failed (a zero on or within rounding of the path).

#include <algorithm>

#include "ddemap/problem/characteristic_function.hpp"

namespace ddemap {

/// Adds the change of arg along a path of arclength `length` to `total`; false when the step
/// underflowed below `tiny`.
template <class Path>
bool follow_phase(Path& path, double length, double tiny, double& total) {
    double t = 0.0, h = path.cap();
    while (t < length) {
        h = std::min(h, length - t);
        const double tn = (length - t - h <= tiny) ? length : t + h;
        double darg = 0.0;
        if (path.trial(tn, darg)) {
            total += darg;
            path.accept();
            t = tn;
            h = std::min(1.6 * h, path.cap());
        } else {
            h *= 0.35;
            if (h < tiny) return false;
        }
    }
    return true;
}

/// Zeros of D inside a rectangle by the argument principle.
struct ZeroCount {
    int zeros = 0;         ///< with multiplicity
    long evaluations = 0;  ///< contour points
    bool ok = false;       ///< false: a zero on (or within rounding of) the boundary
};

/// Zeros of D inside [x0, x1] x [y0, y1]: the change of arg D along the counter-clockwise
/// boundary over 2 pi (D.arg_change with steps of at most max_arg_step radians).
ZeroCount count_zeros(const CharacteristicFunction& d, double x0, double x1, double y0, double y1, double max_arg_step = 0.5);
/// Zeros of a real D inside [x0, x1] x [-y, y]: twice the change of arg D along the upper half.
ZeroCount count_zeros_symmetric(const CharacteristicFunction& d, double x0, double x1, double y, double max_arg_step = 0.5);

}  // namespace ddemap
