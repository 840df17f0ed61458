#pragma once
/// \file dde_solver.hpp
/// An explicit integrator for systems with discrete delays: the classical fourth-order
/// Runge-Kutta method with the delayed values taken from a continuous extension of the computed
/// solution (cubic Hermite interpolation on the stored steps, accurate to O(h^4)), so the
/// method keeps order 4. Steps never exceed the smallest positive delay (delayed values then
/// always lie in the computed past) and land exactly on the given breakpoints (where the
/// solution or its inputs lose smoothness).

#include <functional>
#include <vector>

namespace ddemap {

class DdeSolver {
public:
    /// Past values y(t) for t <= t0 (the initial history), written into y.
    using History = std::function<void(double t, double* y)>;
    /// dy/dt at time t for the current (stage) state y; delayed values through solver.value().
    using Rhs = std::function<void(double t, const double* y, const DdeSolver& solver, double* dydt)>;

    DdeSolver(int dimension, double t0, History history, Rhs rhs);

    /// Integrates to t_end with steps of at most h_max, hitting every breakpoint in (t, t_end].
    /// `after_step` (optional) is called after every step and may return false to stop.
    void integrate(double t_end, double h_max, std::vector<double> breakpoints,
                   const std::function<bool(const DdeSolver&)>& after_step = nullptr);

    /// Component j at time t <= current time (the initial history for t <= t0).
    double value(int j, double t) const;
    double time() const { return m_t.back(); }
    double t0() const { return m_t.front(); }
    const double* state() const { return &m_y[m_y.size() - m_n]; }
    int dimension() const { return m_n; }
    std::size_t steps() const { return m_t.size() - 1; }
    /// Stored step times (t0 first).
    const std::vector<double>& times() const { return m_t; }

private:
    void step(double h);
    int m_n;
    History m_history;
    Rhs m_rhs;
    std::vector<double> m_t;   // step times
    std::vector<double> m_y;   // states, step-major
    std::vector<double> m_f;   // derivatives at the steps
    std::vector<double> m_hist_buffer;
    mutable std::size_t m_cursor = 0;
};

}  // namespace ddemap
