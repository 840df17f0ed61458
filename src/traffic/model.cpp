#include "ddemap/traffic/model.hpp"

#include "core/internal/text.hpp"

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
    for (const auto& entry : values) {
        const std::string& name = entry.first;
        if (std::none_of(specs.begin(), specs.end(), [&](const ParameterSpec& s) { return s.name == name; })) {
            std::string known;
            for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
            throw std::invalid_argument("parameter " + detail::quoted(name) + " does not belong to model " + model +
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
        if (std::abs(v) > kMaxParameterMagnitude)
            throw std::invalid_argument(s.name + " = " + detail::format_number(v) + ": expected at most 1e12 [" +
                                        s.unit + "] in magnitude");
        if (v != 0.0 && std::abs(v) < kMinParameterMagnitude)
            throw std::invalid_argument(s.name + " = " + detail::format_number(v) + ": expected 0 or a magnitude of at least 2.2e-308 (a subnormal number overflows 1 / x) [" + s.unit + "]");
        if (s.lower_open ? !(v > s.lower) : !(v >= s.lower)) {
            throw std::invalid_argument(s.name + " = " + detail::format_number(v) + ": expected a value " + (s.lower_open ? "> " : ">= ") +
                                        detail::format_number(s.lower) + " [" + s.unit + "]");
        }
        out[s.name] = v;
    }
    return out;
}

}  // namespace

// ---------------------------------------------------------------- the law

double CarModel::acceleration(double gap, double speed, const std::vector<double>& leader_speeds) const {
    if (static_cast<int>(leader_speeds.size()) != leaders())
        throw std::invalid_argument("model " + name() + " uses the speeds of " + std::to_string(leaders()) + " cars ahead; " +
                                    std::to_string(leader_speeds.size()) + " given");
    std::vector<double> in{gap, speed};
    in.insert(in.end(), leader_speeds.begin(), leader_speeds.end());
    return evaluate(in.data(), m_law.data());
}

Linearisation CarModel::linearise_at(double gap, double speed, const std::vector<double>& leader_speeds) const {
    if (static_cast<int>(leader_speeds.size()) != leaders())
        throw std::invalid_argument("model " + name() + " uses the speeds of " + std::to_string(leaders()) + " cars ahead; " +
                                    std::to_string(leader_speeds.size()) + " given");
    const int k = inputs();
    std::vector<Dual<double>> in(k), p(m_law.begin(), m_law.end());
    in[0] = gap;
    in[1] = speed;
    for (int j = 0; j < leaders(); ++j) in[2 + j] = leader_speeds[j];
    std::vector<double> partial(k);
    for (int i = 0; i < k; ++i) {
        in[i].deriv = 1.0;
        partial[i] = evaluate(in.data(), p.data()).deriv;
        in[i].deriv = 0.0;
    }
    const std::vector<double> d = input_delays();
    Linearisation l;
    l.gap.add(partial[0], d[0]);
    l.own.add(partial[1], d[1]);
    l.lead.add(partial[2], d[2]);
    for (int j = 1; j < leaders(); ++j) {
        ExpPoly e;
        e.add(partial[2 + j], d[2 + j]);
        l.further.push_back(e);
    }
    return l;
}

Linearisation CarModel::linearise() const {
    const double v = operating_speed();
    return linearise_at(equilibrium_gap(v), v, std::vector<double>(leaders(), v));
}

// ---------------------------------------------------------------- OVRV

OvrvModel::OvrvModel(const ParameterMap& values) {
    const ParameterMap p = resolve("ovrv", ovrv_specs(), values);
    m_k1 = p.at("k1");
    m_k2 = p.at("k2");
    m_th = p.at("th");
    m_tau = p.at("tau");
    m_eta = p.at("eta");
    m_speed = p.at("speed");
    m_law = {m_k1, m_k2, m_th, m_tau, m_eta};
}

std::string OvrvModel::law() const {
    return "v'(t) = k1 [s(t-tau) - eta - th v(t)] + k2 [v_lead(t-tau) - v(t)]";
}

ParameterMap OvrvModel::parameters() const {
    return {{"k1", m_k1}, {"k2", m_k2}, {"th", m_th}, {"tau", m_tau}, {"eta", m_eta}, {"speed", m_speed}};
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
    m_law = {m_k1, m_k2, m_k3, m_th, m_tau, m_tau2, m_eta};
}

std::string CccModel::law() const {
    return "v'(t) = k1 [s(t-tau) - eta - th v(t)] + k2 [v_{i-1}(t-tau) - v(t)] + k3 [v_{i-2}(t-tau2) - v(t)]";
}

ParameterMap CccModel::parameters() const {
    return {{"k1", m_k1}, {"k2", m_k2}, {"k3", m_k3}, {"th", m_th}, {"tau", m_tau}, {"tau2", m_tau2}, {"eta", m_eta}, {"speed", m_speed}};
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
    m_law = {m_a, m_b, m_v0, m_delta, m_th, m_eta, m_tau};
}

std::string IdmModel::law() const {
    return "v'(t) = a [1 - (v/v0)^delta - (S/s(t-tau))^2], S = eta + th v + v (v - v_lead(t-tau)) / (2 sqrt(a b))";
}

ParameterMap IdmModel::parameters() const {
    return {{"a", m_a}, {"b", m_b}, {"v0", m_v0}, {"delta", m_delta}, {"th", m_th},
            {"eta", m_eta}, {"tau", m_tau}, {"speed", m_speed}};
}

double IdmModel::equilibrium_gap(double speed) const {
    return (m_eta + m_th * speed) / std::sqrt(1.0 - std::pow(speed / m_v0, m_delta));
}

// ---------------------------------------------------------------- registry

std::vector<std::string> model_names() { return {"ovrv", "idm", "ccc"}; }

std::vector<ParameterSpec> model_parameters(const std::string& model) {
    if (model == "ovrv") return ovrv_specs();
    if (model == "idm") return idm_specs();
    if (model == "ccc") return ccc_specs();
    throw std::invalid_argument("model " + detail::quoted(model) + ": expected one of ovrv, idm, ccc");
}

std::string parameter_unit(const std::string& name) {
    for (const auto& m : model_names())
        for (const auto& spec : model_parameters(m))
            if (spec.name == name) return spec.unit;
    return "";
}

std::unique_ptr<CarModel> make_model(const std::string& model, const ParameterMap& values) {
    if (model == "ovrv") return std::make_unique<OvrvModel>(values);
    if (model == "idm") return std::make_unique<IdmModel>(values);
    if (model == "ccc") return std::make_unique<CccModel>(values);
    throw std::invalid_argument("model " + detail::quoted(model) + ": expected one of ovrv, idm, ccc");
}

}  // namespace ddemap
