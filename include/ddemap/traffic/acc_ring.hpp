#pragma once
/// \file acc_ring.hpp
/// The seed paper's ACC law (OVRV with sensing delay, OvrvModel in model.hpp) with the limits
/// every real ACC system puts on the commanded acceleration, on a ring of N identical cars, as a
/// nonlinear DDE for bifurcation analysis: car i follows car i+1 (car N-1 follows car 0),
///     s_i'(t) = v_{i+1}(t) - v_i(t),
///     v_i'(t) = sat(u_i),   u_i = k1 [s_i(t - tau) - eta - th v_i(t)] + k2 [v_{i+1}(t - tau) - v_i(t)],
/// where sat is the smooth saturation between a_min < 0 < a_max with sat(0) = 0 and sat'(0) = 1
/// (so the linearisation at the uniform flow is the linear OVRV ring's):
///     sat(u) = m + A tanh(c + k u),  m = (a_max + a_min) / 2,  A = (a_max - a_min) / 2,
///     tanh(c) = -m / A,  k = 1 / (A (1 - (m / A)^2)).
/// sat is analytic, as the criticality of a Hopf point needs (its second and third derivatives
/// at 0 enter L1: sat''(0) = 2 m k / A, nonzero when the limits are asymmetric, and
/// sat'''(0) = -2 k^2 (1 - 3 (m / A)^2)). As in IdmRing the ring conserves
/// its length N gap (gap: the mean bumper-to-bumper gap) and the last gap is eliminated,
///     s_{N-1} = N gap - (s_0 + ... + s_{N-2}),
/// so the state is (s_0, ..., s_{N-2}, v_0, ..., v_{N-1}) in R^{2N-1} and the uniform flow
/// (s_i = gap, v_i = v* = (gap - eta) / th) is a regular equilibrium. Nothing keeps the speeds
/// >= 0: orbits of large amplitude report their minimum speed, which a reader checks.
/// Parameters, in this order: k1, k2, th, tau, eta, a_max, a_min, gap.

#include <cmath>

#include <Eigen/Core>

#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

class AccRing final : public NonlinearDDEOf<AccRing> {
public:
    /// N >= 2 cars; std::invalid_argument naming the value for N < 2, a non-finite parameter,
    /// k1, k2, th not > 0, tau, eta not >= 0, a_max not > 0, a_min not < 0, or gap not > eta.
    AccRing(int cars, double k1, double k2, double th, double tau, double eta, double a_max, double a_min, double gap);

    int cars() const { return m_cars; }
    int dimension() const override { return 2 * m_cars - 1; }
    int delay_count() const override { return 1; }
    std::vector<double> delays(const std::vector<double>& p) const override { return {p[3]}; }
    using NonlinearDDE::delays;
    /// d tau / d p_j: 1 for j = 3 (tau), else 0.
    std::vector<double> delay_derivatives(const std::vector<double>&, int j) const override { return {j == 3 ? 1.0 : 0.0}; }
    bool has_delay_derivatives() const override { return true; }

    /// The uniform flow at the current parameters: s_i = gap, v_i = (gap - eta) / th.
    Eigen::VectorXd uniform_flow() const;

    /// sat(u) of the header for the limits a_max > 0 > a_min.
    template <class T>
    static T saturate(const T& u, const T& a_max, const T& a_min) {
        using std::log;
        using std::tanh;
        const T m = 0.5 * (a_max + a_min), A = 0.5 * (a_max - a_min), r = m / A;
        const T c = 0.5 * log((1.0 - r) / (1.0 + r));  // atanh(-r)
        const T k = 1.0 / (A * (1.0 - r * r));
        return m + A * tanh(c + k * u);
    }

    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        const int n = m_cars, dim = 2 * n - 1;
        const T* v = u + (n - 1);
        const T* sd = u + dim;            // gaps at t - tau
        const T* vd = u + dim + (n - 1);  // speeds at t - tau
        const T &k1 = p[0], &k2 = p[1], &th = p[2], &eta = p[4], &a_max = p[5], &a_min = p[6], &gap = p[7];
        T last = static_cast<double>(n) * gap;
        for (int i = 0; i + 1 < n; ++i) {
            out[i] = v[i + 1] - v[i];
            last = last - sd[i];
        }
        for (int i = 0; i < n; ++i) {
            const T s = i + 1 < n ? sd[i] : last;
            const T command = k1 * (s - eta - th * v[i]) + k2 * (vd[(i + 1) % n] - v[i]);
            out[n - 1 + i] = saturate(command, a_max, a_min);
        }
    }

private:
    int m_cars;
};

}  // namespace ddemap
