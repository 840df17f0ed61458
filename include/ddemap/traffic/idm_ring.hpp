#pragma once
/// \file idm_ring.hpp
/// The intelligent driver model with sensing delay (Treiber, Hennecke and Helbing 2000; the law
/// of IdmModel in model.hpp) on a ring of N identical cars, as a nonlinear DDE for bifurcation
/// analysis: car i follows car i+1 (car N-1 follows car 0),
///     s_i'(t) = v_{i+1}(t) - v_i(t),
///     v_i'(t) = a [1 - (v_i(t) / v0)^delta - (S_i / s_i(t - tau))^2],
///     S_i = eta + th v_i(t) + v_i(t) (v_i(t) - v_{i+1}(t - tau)) / (2 sqrt(a b)),
/// with (v / v0)^delta read as 0 for v <= 0. The ring conserves its length N gap = sum_i s_i
/// (gap: the mean bumper-to-bumper gap), which makes every equilibrium of the 2N-dimensional
/// system non-isolated; as in OvRing the last gap is eliminated,
///     s_{N-1} = N gap - (s_0 + ... + s_{N-2}),
/// so the state is (s_0, ..., s_{N-2}, v_0, ..., v_{N-1}) in R^{2N-1} and the uniform flow
/// (s_i = gap, v_i = v*(gap), the speed at which IdmModel's equilibrium gap
/// s*(v) = (eta + th v) / sqrt(1 - (v/v0)^delta) equals gap) is a regular equilibrium.
/// Parameters, in this order: a, b, v0, delta, th, eta, tau, gap.

#include <Eigen/Core>

#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

class IdmRing final : public NonlinearDDEOf<IdmRing> {
public:
    /// N >= 2 cars; std::invalid_argument naming the value for N < 2, a non-finite parameter,
    /// a, b, v0, delta not > 0, th, eta, tau not >= 0, or gap not > eta (no uniform flow).
    IdmRing(int cars, double a, double b, double v0, double delta, double th, double eta, double tau, double gap);

    int cars() const { return m_cars; }
    int dimension() const override { return 2 * m_cars - 1; }
    int delay_count() const override { return 1; }
    std::vector<double> delays(const std::vector<double>& p) const override { return {p[6]}; }
    using NonlinearDDE::delays;
    /// d tau / d p_j: 1 for j = 6 (tau), else 0.
    std::vector<double> delay_derivatives(const std::vector<double>&, int j) const override { return {j == 6 ? 1.0 : 0.0}; }
    bool has_delay_derivatives() const override { return true; }

    /// v*(gap) at the current parameters: the root of s*(v) = gap in [0, v0) (s* increases from
    /// eta to infinity), by bisection to the last bit; std::invalid_argument when gap <= eta.
    double equilibrium_speed(double gap) const;
    /// The uniform flow at the current gap: s_i = gap, v_i = v*(gap).
    Eigen::VectorXd uniform_flow() const;

    template <class T>
    static T speed_term(const T& v, const T& v0, const T& delta) {
        if (!(v > 0.0)) return T(0.0);
        return exp(delta * log(v / v0));
    }

    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        using std::exp;
        using std::log;
        using std::sqrt;
        const int n = m_cars, dim = 2 * n - 1;
        const T* v = u + (n - 1);
        const T* sd = u + dim;              // gaps at t - tau
        const T* vd = u + dim + (n - 1);    // speeds at t - tau
        const T &a = p[0], &b = p[1], &v0 = p[2], &delta = p[3], &th = p[4], &eta = p[5], &gap = p[7];
        T last = static_cast<double>(n) * gap;
        for (int i = 0; i + 1 < n; ++i) {
            out[i] = v[i + 1] - v[i];
            last = last - sd[i];
        }
        const T two_sqrt_ab = 2.0 * sqrt(a * b);
        for (int i = 0; i < n; ++i) {
            const T s = i + 1 < n ? sd[i] : last;
            const T& lead = vd[(i + 1) % n];
            const T desired = eta + th * v[i] + v[i] * (v[i] - lead) / two_sqrt_ab;
            const T ratio = desired / s;
            out[n - 1 + i] = a * (1.0 - speed_term(v[i], v0, delta) - ratio * ratio);
        }
    }

private:
    int m_cars;
};

}  // namespace ddemap
