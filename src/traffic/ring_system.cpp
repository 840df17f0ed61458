#include "ddemap/traffic/ring_system.hpp"

#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

namespace ddemap {

namespace {

constexpr int max_inputs = 16;

std::unique_ptr<CarModel> clone(const CarModel& m) { return make_model(m.name(), m.parameters()); }

}  // namespace

struct RingSystem::Init {
    std::vector<std::unique_ptr<CarModel>> types;
    std::vector<int> type_of;
    std::vector<std::string> names;
    std::vector<double> values;
};

namespace {

void name_parameters(std::vector<std::unique_ptr<CarModel>>& types, std::vector<std::string>& names, std::vector<double>& values) {
    for (std::size_t t = 0; t < types.size(); ++t) {
        const auto n = types[t]->law_parameter_names();
        const auto& v = types[t]->law_parameter_values();
        if (types[t]->inputs() > max_inputs)
            throw std::invalid_argument("model " + types[t]->name() + " has " + std::to_string(types[t]->inputs()) + " inputs: expected at most " +
                                        std::to_string(max_inputs));
        for (std::size_t k = 0; k < n.size(); ++k) {
            names.push_back(types.size() == 1 ? n[k] : n[k] + "[" + std::to_string(t + 1) + "]");
            values.push_back(v[k]);
        }
    }
}

}  // namespace

RingSystem::RingSystem(const Fleet& fleet, double speed)
    : RingSystem([&] {
          if (fleet.size() < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(fleet.size()));
          Init init;
          std::map<std::pair<std::string, ParameterMap>, int> index;
          for (std::size_t i = 0; i < fleet.size(); ++i) {
              const FleetCar& car = fleet[i];
              if (car.parameters.count("speed"))
                  throw std::invalid_argument("car " + std::to_string(i + 1) + " (" + car.label + "): the speed is set by the ring, not per car");
              auto key = std::make_pair(car.model, car.parameters);
              auto it = index.find(key);
              if (it == index.end()) {
                  ParameterMap p = car.parameters;
                  p["speed"] = speed;  // the law does not use it
                  try {
                      init.types.push_back(make_model(car.model, p));
                  } catch (const std::invalid_argument& e) {
                      throw std::invalid_argument("car " + std::to_string(i + 1) + " (" + car.label + "): " + e.what());
                  }
                  it = index.emplace(key, static_cast<int>(init.types.size()) - 1).first;
              }
              init.type_of.push_back(it->second);
          }
          name_parameters(init.types, init.names, init.values);
          return init;
      }()) {}

RingSystem::RingSystem(const CarModel& model, int cars)
    : RingSystem([&] {
          if (cars < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars));
          Init init;
          init.types.push_back(clone(model));
          init.type_of.assign(cars, 0);
          name_parameters(init.types, init.names, init.values);
          return init;
      }()) {}

RingSystem::RingSystem(Init init)
    : NonlinearDDE(std::move(init.names), std::move(init.values)), m_types(std::move(init.types)), m_type_of(std::move(init.type_of)) {
    int p = 0;
    for (const auto& t : m_types) {
        m_param_offset.push_back(p);
        m_slot_offset.push_back(m_slots);
        p += static_cast<int>(t->law_parameter_names().size());
        m_slots += t->inputs();
    }
}

std::vector<double> RingSystem::delays(const std::vector<double>& p) const {
    std::vector<double> d;
    d.reserve(m_slots);
    for (std::size_t t = 0; t < m_types.size(); ++t) {
        const std::vector<double> dt = m_types[t]->input_delays(p.data() + m_param_offset[t]);
        d.insert(d.end(), dt.begin(), dt.end());
    }
    return d;
}

template <class T>
void RingSystem::rhs(const T* u, const T* p, T* out) const {
    const int n = cars(), dim = 2 * n;
    std::array<T, max_inputs> in;
    for (int i = 0; i < n; ++i) {
        const int t = m_type_of[i];
        const CarModel& model = *m_types[t];
        const int ahead = (i + n - 1) % n;
        out[2 * i] = u[2 * ahead + 1] - u[2 * i + 1];
        // input k of this car's type is read from stacked block 1 + slot
        const T* block0 = u + static_cast<std::ptrdiff_t>(dim) * (1 + m_slot_offset[t]);
        in[0] = block0[2 * i];
        in[1] = block0[dim + 2 * i + 1];
        for (int j = 0; j < model.leaders(); ++j) {
            const int car = ((i - 1 - j) % n + n) % n;
            in[2 + j] = block0[static_cast<std::ptrdiff_t>(dim) * (2 + j) + 2 * car + 1];
        }
        out[2 * i + 1] = model.evaluate(in.data(), p + m_param_offset[t]);
    }
}

void RingSystem::evaluate(const double* u, const double* p, double* out) const { rhs(u, p, out); }
void RingSystem::evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const { rhs(u, p, out); }

Eigen::VectorXd RingSystem::equilibrium(double speed) const {
    if (!(std::isfinite(speed) && speed >= 0.0))
        throw std::invalid_argument("speed = " + std::to_string(speed) + ": expected a finite speed >= 0 m/s");
    std::vector<double> gap(m_types.size());
    for (std::size_t t = 0; t < m_types.size(); ++t) gap[t] = m_types[t]->equilibrium_gap(speed);
    Eigen::VectorXd x(dimension());
    for (int i = 0; i < cars(); ++i) {
        const double s = gap[m_type_of[i]];
        if (!(std::isfinite(s) && s > 0.0))
            throw std::invalid_argument("car " + std::to_string(i + 1) + " (" + m_types[m_type_of[i]]->name() +
                                        ") has no positive equilibrium gap at speed " + std::to_string(speed) + " m/s");
        x[2 * i] = s;
        x[2 * i + 1] = speed;
    }
    return x;
}

std::vector<Linearisation> RingSystem::car_linearisations(const Eigen::VectorXd& state) const {
    const int n = cars();
    if (state.size() != dimension())
        throw std::invalid_argument("the state has " + std::to_string(state.size()) + " entries: expected 2N = " + std::to_string(dimension()));
    if (!state.allFinite()) throw std::invalid_argument("the state has a non-finite entry: expected finite values");
    const std::vector<double>& values = parameter_values();
    const std::vector<double> d = delays();
    std::vector<Dual<double>> p(values.begin(), values.end());
    std::vector<Linearisation> out(n);
    for (int i = 0; i < n; ++i) {
        const int t = m_type_of[i];
        const CarModel& model = *m_types[t];
        const int k = model.inputs();
        std::array<Dual<double>, max_inputs> in;
        in[0] = state[2 * i];
        in[1] = state[2 * i + 1];
        for (int j = 0; j < model.leaders(); ++j) in[2 + j] = state[2 * (((i - 1 - j) % n + n) % n) + 1];
        const double* dt = d.data() + m_slot_offset[t];
        Linearisation& l = out[i];
        l.further.resize(model.leaders() - 1);
        for (int q = 0; q < k; ++q) {
            in[q].deriv = 1.0;
            const double partial = model.evaluate(in.data(), p.data() + m_param_offset[t]).deriv;
            in[q].deriv = 0.0;
            ExpPoly& e = q == 0 ? l.gap : q == 1 ? l.own : q == 2 ? l.lead : l.further[q - 3];
            e.add(partial, dt[q]);
        }
    }
    return out;
}

LinearDDE RingSystem::sparse_linearise(const Eigen::VectorXd& state) const { return mixed_ring_dde(car_linearisations(state)); }

// ---------------------------------------------------------------- one follower

FollowerSystem::FollowerSystem(const CarModel& model, double lead_speed)
    : NonlinearDDE([&] {
          auto n = model.law_parameter_names();
          n.push_back("lead_speed");
          return n;
      }(),
                   [&] {
                       if (!(std::isfinite(lead_speed) && lead_speed >= 0.0))
                           throw std::invalid_argument("lead speed = " + std::to_string(lead_speed) + ": expected a finite speed >= 0 m/s");
                       auto v = model.law_parameter_values();
                       v.push_back(lead_speed);
                       return v;
                   }()),
      m_model(clone(model)) {
    if (m_model->inputs() > max_inputs) throw std::invalid_argument("model " + m_model->name() + ": too many inputs");
}

Eigen::VectorXd FollowerSystem::equilibrium() const {
    const double v = parameter_values().back();
    const double s = m_model->equilibrium_gap(v);
    if (!(std::isfinite(s) && s > 0.0))
        throw std::invalid_argument("model " + m_model->name() + " has no positive equilibrium gap at the lead speed " + std::to_string(v) + " m/s");
    return Eigen::Vector2d(s, v);
}

template <class T>
void FollowerSystem::rhs(const T* u, const T* p, T* out) const {
    const T& lead = p[parameter_values().size() - 1];
    out[0] = lead - u[1];
    std::array<T, max_inputs> in;
    in[0] = u[2 * 1 + 0];  // input 0 (the gap) from block 1
    in[1] = u[2 * 2 + 1];  // input 1 (the own speed) from block 2
    for (int j = 0; j < m_model->leaders(); ++j) in[2 + j] = lead;
    out[1] = m_model->evaluate(in.data(), p);
}

void FollowerSystem::evaluate(const double* u, const double* p, double* out) const { rhs(u, p, out); }
void FollowerSystem::evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const { rhs(u, p, out); }

}  // namespace ddemap
