#pragma once
/// \file argument_principle.hpp
/// Zero counts by the argument principle on a CharacteristicFunction; the phase following
/// itself is the one tracker follow_phase (core/phase_tracking.hpp).

#include "ddemap/core/phase_tracking.hpp"
#include "ddemap/problem/characteristic_function.hpp"

namespace ddemap {

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
