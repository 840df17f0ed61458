#pragma once
/// \file ring_system.hpp
/// Car-following systems as nonlinear DDEs (problem/nonlinear_dde.hpp).
///
/// RingSystem: N cars on a ring road, car i following car i-1 (car 0 follows car N-1), each with
/// its own law (a Fleet, or N identical cars); state (s_0, v_0, ..., s_{N-1}, v_{N-1}):
///     s_i'(t) = v_{i-1}(t) - v_i(t),
///     v_i'(t) = F_i(s_i(t - d_0), v_i(t - d_1), v_{i-1}(t - d_2), v_{i-2}(t - d_3), ...; p_i)
/// with the input delays d_k(p_i) of car i's law (CarModel). Cars with the same model and
/// parameters form one type and share its parameters. Each input of each type is one delay slot
/// of the NonlinearDDE (slots may coincide or be 0; linearise() merges and folds them).
/// Equilibrium at a common speed v: s_i = s_i*(v), v_i = v. Its linearisation is the
/// 2N-dimensional ring of fleet.hpp (mixed_ring_dde) and ring.hpp (full_ring_dde).
///
/// FollowerSystem: one car behind a lead driving at a constant speed v_l (every car ahead at v_l);
/// state (s, v): s' = v_l - v, v' = F(s(t - d_0), v(t - d_1), v_l, ..., v_l). Its linearisation
/// at (s*(v_l), v_l) is the plant of string_stability.hpp (plant_dde).

#include <memory>
#include <string>
#include <vector>

#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/shift_invert.hpp"

namespace ddemap {

class RingSystem final : public NonlinearDDE {
public:
    /// A mixed ring (N = fleet.size() >= 2). Parameters: with one type its law parameters by name
    /// (k1, k2, ...); with several, NAME[j] for type j = 1, 2, ... (types numbered in order of
    /// first appearance, see type_of()). Invalid cars throw std::invalid_argument naming the car.
    /// The models are built (and validated) at the operating speed `speed`: the law does not
    /// depend on it, but a model's admissible parameters may (IDM: speed < v0, eta + th speed > 0).
    explicit RingSystem(const Fleet& fleet, double speed = 0.0);
    /// N identical cars of one model (its law parameters; the operating speed is not used).
    RingSystem(const CarModel& model, int cars);

    int cars() const { return static_cast<int>(m_type_of.size()); }
    int types() const { return static_cast<int>(m_types.size()); }
    /// The type (0-based) of car i.
    int type_of(int car) const { return m_type_of.at(car); }

    int dimension() const override { return 2 * cars(); }
    int delay_count() const override { return m_slots; }
    std::vector<double> delays(const std::vector<double>& p) const override;
    using NonlinearDDE::delays;

    /// (s_0*(v), v, ..., s_{N-1}*(v), v): f vanishes there. std::invalid_argument for a speed
    /// that is negative, not finite, or where some car has no finite positive gap.
    Eigen::VectorXd equilibrium(double speed) const;

    /// The partials of each car's law at the constant history `state` (dual numbers, the current
    /// parameters), car by car: O(N) work.
    std::vector<Linearisation> car_linearisations(const Eigen::VectorXd& state) const;
    /// The same linearisation as linearise(*this, state), assembled with sparse storage (mixed_ring_dde of
    /// car_linearisations): for long rings, where the dense one costs O(N^2).
    LinearDDE sparse_linearise(const Eigen::VectorXd& state) const;

    using NonlinearDDE::evaluate;
    void evaluate(const double* u, const double* p, double* out) const override;
    void evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const override;

private:
    /// f(u; p): the template both evaluate() overloads use.
    template <class T>
    void rhs(const T* u, const T* p, T* out) const;

    struct Init;
    explicit RingSystem(Init init);

    std::vector<std::unique_ptr<CarModel>> m_types;
    std::vector<int> m_type_of;
    std::vector<int> m_param_offset;  // first law parameter of type t in p
    std::vector<int> m_slot_offset;   // first delay slot of type t (slot k is stacked block k + 1)
    int m_slots = 0;
};

class FollowerSystem final : public NonlinearDDE {
public:
    /// The model's law parameters plus "lead_speed" (the lead's constant speed, >= 0).
    FollowerSystem(const CarModel& model, double lead_speed);

    int dimension() const override { return 2; }
    int delay_count() const override { return m_model->inputs(); }
    std::vector<double> delays(const std::vector<double>& p) const override { return m_model->input_delays(p.data()); }
    using NonlinearDDE::delays;
    /// (s*(v_l), v_l).
    Eigen::VectorXd equilibrium() const;

    using NonlinearDDE::evaluate;
    void evaluate(const double* u, const double* p, double* out) const override;
    void evaluate(const Dual<double>* u, const Dual<double>* p, Dual<double>* out) const override;

private:
    template <class T>
    void rhs(const T* u, const T* p, T* out) const;

    std::unique_ptr<CarModel> m_model;
};

}  // namespace ddemap
