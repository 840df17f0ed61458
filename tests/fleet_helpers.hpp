#pragma once
// Shared test fixtures for mixed rings: random cars from a fixed generator, and an OVRV
// linearisation from its four parameters.
#include <random>

#include "ddemap/study/penetration.hpp"

namespace ddemap::test {

/// A random car: OVRV or (ccc = true) connected cruise control; k1, k2, th, tau (then k3, tau2)
/// drawn in this order from uniform ranges.
inline FleetCar random_car(std::mt19937& rng, bool ccc) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    ParameterMap p{{"k1", 0.02 + 0.4 * u(rng)}, {"k2", 0.05 + 0.6 * u(rng)}, {"th", 0.6 + 1.8 * u(rng)}, {"tau", 0.1 + 0.9 * u(rng)}};
    if (ccc) {
        p["k3"] = 0.05 + 0.4 * u(rng);
        p["tau2"] = 0.05 + 0.5 * u(rng);
    }
    return {ccc ? "ccc" : "ovrv", ccc ? "ccc" : "ovrv", p};
}

/// The linearisation of a car at 20 m/s.
inline Linearisation linearised(const FleetCar& car) {
    ParameterMap p = car.parameters;
    p["speed"] = 20.0;
    return make_model(car.model, p)->linearise();
}

/// OVRV with the given gains, headway and delay, linearised.
inline Linearisation ovrv(double k1, double k2, double th, double tau) {
    return linearised({"ovrv", "ovrv", {{"k1", k1}, {"k2", k2}, {"th", th}, {"tau", tau}}});
}

}  // namespace ddemap::test
