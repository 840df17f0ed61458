#pragma once
/// \file fleet.hpp
/// Mixed rings: N cars on a ring road, car i following car i-1 (car 0 follows car N-1), each
/// with its own law, parameters and delays. At a common equilibrium speed v* the cars keep
/// different gaps s_i*(v*); the ring length fixes v* through sum_i s_i*(v*) = L.
/// The linearisation is the 2N-dimensional sparse DDE (state s_0, v_0, s_1, v_1, ...):
///     s_i' = v_{i-1} - v_i,
///     v_i' = gap_i * s_i + own_i * v_i + lead_i * v_{i-1} + sum_j further_ij * v_{i-2-j},
/// with one delayed matrix per distinct delay. Its root lambda = 0 (the ring length is
/// conserved: sum_i s_i' = 0) is the trivial root and is left out of every verdict.
///
/// For laws of the car ahead only, eliminating s_i gives v_i = Gamma_i(lambda) v_{i-1} with
///     Gamma_i = (gap_i + lambda lead_i) / (lambda^2 - lambda own_i + gap_i),
/// so every non-trivial root satisfies prod_i Gamma_i(lambda) = 1, whatever the order of the cars.

#include <limits>
#include <string>
#include <vector>

#include "ddemap/traffic/model.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// One car of a fleet: its law and parameters; the equilibrium speed is set by the ring.
struct FleetCar {
    std::string label;       ///< e.g. "A_min" or "line 4"
    std::string model;       ///< a built-in model name (ovrv, idm, ccc)
    ParameterMap parameters; ///< without "speed"
};
using Fleet = std::vector<FleetCar>;

/// "A_min,C_max*3,E_min": names from the built-in calibration table, each optionally repeated
/// (*k), the whole pattern repeated to `cars` cars (cars = 0: the pattern once; otherwise the
/// last repetition is cut short when cars is not a multiple of the pattern length).
Fleet fleet_from_pattern(const std::string& pattern, int cars);

/// The cars of a car table (traffic/vehicles.hpp read_car_table: name, vehicle, model, count,
/// parameter columns), as a fleet: each car's name, law and parameters.
Fleet read_fleet_csv(const std::string& text, const std::string& source);

/// One car from text: a calibrated vehicle name ("E_min") or "MODEL:NAME=VALUE,..."
/// (e.g. "ccc:k1=0.1,k2=0.3,k3=0.2,th=1.2,tau=0.3,tau2=0.2"); parameters validated.
FleetCar parse_fleet_car(const std::string& spec);

/// The built-in models of a fleet, each linearised at speed v.
std::vector<Linearisation> linearise_fleet(const Fleet& fleet, double speed);

struct RingEquilibrium {
    double speed = 0.0;          ///< common speed v* [m/s]
    double length = 0.0;         ///< ring length L = sum of the gaps [m] (vehicle lengths excluded)
    std::vector<double> gaps;    ///< s_i*(v*) [m]
};

/// The equilibrium at a common speed (every car's s_i*(v) must be finite and > 0).
RingEquilibrium ring_equilibrium_at_speed(const Fleet& fleet, double speed);
/// The equilibrium for a ring length L: the speed with sum_i s_i*(v) = L, by bisection
/// (s_i* increases with v). Errors when L is below the standstill gaps or beyond every speed.
RingEquilibrium ring_equilibrium_at_length(const Fleet& fleet, double length);

/// The 2N-dimensional linearised ring (see the file comment) assembled sparse from the cars'
/// linearisations; N >= 2. With the cars' partials at the equilibrium it is the linearisation of
/// the nonlinear ring (traffic/ring_system.hpp: RingSystem::sparse_linearise, equal to
/// linearise(RingSystem, equilibrium) entrywise); analyse_mixed_ring takes them from there.
LinearDDE mixed_ring_dde(const std::vector<Linearisation>& cars);

/// |prod_i Gamma_i(lambda) - 1| for laws of the car ahead only (sums of logarithms, so no
/// overflow for long rings): 0 at every non-trivial root of the ring.
double ring_product_residual(const std::vector<Linearisation>& cars, cplx lambda);

/// A ring of N cars with k of type X and N - k of type Y. draw = 0: the X cars spread as evenly
/// as possible (car i is X when floor((i+1) k / N) > floor(i k / N)); draw >= 1: a random
/// arrangement from std::mt19937(seed + draw).
Fleet mixed_fleet(const FleetCar& x, const FleetCar& y, int cars, int x_cars, int draw = 0, unsigned seed = 1);

}  // namespace ddemap
