#include "ddemap/traffic/ov_ring.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ddemap {

OvRing::OvRing(int cars, double alpha, double tau, double v0, double h_st, double headway)
    : NonlinearDDEOf({"alpha", "tau", "v0", "h_st", "headway"}, {alpha, tau, v0, h_st, headway}), m_cars(cars) {
    if (cars < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars));
    if (!(alpha > 0.0)) throw std::invalid_argument("alpha: expected a value > 0");
    if (!(tau >= 0.0)) throw std::invalid_argument("tau: expected a value >= 0");
    if (!(v0 > 0.0)) throw std::invalid_argument("v0: expected a value > 0");
    if (!(h_st > 0.0)) throw std::invalid_argument("h_st: expected a value > 0");
    if (!(headway > 0.0)) throw std::invalid_argument("headway: expected a value > 0");
}

double OvRing::optimal_velocity(double h) const { return velocity(h, parameter("v0"), parameter("h_st")); }

double OvRing::optimal_velocity_slope(double h) const {
    const Dual<double> d = velocity(variable(h), Dual<double>(parameter("v0")), Dual<double>(parameter("h_st")));
    return d.deriv;
}

Eigen::VectorXd OvRing::uniform_flow() const {
    const int n = m_cars;
    Eigen::VectorXd x(2 * n - 1);
    const double h = parameter("headway");
    x.head(n - 1).setConstant(h);
    x.tail(n).setConstant(optimal_velocity(h));
    return x;
}

}  // namespace ddemap
