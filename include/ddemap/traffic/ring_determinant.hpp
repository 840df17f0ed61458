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

/// D(lambda) of a ring whose cars react to the car ahead and to the car two ahead (connected
/// cruise control; cars of one leader may be mixed in), by 2 x 2 transfer matrices. Eliminating
/// the gaps (lambda s_i = v_{i-1} - v_i), car i obeys
///     P_i v_i = Q_i v_{i-1} + R_i v_{i-2},   R_i(lambda) = lambda further_i(lambda)
/// (P_i, Q_i as above, R_i = 0 for a car of one leader), so x_i = (v_i, v_{i-1}) = T_i x_{i-1} with
///     T_i = [[Q_i / P_i, R_i / P_i], [1, 0]],   det T_i = -R_i / P_i,
/// and, the ring closing with x_N = x_0,
///     D(lambda) = det Delta(lambda) = prod_i P_i(lambda) det(I - M(lambda)),   M = T_{N-1} ... T_1 T_0,
///     det(I - M) = 1 - tr M + det M,   det M = prod_i (-R_i / P_i).
/// (The 2N x 2N determinant is lambda^N times the N x N one of the speeds, whose rows are
/// P_i v_i - Q_i v_{i-1} - R_i v_{i-2}; that cyclic banded determinant is prod P_i det(I - M).)
/// The order of the cars matters. lambda = 0 is a root of every ring (M(0) has the eigenvalue 1).
///
/// Evaluation without overflow for any N: the product M is kept as 2^e times a matrix of
/// moderate size (with its derivative, forward mode), det M as a sum of logarithms over the
/// car types; the ring is cut into blocks of b cars (b chosen to minimise the matrix products),
/// each distinct block multiplied out once per evaluation, and runs of identical blocks taken as
/// matrix powers by repeated squaring. Arg D is followed as sum_t n_t arg P_t (per car type) plus
/// arg det(I - M), each with steps of at most max_arg_step radians and capped by its local
/// turning rate |d/dlambda log|, and with size = log ||M||_F (the roots lie where size >= 0)
/// changing by at most max(max_arg_step, |size| / 2) per step, so that a step cannot jump over
/// the band where the spectral radius of M reaches 1 (as RingDeterminant does with Re Phi);
/// all by the one phase tracker. The contour backend of rightmost_roots finds and certifies the
/// roots from it exactly as for RingDeterminant.
class TransferRingDeterminant final : public CharacteristicFunction {
public:
    /// Throws std::invalid_argument for fewer than 2 cars or a car with more than two leaders.
    /// Cars in ring order, car i following car i-1 (car 0 follows car N-1).
    explicit TransferRingDeterminant(const std::vector<Linearisation>& cars);
    int types() const { return static_cast<int>(m_types.size()); }
    int cars() const { return static_cast<int>(m_car_type.size()); }
    /// Cars per block and the 2 x 2 matrix products (with derivatives) of one evaluation.
    int block_length() const { return m_block; }
    long products() const { return m_products; }
    /// log D(lambda) (imaginary part modulo 2 pi); NaN where it cannot be evaluated (P_i = 0).
    cplx log_value(cplx lambda) const;
    /// log det(I - M(lambda)) (imaginary part modulo 2 pi).
    cplx log_closure(cplx lambda) const;
    /// D'(lambda) / D(lambda).
    cplx log_derivative(cplx lambda) const override;

    /// Zeros in [x0, x1] x [y0, y1] and in [x0, x1] x [-y, y] (argument_principle.hpp).
    ZeroCount count(double x0, double x1, double y0, double y1, double max_arg_step = 0.5) const;
    ZeroCount count_symmetric(double x0, double x1, double y, double max_arg_step = 0.5) const;

    // CharacteristicFunction
    bool arg_change(cplx a, cplx b, double max_arg_step, double& total, long& evaluations) const override;
    double evaluation_cost() const override;
    bool is_real() const override { return true; }
    /// A null vector of Delta(lambda): the speeds from one inverse iteration with the sparse LU of
    /// the cyclic banded N x N speed matrix, the gaps from the rows of Delta.
    VectorXc null_vector(cplx lambda) const override;
    std::string description() const override { return "det Delta = prod P_i det(I - prod T_i)"; }
    std::string cost_description() const override;

    /// One evaluation: per type P_t and P_t'/P_t; det(I - M) as e^scale g with g' (scale real);
    /// the size of the product, size = log ||M||_F, and its turning rate ||M'||_F / ||M||_F (an
    /// upper bound on |d size / d lambda|). Where size < 0 the spectral radius of M is below 1,
    /// so no root is near and arg det(I - M) stays within (-pi, pi).
    struct Sample {
        std::vector<cplx> p, dlogp;
        cplx g = 0.0, dg = 0.0;
        double scale = 0.0;
        double size = 0.0, size_rate = 0.0;
        bool ok = false;
        /// scratch of one evaluation (kept to avoid allocations)
        std::vector<cplx> a, b, da, db;
    };
    void evaluate(cplx lambda, Sample& s) const;

private:
    /// The speeds of a null vector: two steps of inverse iteration with the sparse LU of the
    /// cyclic N x N matrix with rows P_i v_i - Q_i v_{i-1} - R_i v_{i-2}; empty when singular.
    VectorXc speed_null_vector(cplx lambda) const;
    struct Type {
        Linearisation lin;
        double n = 0.0;  ///< how many cars
    };
    struct Run {
        int block = 0;   ///< index into m_blocks
        long count = 0;  ///< consecutive repetitions
    };
    std::vector<Type> m_types;
    std::vector<int> m_car_type;            ///< the type of every car, ring order
    std::vector<std::vector<int>> m_blocks; ///< distinct blocks: type sequences in ring order
    std::vector<Run> m_runs;                ///< the ring as runs of blocks, ring order
    int m_block = 1;
    long m_products = 0;
    bool m_det_zero = false;  ///< some car has R_i = 0 identically, so det M = 0
};

/// The root problem of a ring of cars (ring order, car i following car i-1): the 2N-state
/// sparse LinearDDE (mixed_ring_dde) and its characteristic function: RingDeterminant when
/// every car reacts only to the car ahead, TransferRingDeterminant when some car also reacts to
/// the car two ahead (then "auto" takes the contour backend for both).
RootProblem ring_root_problem(const std::vector<Linearisation>& cars);

}  // namespace ddemap
