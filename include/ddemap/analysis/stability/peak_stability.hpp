#pragma once
/// \file peak_stability.hpp
/// Peak (L-infinity) string stability of identical cars: the follower's speed never overshoots
/// what the car ahead did. With h the impulse response of the head-to-tail transfer function
/// Gamma (string_stability.hpp), a disturbance e(t) of the leader's speed reaches the follower as
/// h * e, and
///     sup_e ||h * e||_inf / ||e||_inf = ||h||_1 = integral_0^inf |h(t)| dt.
/// Gamma(0) = 1 gives integral h = 1, so ||h||_1 >= 1, with equality exactly when h >= 0, that is
/// when the unit-step response y (the follower's speed after the leader's speed steps by 1) never
/// decreases. ||h||_1 is the total variation of y; and |Gamma(i w)| <= ||h||_1 for every w, so
/// peak stability implies the L2 (head-to-tail) string stability of analyse_string.

#include <string>
#include <vector>

#include "ddemap/core/status.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

struct PeakOptions {
    double tolerance = 1e-7;   ///< target of the error estimate of ||h||_1 (absolute, > 0)
    double max_time = 1e5;     ///< s: the response is followed at most this long (> 0)
    long max_steps = 4000000;  ///< integrator steps of one resolution at most (>= 1000)
    /// std::invalid_argument naming the first bad option.
    void validate() const;
};

struct PeakResult {
    Status status = Status::Converged;
    std::string message;
    /// Stable: ||h||_1 - 1 <= error (the step response does not decrease, to the accuracy);
    /// Unstable: the plant is unstable (||h||_1 is infinite) or ||h||_1 - 1 > error;
    /// Undecided: the estimate did not reach the tolerance (status says why).
    Verdict verdict = Verdict::Undecided;
    /// norm holds ||h||_1; false when the plant is unstable (||h||_1 is infinite), or when
    /// analyse_string decided the verdict from sup |Gamma(i w)| > 1 without the norm
    bool finite = false;
    double norm = 0.0;         ///< ||h||_1, the total variation of the unit-step response
    double error = 0.0;        ///< estimate of |norm - ||h||_1|: two step sizes, the tail, the sum's rounding
    double overshoot = 0.0;    ///< max_t y(t) - 1 (>= 0; the step response's overshoot)
    double t_end = 0.0;        ///< s: how long the response was followed
    double step = 0.0;         ///< s: the finest step used
    long steps = 0;            ///< integrator steps of the finest run
};

/// ||h||_1 of Gamma for the linearised law `lin` whose plant (one car behind a steady lead) has
/// spectral abscissa `plant_abscissa` (< 0: stable; analyse_string gives it). The step response
/// is y = v_a + sum_j lead_j v_b(t - d_j), where v_a, v_b are the speed responses to a unit step
/// entering the gap equation and the speed equation (so that no input jumps inside a step):
///     s_a' = 1 - v_a,  v_a' = sum gap_j s_a(t - d_j) + sum own_j v_a(t - d_j),
///     s_b' =   - v_b,  v_b' = sum gap_j s_b(t - d_j) + sum own_j v_b(t - d_j) + 1,
/// zero before t = 0, integrated by DdeSolver (fourth order) with the breakpoints where the
/// derivatives jump (sums of up to three delays). Then
///     ||h||_1 = sum_k |y(z_{k+1}) - y(z_k)|
/// over the zeros z_k of h = y' (located on a grid of half steps, each by bisection of h
/// evaluated from the right-hand side) and the jumps of h at the lead delays. The run is repeated
/// with the step halved until two agree to `tolerance` (their difference is the error estimate),
/// and followed until the tail estimate max |h| over the last stretch / |plant_abscissa| is below
/// a tenth of it. Delays shorter than tolerance / (20 sum|c|) (sum over every coefficient) are
/// taken as 0, adding the estimate 10 sum |c| d over them to the error (x(t - d) - x(t) is at
/// most d max|x'|); longer ones bound the step, and a run of more than max_steps steps is
/// undecided (BudgetExhausted) rather than slow.
PeakResult peak_string_stability(const Linearisation& lin, double plant_abscissa, const PeakOptions& options = {});

/// The same, and the derivatives of ||h||_1 along `directions` into `gradient` (one per
/// direction; empty unless the result converged with a finite norm). A direction holds the
/// derivatives of `lin`'s coefficients at the same delays (d/dp of sum_j c_j e^{-s d_j} with every
/// d_j held; std::invalid_argument when it has a delay `lin` does not). The derivatives w_k of
/// the responses along direction k obey the same equations forced by the direction's
/// coefficients times the responses, integrated with them, and
///     d||h||_1 = sum over the pieces [z_k, z_{k+1}] of sign(y(z_{k+1}) - y(z_k)) (w(z_{k+1}) - w(z_k)),
/// the pieces as in the norm: the zeros z_k of h move with the parameters, but y' = 0 there, so
/// to first order only the values at the ends change (where an extremum is born or the pieces'
/// count changes, ||h||_1 is not differentiable and this is the derivative of one side). At the
/// finest run's resolution, without an error estimate of its own.
PeakResult peak_string_stability(const Linearisation& lin, double plant_abscissa, const PeakOptions& options,
                                 const std::vector<Linearisation>& directions, std::vector<double>& gradient);

}  // namespace ddemap
