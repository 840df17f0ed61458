#pragma once
/// \file characteristic_function.hpp
/// A scalar characteristic function: det Delta(lambda) of a linear DDE available in a factored
/// scalar form D(lambda) (the ring determinant prod P_i - prod Q_i of a ring of one-leader
/// cars, a quasi-polynomial). The contour backend of rightmost_roots (solve/roots.hpp) needs
/// only this interface: counts of zeros inside rectangles by the argument principle, Newton on
/// D, and a null vector of Delta at a root for the one residual definition (root_bounds.hpp).

#include <string>

#include "ddemap/core/types.hpp"

namespace ddemap {

class CharacteristicFunction {
public:
    virtual ~CharacteristicFunction() = default;
    /// D'(lambda) / D(lambda) (not finite at an exact zero of D).
    virtual cplx log_derivative(cplx lambda) const = 0;
    /// Adds the continuous change of arg D along the segment a -> b to `total`, following the
    /// phase with steps of at most `max_arg_step` radians; `evaluations` counts the points.
    /// False when the phase cannot be followed (a zero on or within rounding of the segment).
    virtual bool arg_change(cplx a, cplx b, double max_arg_step, double& total, long& evaluations) const = 0;
    /// The cost of one evaluation of D in units of a simple factor (e.g. the number of car types).
    virtual double evaluation_cost() const { return 1.0; }
    /// What D is, for messages (e.g. "det Delta = prod P_i - prod Q_i").
    virtual std::string description() const { return "det Delta"; }
    /// The evaluation cost for messages (e.g. " over 3 car types"); empty by default.
    virtual std::string cost_description() const { return {}; }
    /// True when D is real on the real axis (zeros come in conjugate pairs).
    virtual bool is_real() const = 0;
    /// A null vector v of Delta(lambda) at a zero lambda of D (the residual of the underlying
    /// LinearDDE is computed with it); an empty vector when none can be built.
    virtual VectorXc null_vector(cplx lambda) const = 0;
};

}  // namespace ddemap
