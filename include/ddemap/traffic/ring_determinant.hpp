#pragma once
/// \file ring_product.hpp
/// Rings of cars that react only to the car ahead, solved through the scalar characteristic
/// function instead of an eigenvalue problem. With
///     P_i(lambda) = lambda^2 - lambda own_i(lambda) + gap_i(lambda),
///     Q_i(lambda) = gap_i(lambda) + lambda lead_i(lambda),   Gamma_i = Q_i / P_i,
/// the 2N x 2N characteristic matrix of the ring (fleet.hpp) has the determinant
///     D(lambda) = det Delta(lambda) = prod_i P_i(lambda) - prod_i Q_i(lambda)
///               = prod_i P_i (1 - e^Phi) = -prod_i Q_i (1 - e^{-Phi}),   Phi = sum_i log Gamma_i,
/// so the roots do not depend on the order of the cars, and D, D'/D and arg D cost O(types)
/// (identical cars are grouped) whatever N is, without overflow.
///
/// Completeness by the argument principle: the number of roots inside a rectangle is the
/// winding number of D along its boundary, tracked in the factored form: sum_t n_t arg P_t
/// (each P_t followed with steps of at most max_arg_step radians) plus the unwrapped arg of
/// 1 - e^Phi (followed through Im Phi where |Re Phi| is large, and with |delta Phi| <=
/// max_arg_step near |e^Phi| = 1, where the roots are). The rightmost roots: the strip floor
/// alpha is lowered (bisection) until at least `count` roots lie in [alpha, beta] x
/// [-R(alpha), R(alpha)] (no root with Re >= alpha lies outside it, sparse.hpp); the rectangle
/// is split into cells with their counts until each holds one root, which Newton on D finds.
/// The listed roots are then certified complete by the count, not only by the discretisation.

#include <string>
#include <vector>

#include "ddemap/traffic/model.hpp"
#include "ddemap/solve/shift_invert.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

/// D(lambda) of a ring of one-leader cars, in the factored form above.
class RingDeterminant {
public:
    /// Groups identical linearisations; throws std::invalid_argument for fewer than 2 cars or
    /// a car with more than one leader.
    explicit RingDeterminant(const std::vector<Linearisation>& cars);
    int types() const { return static_cast<int>(m_types.size()); }
    /// log D(lambda) (imaginary part modulo 2 pi); -inf real part at an exact root.
    cplx log_value(cplx lambda) const;
    /// D'(lambda) / D(lambda).
    cplx log_derivative(cplx lambda) const;
    /// Phi(lambda) = sum_i log Gamma_i(lambda) (imaginary part modulo 2 pi).
    cplx phi(cplx lambda) const;

    /// Zeros of D inside a rectangle by the argument principle.
    struct Count {
        int zeros = 0;         ///< with multiplicity
        long evaluations = 0;  ///< contour points (each O(types))
        bool ok = false;       ///< false: a zero on (or within rounding of) the boundary
    };
    /// [x0, x1] x [y0, y1], counter-clockwise boundary.
    Count count(double x0, double x1, double y0, double y1, double max_arg_step = 0.5) const;
    /// [x0, x1] x [-y, y] for this real problem: twice the change of arg D along the upper half.
    Count count_symmetric(double x0, double x1, double y, double max_arg_step = 0.5) const;

private:
    struct Type {
        TransferFunction gamma;  ///< Gamma = Q / P of one car of this type
        double n = 0.0;          ///< how many cars
    };
    /// P, Q (and P', Q' when dp is given) of one type at z.
    void factors(const Type& t, cplx z, cplx& p, cplx& q, cplx* dp, cplx* dq) const;
    /// Adds the change of arg D along the segment a -> b to `total`; false if the step underflowed.
    bool follow(cplx a, cplx b, double max_arg_step, double& total, long& evaluations) const;
    std::vector<Type> m_types;
};

struct ProductRootOptions {
    int count = 10;                     ///< rightmost roots wanted (a conjugate partner may be added)
    double max_arg_step = 0.5;          ///< radians per step along a contour
    int max_cells = 200000;             ///< give up (EigenFailure) after this many cell counts
    double max_type_evaluations = 2e9;  ///< or after this many evaluations of one car type's factors
    int newton_max_iterations = 60;
    double newton_tolerance = 1e-14;    ///< stop when |step| <= tol max(1, |lambda|)
    double residual_tolerance = 1e-9;   ///< accept a root below this relative residual
    void validate() const;
};

/// The rightmost roots of D (the trivial root lambda = 0 included; cars in ring order, car i
/// following car i-1). Result in the sparse layout: strip_floor = alpha, right_bound = beta,
/// height = R(alpha), eigenvalues_found = the count in the rectangle, degree = 0, shifts = 0;
/// each root's residual is ||Delta(lambda) x|| / (||x|| (|lambda| + R(Re lambda))) for the
/// eigenvector x built from x_i = Gamma_i x_{i-1}.
SparseRootResult product_ring_roots(const std::vector<Linearisation>& cars, const ProductRootOptions& options = {});

}  // namespace ddemap
