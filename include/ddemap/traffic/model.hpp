#pragma once
/// \file model.hpp
/// Car-following models: the law v_i' = F(s_i(t - tau), v_i(t), v_{i-1}(t - tau), ...) (more cars
/// ahead for connected cruise control), its equilibria and its linearisation. Nothing downstream depends on a particular law: the ring,
/// the transfer function and the charts see only the Linearisation.

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "ddemap/core/dual.hpp"
#include "ddemap/core/parameters.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/problem/expoly.hpp"

namespace ddemap {

/// The largest speed of a road vehicle the readers take, in m/s (360 km/h): a lead profile, a
/// platoon or a trace above it is refused as bad input (a speed in km/h, a corrupt row), never
/// integrated into a non-finite number.
inline constexpr double kMaxRoadSpeed = 100.0;

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

/// The largest magnitude of any law parameter, in its unit: beyond it the products the
/// analyses form (k1 (1 + th), eta + th v, N (eta + th v) for a ring) leave double range or mean
/// nothing physical; refused with the value and the unit.
constexpr double kMaxParameterMagnitude = 1e12;
/// The smallest magnitude of a nonzero law parameter, the smallest normal double (2.2e-308):
/// below it (a subnormal delay such as 1e-320) 1 / tau and the root bounds overflow to
/// infinity; refused, 0 itself is allowed (tau = 1e-300 is computed, tests/analysis/stability/test_verdicts.cpp).
constexpr double kMinParameterMagnitude = 2.2250738585072014e-308;

/// The car-following law. Implementations validate their parameters on construction and
/// throw std::invalid_argument with a one-line message naming the value and what was expected.
///
/// The law takes 2 + leaders() inputs, each with its own delay (input_delays()):
///     in[0] = s_i(t - d_0)        the own gap,
///     in[1] = v_i(t - d_1)        the own speed (d_1 = 0 for the built-in laws),
///     in[2 + j] = v_{i-1-j}(t - d_{2+j})   the speed of the car j + 1 ahead,
/// and the law parameters p (law_parameter_names(); the operating speed is not one of them):
///     v_i'(t) = F(in; p).
/// F is written once as a template (CarModelOf) and evaluated in doubles or in dual numbers, so
/// linearise() is the exact derivative of the same law that simulations integrate.
class CarModel {
public:
    virtual ~CarModel() = default;
    virtual std::string name() const = 0;
    /// The law as a formula, for help texts and reports.
    virtual std::string law() const = 0;
    virtual ParameterMap parameters() const = 0;
    /// The sensing delay tau: the gap and the speed of the car ahead enter F delayed by tau.
    virtual double delay() const = 0;
    /// Equilibrium gap s*(v) with F(s*, v, v, ..., v) = 0.
    virtual double equilibrium_gap(double speed) const = 0;
    /// The speed about which the model is linearised (for laws whose linearisation depends on it).
    virtual double operating_speed() const = 0;
    /// Cars ahead whose speed the law uses (1: the predecessor only).
    virtual int leaders() const { return 1; }
    /// Number of inputs of F: 2 + leaders().
    int inputs() const { return 2 + leaders(); }

    /// Names of the law parameters p, in the order F takes them.
    virtual std::vector<std::string> law_parameter_names() const = 0;
    /// Their current values.
    const std::vector<double>& law_parameter_values() const { return m_law; }
    /// The delays d_0, ..., d_{1+leaders()} of the inputs for law parameters p.
    virtual std::vector<double> input_delays(const double* p) const = 0;
    /// The delays at the current parameters.
    std::vector<double> input_delays() const { return input_delays(m_law.data()); }

    /// F(in; p) in doubles and in dual numbers (in: inputs() values; p: law parameters).
    virtual double evaluate(const double* in, const double* p) const = 0;
    virtual Dual<double> evaluate(const Dual<double>* in, const Dual<double>* p) const = 0;

    /// F at the current parameters for the own gap, the own speed and the speeds of the
    /// leaders() cars ahead (car ahead first). std::invalid_argument when the number of leader
    /// speeds is not leaders().
    double acceleration(double gap, double speed, const std::vector<double>& leader_speeds) const;
    /// F at the current parameters for inputs() values (no checks; for inner loops).
    double acceleration(const double* in) const { return evaluate(in, m_law.data()); }

    /// The partials of F at the given inputs as a Linearisation with the input delays:
    ///     gap = dF/din_0 e^{-s d_0}, own = dF/din_1 e^{-s d_1}, lead = dF/din_2 e^{-s d_2},
    ///     further[j] = dF/din_{3+j} e^{-s d_{3+j}};  exact (dual numbers).
    Linearisation linearise_at(double gap, double speed, const std::vector<double>& leader_speeds) const;
    /// The Linearisation at the equilibrium (s*(v*), v*, v*, ..., v*), v* = operating_speed().
    Linearisation linearise() const;

protected:
    std::vector<double> m_law;  ///< law parameter values, in the order of law_parameter_names()
};

/// Implements CarModel::evaluate for doubles and dual numbers from one member template
///     template <class T> static T law(const T* in, const T* p);
template <class Derived>
class CarModelOf : public CarModel {
public:
    double evaluate(const double* in, const double* p) const override { return Derived::law(in, p); }
    Dual<double> evaluate(const Dual<double>* in, const Dual<double>* p) const override { return Derived::law(in, p); }
};

/// OVRV with sensing delay (the seed paper's eq. 3):
///     F = k1 [ s(t - tau) - eta - th v(t) ] + k2 [ v_lead(t - tau) - v(t) ];
///     f_s = k1, f_v = -(k1 th + k2), f_l = k2; s*(v) = eta + th v.
/// Law parameters (k1, k2, th, tau, eta).
class OvrvModel final : public CarModelOf<OvrvModel> {
public:
    explicit OvrvModel(const ParameterMap& p);
    std::string name() const override { return "ovrv"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    double equilibrium_gap(double speed) const override { return m_eta + m_th * speed; }
    double operating_speed() const override { return m_speed; }
    std::vector<std::string> law_parameter_names() const override { return {"k1", "k2", "th", "tau", "eta"}; }
    std::vector<double> input_delays(const double* p) const override { return {p[3], 0.0, p[3]}; }
    template <class T>
    static T law(const T* in, const T* p) {
        return p[0] * (in[0] - p[4] - p[2] * in[1]) + p[1] * (in[2] - in[1]);
    }

private:
    double m_k1, m_k2, m_th, m_tau, m_eta, m_speed;
};

/// Connected cruise control (after Orosz and co-workers): OVRV plus the speed of the car two
/// ahead, received over V2V with its own delay tau2:
///     F = k1 [ s(t - tau) - eta - th v(t) ] + k2 [ v_{i-1}(t - tau) - v(t) ] + k3 [ v_{i-2}(t - tau2) - v(t) ];
///     gap = k1 e^{-s tau}, own = -(k1 th + k2 + k3), lead = k2 e^{-s tau}, further[0] = k3 e^{-s tau2}.
/// Law parameters (k1, k2, k3, th, tau, tau2, eta); inputs (s, v, v_{i-1}, v_{i-2}).
class CccModel final : public CarModelOf<CccModel> {
public:
    explicit CccModel(const ParameterMap& p);
    std::string name() const override { return "ccc"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    double equilibrium_gap(double speed) const override { return m_eta + m_th * speed; }
    double operating_speed() const override { return m_speed; }
    int leaders() const override { return 2; }
    std::vector<std::string> law_parameter_names() const override { return {"k1", "k2", "k3", "th", "tau", "tau2", "eta"}; }
    std::vector<double> input_delays(const double* p) const override { return {p[4], 0.0, p[4], p[5]}; }
    template <class T>
    static T law(const T* in, const T* p) {
        return p[0] * (in[0] - p[6] - p[3] * in[1]) + p[1] * (in[2] - in[1]) + p[2] * (in[3] - in[1]);
    }

private:
    double m_k1, m_k2, m_k3, m_th, m_tau, m_tau2, m_eta, m_speed;
};

/// Intelligent driver model (Treiber, Hennecke, Helbing 2000) with sensing delay:
///     F = a [ 1 - (v / v0)^delta - (S / s(t - tau))^2 ],
///     S = eta + th v + v (v - v_lead(t - tau)) / (2 sqrt(a b));
///     s*(v) = (eta + th v) / sqrt(1 - (v / v0)^delta).
/// Linearised at the operating speed v* = speed (0 <= speed < v0).
/// Law parameters (a, b, v0, delta, th, eta, tau).
class IdmModel final : public CarModelOf<IdmModel> {
public:
    explicit IdmModel(const ParameterMap& p);
    std::string name() const override { return "idm"; }
    std::string law() const override;
    ParameterMap parameters() const override;
    double delay() const override { return m_tau; }
    double equilibrium_gap(double speed) const override;
    double operating_speed() const override { return m_speed; }
    std::vector<std::string> law_parameter_names() const override { return {"a", "b", "v0", "delta", "th", "eta", "tau"}; }
    std::vector<double> input_delays(const double* p) const override { return {p[6], 0.0, p[6]}; }
    template <class T>
    static T law(const T* in, const T* p) {
        const T& v = in[1];
        const T s_star = p[5] + p[4] * v + v * (v - in[2]) / (2.0 * sqrt(p[0] * p[1]));
        const T r = s_star / in[0];
        // (v / v0)^delta, 0 at standstill (with derivative 0: delta > 0 is required)
        const T free_road = value_of(v) > 0.0 ? pow(v / p[2], p[3]) : T(0.0);
        return p[0] * (1.0 - free_road - r * r);
    }

private:
    double m_a, m_b, m_v0, m_delta, m_th, m_eta, m_tau, m_speed;
};

/// Names of the built-in models.
std::vector<std::string> model_names();
/// Parameter specifications of a built-in model (std::invalid_argument for an unknown name).
std::vector<ParameterSpec> model_parameters(const std::string& model);
/// The unit of a parameter of the built-in models (the same in every model that has it; "speed"
/// included), "" for a name none of them has: what column headers carry (`k1_per_s2`).
std::string parameter_unit(const std::string& name);
/// Builds a model from named values; missing required values, unknown names, non-finite or
/// out-of-range values throw std::invalid_argument.
std::unique_ptr<CarModel> make_model(const std::string& model, const ParameterMap& values);

}  // namespace ddemap
