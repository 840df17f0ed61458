#include "ddemap/traffic/ring_car.hpp"

#include <stdexcept>

#include "ddemap/traffic/nonlinear_ring.hpp"

namespace ddemap {

namespace {
/// The parameter values with make_nonlinear_ring's defaults and checks (a two-car ring is built
/// only to validate them and read them back).
std::vector<double> checked_values(const std::string& model, const ParameterMap& parameters) {
    return make_nonlinear_ring(model, 2, parameters).system->parameter_values();
}
}  // namespace

RingCar::RingCar(const std::string& model, const ParameterMap& parameters)
    : RingCar(model, nonlinear_ring_parameters(model), checked_values(model, parameters)) {}

RingCar::RingCar(const std::string& model, std::vector<std::string> names, std::vector<double> values)
    : NonlinearDDEOf(std::move(names), std::move(values)), m_model(model), m_ov(model == "ov") {
    m_tau = parameter_index("tau");
    m_length = parameter_index(m_ov ? "headway" : "gap");
}

Eigen::VectorXd RingCar::uniform_flow(const std::vector<double>& p) const {
    const std::vector<std::string>& names = parameter_names();
    if (p.size() != names.size()) throw std::invalid_argument("ring car: expected one value per parameter");
    ParameterMap map;
    for (std::size_t i = 0; i < names.size(); ++i) map[names[i]] = p[i];
    const NonlinearRing ring = make_nonlinear_ring(m_model, 2, map);
    Eigen::VectorXd x(2);
    x << ring.uniform_flow(0), ring.uniform_flow(1);  // (h_0, v_0) of the two-car ring
    return x;
}

}  // namespace ddemap
