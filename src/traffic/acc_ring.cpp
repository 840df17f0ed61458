#include "ddemap/traffic/acc_ring.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {
using detail::require_value;
}  // namespace

AccRing::AccRing(int cars, double k1, double k2, double th, double tau, double eta, double a_max, double a_min, double gap)
    : NonlinearDDEOf({"k1", "k2", "th", "tau", "eta", "a_max", "a_min", "gap"}, {k1, k2, th, tau, eta, a_max, a_min, gap}), m_cars(cars) {
    if (cars < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars));
    require_value(std::isfinite(k1) && k1 > 0.0, "k1", k1, "a finite value > 0 [1/s^2]");
    require_value(std::isfinite(k2) && k2 > 0.0, "k2", k2, "a finite value > 0 [1/s]");
    require_value(std::isfinite(th) && th > 0.0, "th", th, "a finite value > 0 [s]");
    require_value(std::isfinite(tau) && tau >= 0.0, "tau", tau, "a finite value >= 0 [s]");
    require_value(std::isfinite(eta) && eta >= 0.0, "eta", eta, "a finite value >= 0 [m]");
    require_value(std::isfinite(a_max) && a_max > 0.0, "a_max", a_max, "a finite acceleration limit > 0 [m/s^2]");
    require_value(std::isfinite(a_min) && a_min < 0.0, "a_min", a_min, "a finite braking limit < 0 [m/s^2]");
    require_value(std::isfinite(gap) && gap > eta, "gap", gap, "a finite mean gap > eta (a uniform flow at a speed > 0 exists only then) [m]");
}

Eigen::VectorXd AccRing::uniform_flow() const {
    const int n = m_cars;
    Eigen::VectorXd x(2 * n - 1);
    const double gap = parameter("gap");
    x.head(n - 1).setConstant(gap);
    x.tail(n).setConstant((gap - parameter("eta")) / parameter("th"));
    return x;
}

}  // namespace ddemap
