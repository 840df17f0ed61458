#include "ddemap/traffic/idm_ring.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {
using detail::require_value;
}  // namespace

IdmRing::IdmRing(int cars, double a, double b, double v0, double delta, double th, double eta, double tau, double gap)
    : NonlinearDDEOf({"a", "b", "v0", "delta", "th", "eta", "tau", "gap"}, {a, b, v0, delta, th, eta, tau, gap}), m_cars(cars) {
    if (cars < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars));
    require_value(std::isfinite(a) && a > 0.0, "a", a, "a finite value > 0 [m/s^2]");
    require_value(std::isfinite(b) && b > 0.0, "b", b, "a finite value > 0 [m/s^2]");
    require_value(std::isfinite(v0) && v0 > 0.0, "v0", v0, "a finite value > 0 [m/s]");
    require_value(std::isfinite(delta) && delta > 0.0, "delta", delta, "a finite value > 0");
    require_value(std::isfinite(th) && th >= 0.0, "th", th, "a finite value >= 0 [s]");
    require_value(std::isfinite(eta) && eta >= 0.0, "eta", eta, "a finite value >= 0 [m]");
    require_value(std::isfinite(tau) && tau >= 0.0, "tau", tau, "a finite value >= 0 [s]");
    require_value(std::isfinite(gap) && gap > eta, "gap", gap, "a finite mean gap > eta (a uniform flow exists only then) [m]");
}

double IdmRing::equilibrium_speed(double gap) const {
    const double v0 = parameter("v0"), delta = parameter("delta"), th = parameter("th"), eta = parameter("eta");
    if (!(gap > eta)) throw std::invalid_argument("gap = " + detail::format_number(gap) + ": expected a mean gap > eta = " + detail::format_number(eta) + " m");
    // s*(v) - gap changes sign on [0, v0): negative at 0 (eta < gap), +inf as v -> v0
    auto excess = [&](double v) { return (eta + th * v) - gap * std::sqrt(1.0 - std::pow(v / v0, delta)); };
    double lo = 0.0, hi = v0;
    for (int k = 0; k < 200 && hi - lo > 0.0; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi) break;
        (excess(mid) < 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi) < v0 ? 0.5 * (lo + hi) : lo;
}

Eigen::VectorXd IdmRing::uniform_flow() const {
    const int n = m_cars;
    Eigen::VectorXd x(2 * n - 1);
    const double gap = parameter("gap");
    x.head(n - 1).setConstant(gap);
    x.tail(n).setConstant(equilibrium_speed(gap));
    return x;
}

}  // namespace ddemap
