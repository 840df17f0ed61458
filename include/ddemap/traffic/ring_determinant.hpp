#pragma once
/// \file ring_determinant.hpp
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
/// max_arg_step near |e^Phi| = 1, where the roots are), by the one phase tracker
/// (solve/argument_principle.hpp). RingDeterminant is a CharacteristicFunction: the contour
/// backend of rightmost_roots (solve/roots.hpp) finds the rightmost roots from it, certified
/// complete by the count, not only by a discretisation; ring_root_problem builds that problem.

#include <memory>
#include <string>
#include <vector>

#include "ddemap/problem/characteristic_function.hpp"
#include "ddemap/solve/argument_principle.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

/// D(lambda) of a ring of one-leader cars, in the factored form above.
class RingDeterminant final : public CharacteristicFunction {
public:
    /// Groups identical linearisations; throws std::invalid_argument for fewer than 2 cars or
    /// a car with more than one leader. Cars in ring order, car i following car i-1.
    explicit RingDeterminant(const std::vector<Linearisation>& cars);
    int types() const { return static_cast<int>(m_types.size()); }
    /// log D(lambda) (imaginary part modulo 2 pi); -inf real part at an exact root.
    cplx log_value(cplx lambda) const;
    /// D'(lambda) / D(lambda).
    cplx log_derivative(cplx lambda) const override;
    /// Phi(lambda) = sum_i log Gamma_i(lambda) (imaginary part modulo 2 pi).
    cplx phi(cplx lambda) const;

    using Count = ZeroCount;
    /// Zeros in [x0, x1] x [y0, y1] (count_zeros of argument_principle.hpp).
    Count count(double x0, double x1, double y0, double y1, double max_arg_step = 0.5) const;
    /// Zeros in [x0, x1] x [-y, y] (count_zeros_symmetric).
    Count count_symmetric(double x0, double x1, double y, double max_arg_step = 0.5) const;

    // CharacteristicFunction
    bool arg_change(cplx a, cplx b, double max_arg_step, double& total, long& evaluations) const override;
    double evaluation_cost() const override { return static_cast<double>(m_types.size()); }
    bool is_real() const override { return true; }
    /// The ring eigenvector x with speeds x_v,i = Gamma_i x_v,i-1 (and gaps from the rows of Delta).
    VectorXc null_vector(cplx lambda) const override;
    std::string description() const override { return "det Delta = prod P_i - prod Q_i"; }
    std::string cost_description() const override;

private:
    struct Type {
        TransferFunction gamma;  ///< Gamma = Q / P of one car of this type
        double n = 0.0;          ///< how many cars
    };
    /// P, Q (and P', Q' when dp is given) of one type at z.
    void factors(const Type& t, cplx z, cplx& p, cplx& q, cplx* dp, cplx* dq) const;
    std::vector<Type> m_types;
    std::vector<TransferFunction> m_gamma;  ///< every car in ring order (for the null vector)
};

/// The root problem of a ring of cars (ring order, car i following car i-1): the 2N-state
/// sparse LinearDDE (mixed_ring_dde) and, when every car reacts only to the car ahead, its
/// RingDeterminant as the characteristic function (then "auto" takes the contour backend).
RootProblem ring_root_problem(const std::vector<Linearisation>& cars);

}  // namespace ddemap
