#pragma once
/// \file ring_car.hpp
/// One car of a built-in nonlinear ring (traffic/nonlinear_ring.hpp: "ov", "idm") with its
/// leader's state as separate arguments, for the travelling waves of the ring
/// (analysis/travelling_wave.hpp). The state is x = (h, v) (ov: headway h; idm: gap s), and
///     x'(t) = g(x(t), x(t - tau), x_lead(t), x_lead(t - tau); p)
/// is the law of car i of the ring with x_lead = x_{i+1}:
///     ov:  h' = v_lead(t) - v(t),  v' = alpha (V(h(t - tau)) - v(t))            (OvRing)
///     idm: s' = v_lead(t) - v(t),  v' = a [1 - (v/v0)^delta - (S / s(t - tau))^2],
///          S = eta + th v(t) + v(t) (v(t) - v_lead(t - tau)) / (2 sqrt(a b))       (IdmRing)
/// As a NonlinearDDE its stacked argument is (x(t), x(t - tau), x_lead(t), x_lead(t - tau)):
/// three "delays" (tau, 0, tau), of which the last two are the leader's (is_lead). Read as a DDE
/// in x alone (the leader replaced by the car itself) it is the ring's uniform mode, not the ring:
/// the leader is the car shifted in time only in the travelling-wave form. Nothing here
/// eliminates a headway: the mean headway (the ring length / N) is the parameter headway (ov) or
/// gap (idm), imposed by the travelling-wave form as an integral condition.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/traffic/idm_ring.hpp"
#include "ddemap/traffic/ov_ring.hpp"

namespace ddemap {

class RingCar final : public NonlinearDDEOf<RingCar> {
public:
    /// The car of ring `model` ("ov" or "idm") with the named parameters, the defaults and
    /// checks of make_nonlinear_ring (std::invalid_argument naming the value otherwise).
    RingCar(const std::string& model, const ParameterMap& parameters);

    const std::string& model() const { return m_model; }
    int dimension() const override { return 2; }
    int delay_count() const override { return 3; }
    /// (tau, 0, tau)
    std::vector<double> delays(const std::vector<double>& p) const override {
        const double tau = p[static_cast<std::size_t>(m_tau)];
        return {tau, 0.0, tau};
    }
    using NonlinearDDE::delays;
    std::vector<double> delay_derivatives(const std::vector<double>&, int j) const override {
        const double d = j == m_tau ? 1.0 : 0.0;
        return {d, 0.0, d};
    }
    bool has_delay_derivatives() const override { return true; }
    /// True for the delayed arguments k = 1..3 that are the leader's (k = 2, 3).
    static bool is_lead(int k) { return k >= 2; }
    /// The index of the mean headway parameter (ov: headway, idm: gap).
    int length_parameter() const { return m_length; }
    /// The uniform flow (h, v) = (mean headway, equilibrium speed) at parameter values p (in the
    /// order of parameter_names()); std::invalid_argument when there is none (idm: gap <= eta).
    Eigen::VectorXd uniform_flow(const std::vector<double>& p) const;

    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        using std::sqrt;
        const T& v = u[1];
        const T& hd = u[2];
        const T& vl = u[5];
        const T& vld = u[7];
        out[0] = vl - v;
        if (m_ov) {
            out[1] = p[0] * (OvRing::velocity(hd, p[2], p[3]) - v);
        } else {
            const T &a = p[0], &b = p[1], &v0 = p[2], &delta = p[3], &th = p[4], &eta = p[5];
            const T desired = eta + th * v + v * (v - vld) / (2.0 * sqrt(a * b));
            const T ratio = desired / hd;
            out[1] = a * (1.0 - IdmRing::speed_term(v, v0, delta) - ratio * ratio);
        }
    }

private:
    RingCar(const std::string& model, std::vector<std::string> names, std::vector<double> values);
    std::string m_model;
    bool m_ov = true;
    int m_tau = 0, m_length = 0;
};

}  // namespace ddemap
