#pragma once
/// \file model.hpp
/// Car-following models: the law v_i' = F(s_i(t - tau), v_i(t), v_{i-1}(t - tau)), its
/// equilibria and its linearisation. Nothing downstream depends on a particular law: the ring,
/// the transfer function and the charts see only the Linearisation.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ddemap/core/parameters.hpp"
#include "ddemap/expoly.hpp"

namespace ddemap {

/// Linearisation about an equilibrium of a car that reacts to its own gap and speed and to the
/// speed of the car ahead:
///     s_i'(t) = v_{i-1}(t) - v_i(t),
///     v_i'(t) = (gap * s_i)(t) + (own * v_i)(t) + (lead * v_{i-1})(t),
/// where (E * x)(t) = sum_j c_j x(t - d_j) for E(s) = sum_j c_j e^{-s d_j}. For a law
/// F(s(t - tau), v(t), v_lead(t - tau)) with partials f_s, f_v, f_l:
/// gap = f_s e^{-s tau}, own = f_v, lead = f_l e^{-s tau}.
///
/// Connected cruise control adds the speeds of cars further ahead, each with its own delays:
///     v_i'(t) = ... + sum_j (further[j] * v_{i-2-j})(t),
/// so further[0] acts on the car two ahead. Analyses built on one leader (the head-to-tail
/// transfer function, the plant, simulation) reject a Linearisation with `further` terms; the
/// ring (Fourier modes and the full system) accepts it.
struct Linearisation {
    ExpPoly gap;
    ExpPoly own;
    ExpPoly lead;
    std::vector<ExpPoly> further;
    double max_delay() const;
    /// Number of cars ahead whose speed is used (1 + further.size()).
    int leaders() const { return 1 + static_cast<int>(further.size()); }
};

/// Throws std::invalid_argument naming `analysis` when `lin` uses more than one leader.
void require_single_leader(const Linearisation& lin, const std::string& analysis);

/// Description of one named model parameter.
struct ParameterSpec {
    std::string name;
    std::string unit;
    std::string description;
    bool required = true;        ///< must be given (no default)
    double default_value = 0.0;  ///< used when not required and not given
    double lower = 0.0;          ///< smallest valid value
    bool lower_open = false;     ///< lower bound excluded (value must be > lower)
};

/// The car-following law. Implementations validate their parameters on construction and
/// throw std::invalid_argument with a one-line message naming the value and what was expected.
class CarModel {
public:
    virtual ~CarModel() = default;
    virtual std::string name() const = 0;
    /// The law as a formula, for help texts and reports.
    virtual std::string law() const = 0;
    virtual ParameterMap parameters() const = 0;
    /// The sensing delay tau: gap and lead speed enter F delayed by tau.
    virtual double delay() const = 0;
    /// F(s, v, v_lead): acceleration for delayed gap s, current speed v, delayed lead speed.
    virtual double acceleration(double gap, double speed, double lead_speed) const = 0;
    /// Equilibrium gap s*(v) with F(s*, v, v) = 0.
    virtual double equilibrium_gap(double speed) const = 0;
    /// The speed about which the model is linearised (for laws whose linearisation depends on it).
    virtual double operating_speed() const = 0;
    /// Partials of F at (s*(v*), v*, v*), as a Linearisation with the delays of the law.
    virtual Linearisation linearise() const = 0;
    /// Cars ahead whose speed the law uses (1: the predecessor only).
    virtual int leaders() const { return 1; }
};

/// OVRV with sensing delay (the seed paper's eq. 3):
///     F = k1 [ s(t - tau) - eta - th v(t) ] + k2 [ v_lead(t - tau) - v(t) ];
///     f_s = k1, f_v = -(k1 th + k2), f_l = k2; s*(v) = eta + th v.
class OvrvModel final : public CarModel {
public:
    explicit OvrvModel(const ParameterMap& p);
    std::string name() const override { return "ovrv"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    double acceleration(double gap, double speed, double lead_speed) const override;
    double equilibrium_gap(double speed) const override { return m_eta + m_th * speed; }
    double operating_speed() const override { return m_speed; }
    Linearisation linearise() const override;

private:
    double m_k1, m_k2, m_th, m_tau, m_eta, m_speed;
};

/// Connected cruise control (after Orosz and co-workers): OVRV plus the speed of the car two
/// ahead, received over V2V with its own delay tau2:
///     F = k1 [ s(t - tau) - eta - th v(t) ] + k2 [ v_{i-1}(t - tau) - v(t) ] + k3 [ v_{i-2}(t - tau2) - v(t) ];
///     gap = k1 e^{-s tau}, own = -(k1 th + k2 + k3), lead = k2 e^{-s tau}, further[0] = k3 e^{-s tau2}.
/// acceleration() of the one-leader interface is not defined for it (leaders() = 2).
class CccModel final : public CarModel {
public:
    explicit CccModel(const ParameterMap& p);
    std::string name() const override { return "ccc"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    /// With the car two ahead at lead_speed too (the one-leader view); simulation rejects CCC.
    double acceleration(double gap, double speed, double lead_speed) const override;
    double equilibrium_gap(double speed) const override { return m_eta + m_th * speed; }
    double operating_speed() const override { return m_speed; }
    Linearisation linearise() const override;
    int leaders() const override { return 2; }

private:
    double m_k1, m_k2, m_k3, m_th, m_tau, m_tau2, m_eta, m_speed;
};

/// Intelligent driver model (Treiber, Hennecke, Helbing 2000) with sensing delay:
///     F = a [ 1 - (v / v0)^delta - (S / s(t - tau))^2 ],
///     S = eta + th v + v (v - v_lead(t - tau)) / (2 sqrt(a b));
///     s*(v) = (eta + th v) / sqrt(1 - (v / v0)^delta).
/// Linearised at the operating speed v* = speed (0 <= speed < v0).
class IdmModel final : public CarModel {
public:
    explicit IdmModel(const ParameterMap& p);
    std::string name() const override { return "idm"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    double acceleration(double gap, double speed, double lead_speed) const override;
    double equilibrium_gap(double speed) const override;
    double operating_speed() const override { return m_speed; }
    Linearisation linearise() const override;

private:
    double m_a, m_b, m_v0, m_delta, m_th, m_eta, m_tau, m_speed;
};

/// Names of the built-in models.
std::vector<std::string> model_names();
/// Parameter specifications of a built-in model (std::invalid_argument for an unknown name).
std::vector<ParameterSpec> model_parameters(const std::string& model);
/// Builds a model from named values; missing required values, unknown names, non-finite or
/// out-of-range values throw std::invalid_argument.
std::unique_ptr<CarModel> make_model(const std::string& model, const ParameterMap& values);

}  // namespace ddemap
