#include "ddemap/traffic/model.hpp"

#include "ddemap/core/text.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ddemap {

double Linearisation::max_delay() const {
    double d = std::max({gap.max_delay(), own.max_delay(), lead.max_delay()});
    for (const auto& f : further) d = std::max(d, f.max_delay());
    return d;
}

void require_single_leader(const Linearisation& lin, const std::string& analysis) {
    if (lin.leaders() > 1)
        throw std::invalid_argument(analysis + " needs a law that uses only the car ahead; this one uses " +
                                    std::to_string(lin.leaders()) + " cars ahead (analyse it as a ring or a fleet)");
}

namespace {

const std::vector<ParameterSpec>& ovrv_specs() {
    static const std::vector<ParameterSpec> specs = {
        {"k1", "1/s^2", "gain on the gap error s - eta - th v", true, 0.0, 0.0, false},
        {"k2", "1/s", "gain on the speed difference v_lead - v", true, 0.0, 0.0, false},
        {"th", "s", "time headway", true, 0.0, 0.0, false},
        {"tau", "s", "sensing delay", true, 0.0, 0.0, false},
        {"eta", "m", "jam (standstill) gap", false, 10.0, 0.0, false},
        {"speed", "m/s", "equilibrium speed (the linearisation does not depend on it)", false, 20.0, 0.0, false},
    };
    return specs;
}

const std::vector<ParameterSpec>& ccc_specs() {
    static const std::vector<ParameterSpec> specs = {
        {"k1", "1/s^2", "gain on the gap error s - eta - th v", true, 0.0, 0.0, false},
        {"k2", "1/s", "gain on the speed difference to the car ahead", true, 0.0, 0.0, false},
        {"k3", "1/s", "gain on the speed difference to the car two ahead (V2V)", true, 0.0, 0.0, false},
        {"th", "s", "time headway", true, 0.0, 0.0, false},
        {"tau", "s", "sensing delay (gap, car ahead)", true, 0.0, 0.0, false},
        {"tau2", "s", "delay of the V2V signal from the car two ahead", true, 0.0, 0.0, false},
        {"eta", "m", "jam (standstill) gap", false, 10.0, 0.0, false},
        {"speed", "m/s", "equilibrium speed (the linearisation does not depend on it)", false, 20.0, 0.0, false},
    };
    return specs;
}

const std::vector<ParameterSpec>& idm_specs() {
    static const std::vector<ParameterSpec> specs = {
        {"a", "m/s^2", "maximum acceleration", false, 1.0, 0.0, true},
        {"b", "m/s^2", "comfortable deceleration", false, 1.5, 0.0, true},
        {"v0", "m/s", "desired speed", false, 33.3, 0.0, true},
        {"delta", "1", "acceleration exponent", false, 4.0, 0.0, true},
        {"th", "s", "time headway", true, 0.0, 0.0, false},
        {"tau", "s", "sensing delay", true, 0.0, 0.0, false},
        {"eta", "m", "jam (standstill) gap s0", false, 2.0, 0.0, false},
        {"speed", "m/s", "equilibrium speed about which the model is linearised", false, 20.0, 0.0, false},
    };
    return specs;
}

/// Fills every parameter from `values` or its default, validating finiteness and the bound.
ParameterMap resolve(const std::string& model, const std::vector<ParameterSpec>& specs, const ParameterMap& values) {
    for (const auto& [name, value] : values) {
        (void)value;
        if (std::none_of(specs.begin(), specs.end(), [&](const ParameterSpec& s) { return s.name == name; })) {
            std::string known;
            for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
            throw std::invalid_argument("parameter '" + name + "' does not belong to model " + model +
                                        ": expected one of " + known);
        }
    }
    ParameterMap out;
    for (const auto& s : specs) {
        auto it = values.find(s.name);
        if (it == values.end()) {
            if (s.required) throw std::invalid_argument("model " + model + " needs " + s.name + " [" + s.unit + "] (" + s.description + ")");
            out[s.name] = s.default_value;
            continue;
        }
        const double v = it->second;
        if (!std::isfinite(v)) throw std::invalid_argument(s.name + " = " + detail::format_number(v) + ": expected a finite number [" + s.unit + "]");
        if (s.lower_open ? !(v > s.lower) : !(v >= s.lower)) {
            throw std::invalid_argument(s.name + " = " + detail::format_number(v) + ": expected a value " + (s.lower_open ? "> " : ">= ") +
                                        detail::format_number(s.lower) + " [" + s.unit + "]");
        }
        out[s.name] = v;
    }
    return out;
}

}  // namespace

// ---------------------------------------------------------------- OVRV

OvrvModel::OvrvModel(const ParameterMap& values) {
    const ParameterMap p = resolve("ovrv", ovrv_specs(), values);
    m_k1 = p.at("k1");
    m_k2 = p.at("k2");
    m_th = p.at("th");
    m_tau = p.at("tau");
    m_eta = p.at("eta");
    m_speed = p.at("speed");
}

std::string OvrvModel::law() const {
    return "v'(t) = k1 [s(t-tau) - eta - th v(t)] + k2 [v_lead(t-tau) - v(t)]";
}

ParameterMap OvrvModel::parameters() const {
    return {{"k1", m_k1}, {"k2", m_k2}, {"th", m_th}, {"tau", m_tau}, {"eta", m_eta}, {"speed", m_speed}};
}

double OvrvModel::acceleration(double gap, double speed, double lead_speed) const {
    return m_k1 * (gap - m_eta - m_th * speed) + m_k2 * (lead_speed - speed);
}

Linearisation OvrvModel::linearise() const {
    Linearisation l;
    l.gap.add(m_k1, m_tau);
    l.own.add(-(m_k1 * m_th + m_k2), 0.0);
    l.lead.add(m_k2, m_tau);
    return l;
}

// ---------------------------------------------------------------- CCC

CccModel::CccModel(const ParameterMap& values) {
    const ParameterMap p = resolve("ccc", ccc_specs(), values);
    m_k1 = p.at("k1");
    m_k2 = p.at("k2");
    m_k3 = p.at("k3");
    m_th = p.at("th");
    m_tau = p.at("tau");
    m_tau2 = p.at("tau2");
    m_eta = p.at("eta");
    m_speed = p.at("speed");
}

std::string CccModel::law() const {
    return "v'(t) = k1 [s(t-tau) - eta - th v(t)] + k2 [v_{i-1}(t-tau) - v(t)] + k3 [v_{i-2}(t-tau2) - v(t)]";
}

ParameterMap CccModel::parameters() const {
    return {{"k1", m_k1}, {"k2", m_k2}, {"k3", m_k3}, {"th", m_th}, {"tau", m_tau}, {"tau2", m_tau2}, {"eta", m_eta}, {"speed", m_speed}};
}

double CccModel::acceleration(double gap, double speed, double lead_speed) const {
    return m_k1 * (gap - m_eta - m_th * speed) + (m_k2 + m_k3) * (lead_speed - speed);
}

Linearisation CccModel::linearise() const {
    Linearisation l;
    l.gap.add(m_k1, m_tau);
    l.own.add(-(m_k1 * m_th + m_k2 + m_k3), 0.0);
    l.lead.add(m_k2, m_tau);
    ExpPoly two;
    two.add(m_k3, m_tau2);
    l.further.push_back(two);
    return l;
}

// ---------------------------------------------------------------- IDM

IdmModel::IdmModel(const ParameterMap& values) {
    const ParameterMap p = resolve("idm", idm_specs(), values);
    m_a = p.at("a");
    m_b = p.at("b");
    m_v0 = p.at("v0");
    m_delta = p.at("delta");
    m_th = p.at("th");
    m_eta = p.at("eta");
    m_tau = p.at("tau");
    m_speed = p.at("speed");
    if (!(m_speed < m_v0)) {
        throw std::invalid_argument("speed = " + detail::format_number(m_speed) + ": expected an equilibrium speed below v0 = " + detail::format_number(m_v0) + " m/s");
    }
    if (m_eta + m_th * m_speed <= 0.0) {
        throw std::invalid_argument("eta + th * speed = 0: the IDM equilibrium gap vanishes; expected eta > 0 or th * speed > 0");
    }
}

std::string IdmModel::law() const {
    return "v'(t) = a [1 - (v/v0)^delta - (S/s(t-tau))^2], S = eta + th v + v (v - v_lead(t-tau)) / (2 sqrt(a b))";
}

ParameterMap IdmModel::parameters() const {
    return {{"a", m_a}, {"b", m_b}, {"v0", m_v0}, {"delta", m_delta}, {"th", m_th},
            {"eta", m_eta}, {"tau", m_tau}, {"speed", m_speed}};
}

double IdmModel::acceleration(double gap, double speed, double lead_speed) const {
    const double s_star = m_eta + m_th * speed + speed * (speed - lead_speed) / (2.0 * std::sqrt(m_a * m_b));
    const double r = s_star / gap;
    return m_a * (1.0 - std::pow(speed / m_v0, m_delta) - r * r);
}

double IdmModel::equilibrium_gap(double speed) const {
    return (m_eta + m_th * speed) / std::sqrt(1.0 - std::pow(speed / m_v0, m_delta));
}

Linearisation IdmModel::linearise() const {
    const double v = m_speed;
    const double s = equilibrium_gap(v);
    const double sd = m_eta + m_th * v;  // desired gap S at equilibrium
    const double sab = 2.0 * std::sqrt(m_a * m_b);
    const double f_s = 2.0 * m_a * sd * sd / (s * s * s);
    const double dpow = v > 0.0 ? m_delta * std::pow(v, m_delta - 1.0) / std::pow(m_v0, m_delta) : 0.0;
    const double f_v = -m_a * (dpow + 2.0 * sd / (s * s) * (m_th + v / sab));
    const double f_l = m_a * 2.0 * sd / (s * s) * (v / sab);
    Linearisation l;
    l.gap.add(f_s, m_tau);
    l.own.add(f_v, 0.0);
    l.lead.add(f_l, m_tau);
    return l;
}

// ---------------------------------------------------------------- registry

std::vector<std::string> model_names() { return {"ovrv", "idm", "ccc"}; }

std::vector<ParameterSpec> model_parameters(const std::string& model) {
    if (model == "ovrv") return ovrv_specs();
    if (model == "idm") return idm_specs();
    if (model == "ccc") return ccc_specs();
    throw std::invalid_argument("model '" + model + "': expected one of ovrv, idm, ccc");
}

std::unique_ptr<CarModel> make_model(const std::string& model, const ParameterMap& values) {
    if (model == "ovrv") return std::make_unique<OvrvModel>(values);
    if (model == "idm") return std::make_unique<IdmModel>(values);
    if (model == "ccc") return std::make_unique<CccModel>(values);
    throw std::invalid_argument("model '" + model + "': expected one of ovrv, idm, ccc");
}

}  // namespace ddemap
