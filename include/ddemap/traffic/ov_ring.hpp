#pragma once
/// \file ov_ring.hpp
/// The optimal velocity model with reaction delay on a ring of N cars (Orosz, Wilson and Stepan,
/// Phys. Rev. E 70, 026207, 2004): car i follows car i+1 (car N-1 follows car 0),
///     h_i'(t) = v_{i+1}(t) - v_i(t),
///     v_i'(t) = alpha (V(h_i(t - tau)) - v_i(t)),
///     V(h) = v0 (h/h_st - 1)^3 / (1 + (h/h_st - 1)^3) for h > h_st, 0 otherwise.
/// The ring conserves its length N h_mean = sum_i h_i, which makes every equilibrium of the full
/// 2N system non-isolated (a structural zero eigenvalue). Here the last headway is eliminated,
///     h_{N-1} = N headway - (h_0 + ... + h_{N-2}),
/// so the state is (h_0, ..., h_{N-2}, v_0, ..., v_{N-1}) in R^{2N-1} and the equilibria
/// (h_i = headway, v_i = V(headway)) are regular. Parameters: alpha, tau, v0, h_st, headway.

#include <Eigen/Core>

#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap {

class OvRing final : public NonlinearDDEOf<OvRing> {
public:
    /// N >= 2 cars; std::invalid_argument for N < 2 or parameters that are not finite, or
    /// alpha, tau, v0, h_st, headway not > 0 (tau >= 0).
    OvRing(int cars, double alpha, double tau, double v0 = 1.0, double h_st = 1.0, double headway = 2.0);

    int cars() const { return m_cars; }
    int dimension() const override { return 2 * m_cars - 1; }
    int delay_count() const override { return 1; }
    std::vector<double> delays(const std::vector<double>& p) const override { return {p[1]}; }
    using NonlinearDDE::delays;
    /// d tau / d p_j: 1 for j = 1 (tau), else 0.
    std::vector<double> delay_derivatives(const std::vector<double>&, int j) const override { return {j == 1 ? 1.0 : 0.0}; }
    bool has_delay_derivatives() const override { return true; }

    /// V(h) and V'(h) at the current v0, h_st.
    double optimal_velocity(double h) const;
    double optimal_velocity_slope(double h) const;
    /// The uniform flow at the current headway: h_i = headway, v_i = V(headway).
    Eigen::VectorXd uniform_flow() const;

    template <class T>
    static T velocity(const T& h, const T& v0, const T& h_st) {
        const T y = h / h_st - 1.0;
        if (!(y > 0.0)) return T(0.0);
        const T y3 = y * y * y;
        return v0 * y3 / (1.0 + y3);
    }

    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        const int n = m_cars, dim = 2 * n - 1;
        const T* v = u + (n - 1);
        const T* hd = u + dim;  // headways at t - tau
        T last = static_cast<double>(n) * p[4];
        for (int i = 0; i + 1 < n; ++i) {
            out[i] = v[i + 1] - v[i];
            last = last - hd[i];
        }
        for (int i = 0; i < n; ++i) {
            const T h = i + 1 < n ? hd[i] : last;
            out[n - 1 + i] = p[0] * (velocity(h, p[2], p[3]) - v[i]);
        }
    }

private:
    int m_cars;
};

}  // namespace ddemap
