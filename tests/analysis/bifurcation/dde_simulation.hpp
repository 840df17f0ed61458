#pragma once
// Simulations of nonlinear DDEs for the bifurcation tests: the project's integrator (RK4 with
// Hermite history) on a NonlinearDDE, and what the tests read off a run (upward crossings of a
// level, the range of a component). Independent of the collocation the tests check.
#include <algorithm>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/integrate.hpp"

namespace ddemap::test {

/// Integrates the system from the history `history` on [-tau_max, 0] to t_end with step h.
inline DdeSolver simulate(const NonlinearDDE& sys, const std::function<void(double, double*)>& history, double t_end, double h) {
    const int n = sys.dimension(), m = sys.delay_count();
    const std::vector<double> tau = sys.delays();
    DdeSolver s(n, 0.0, history, [&sys, n, m, tau](double t, const double* y, const DdeSolver& sol, double* dy) {
        Eigen::VectorXd u(static_cast<Eigen::Index>(n) * (m + 1));
        for (int i = 0; i < n; ++i) u(i) = y[i];
        for (int k = 0; k < m; ++k)
            for (int i = 0; i < n; ++i) u((k + 1) * n + i) = sol.value(i, t - tau[static_cast<std::size_t>(k)]);
        const Eigen::VectorXd f = sys.f(u);
        for (int i = 0; i < n; ++i) dy[i] = f(i);
    });
    s.integrate(t_end, h, {});
    return s;
}

/// Upward crossings of component j through `level` in [t0, t1], located by bisection on the
/// integrator's continuous extension.
inline std::vector<double> crossings(const DdeSolver& s, int j, double level, double t0, double t1, double dt) {
    std::vector<double> out;
    for (double t = t0; t + dt <= t1; t += dt) {
        double a = t, b = t + dt;
        if (!(s.value(j, a) < level && s.value(j, b) >= level)) continue;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (a + b);
            (s.value(j, mid) < level ? a : b) = mid;
        }
        out.push_back(0.5 * (a + b));
    }
    return out;
}

/// max - min of component j on [t0, t1] sampled at dt (sampling error O(dt^2 |y''|)).
inline double range(const DdeSolver& s, int j, double t0, double t1, double dt) {
    double lo = 1e300, hi = -1e300;
    for (double t = t0; t <= t1; t += dt) {
        lo = std::min(lo, s.value(j, t));
        hi = std::max(hi, s.value(j, t));
    }
    return hi - lo;
}

}  // namespace ddemap::test
