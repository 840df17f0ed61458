#pragma once
// Mesh adaptation shared by the periodic orbits (periodic_orbit.cpp) and the travelling waves
// (travelling_wave.cpp): both represent an orbit by its values on a PeriodicMesh.
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "ddemap/discretize/periodic_mesh.hpp"

namespace ddemap::orbit_mesh {

/// The mesh that equidistributes |x^(d+1)|^(1/(d+1)) of the orbit whose values at the L d
/// representation points of `mesh` are u(i n .. i n + n - 1) (n variables; entries of u after
/// the first L d n are ignored), as in COLSYS and DDE-BIFTOOL: on interval i the d-th derivative
/// D_i of the polynomial is constant (the d-th difference of its d + 1 equispaced values over
/// (h_i / d)^d); |x^(d+1)| is estimated from the jumps of D_i to both neighbours. The density is
/// that estimate to the power 1/(d+1) plus `floor` times its mean (so that no interval grows
/// without bound where x is nearly polynomial). Returns the breakpoints 0 = t_0 < ... < t_L = 1
/// (those of `mesh` when the density vanishes or is not finite).
inline std::vector<double> equidistributed_breakpoints(const PeriodicMesh& mesh, int n, const Eigen::VectorXd& u, double floor = 0.1) {
    const int L = mesh.intervals(), d = mesh.degree(), P = mesh.points();
    std::vector<double> binom(static_cast<std::size_t>(d) + 1, 1.0);
    for (int j = 1; j <= d; ++j) binom[static_cast<std::size_t>(j)] = binom[static_cast<std::size_t>(j - 1)] * (d - j + 1) / j;
    std::vector<Eigen::VectorXd> D(static_cast<std::size_t>(L));
    for (int i = 0; i < L; ++i) {
        Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
        for (int j = 0; j <= d; ++j) {
            const int pt = (i * d + j) % P;
            v += (((d - j) % 2) ? -1.0 : 1.0) * binom[static_cast<std::size_t>(j)] * u.segment(static_cast<Eigen::Index>(pt) * n, n);
        }
        D[static_cast<std::size_t>(i)] = v / std::pow(mesh.width(i) / d, d);
    }
    std::vector<double> m(static_cast<std::size_t>(L));
    double mean = 0.0;
    for (int i = 0; i < L; ++i) {
        const int ip = (i + 1) % L, im = (i + L - 1) % L;
        const auto ui = static_cast<std::size_t>(i);
        const double wl = (D[ui] - D[static_cast<std::size_t>(im)]).lpNorm<Eigen::Infinity>() / (0.5 * (mesh.width(i) + mesh.width(im)));
        const double wr = (D[static_cast<std::size_t>(ip)] - D[ui]).lpNorm<Eigen::Infinity>() / (0.5 * (mesh.width(i) + mesh.width(ip)));
        m[ui] = std::pow(0.5 * (wl + wr), 1.0 / (d + 1));
        mean += m[ui] * mesh.width(i);
    }
    if (!(mean > 0.0) || !std::isfinite(mean)) return mesh.breakpoints();
    std::vector<double> F(static_cast<std::size_t>(L) + 1, 0.0);
    for (int i = 0; i < L; ++i) {
        m[static_cast<std::size_t>(i)] += floor * mean;
        F[static_cast<std::size_t>(i) + 1] = F[static_cast<std::size_t>(i)] + m[static_cast<std::size_t>(i)] * mesh.width(i);
    }
    std::vector<double> t(static_cast<std::size_t>(L) + 1);
    t.front() = 0.0;
    t.back() = 1.0;
    int i = 0;
    for (int k = 1; k < L; ++k) {
        const double target = F.back() * k / L;
        while (i + 1 < L && F[static_cast<std::size_t>(i) + 1] <= target) ++i;
        t[static_cast<std::size_t>(k)] = mesh.breakpoints()[static_cast<std::size_t>(i)] + (target - F[static_cast<std::size_t>(i)]) / m[static_cast<std::size_t>(i)];
    }
    for (int k = 1; k <= L; ++k)
        if (!(t[static_cast<std::size_t>(k)] > t[static_cast<std::size_t>(k) - 1])) return mesh.breakpoints();
    return t;
}

}  // namespace ddemap::orbit_mesh
