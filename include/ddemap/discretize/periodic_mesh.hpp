#pragma once
/// \file periodic_mesh.hpp
/// The mesh of periodic collocation on [0, 1] (periodic orbits, time scaled by the period):
/// L intervals 0 = t_0 < t_1 < ... < t_L = 1, on each the polynomial of degree d through d + 1
/// equispaced representation points t_i + (j / d) h_i (j = 0..d; Lagrange basis), the last
/// point of an interval being the first of the next, and t_L identified with t_0: L d distinct
/// points. Collocation at the d Gauss-Legendre nodes t_i + c_g h_i of every interval (c_g the
/// zeros of the shifted Legendre polynomial P_d(2c - 1), weights w_g summing to 1). Cf.
/// DDE-BIFTOOL's psol representation (Engelborghs, Luzyanina, in 't Hout, Roose, SIAM J. Sci.
/// Comput. 22 (2000) 1593-1609).

#include <vector>

namespace ddemap {

class PeriodicMesh {
public:
    /// A uniform mesh: `intervals` >= 1 intervals of degree `degree` >= 1 (std::invalid_argument otherwise).
    PeriodicMesh(int degree, int intervals);
    /// Given breakpoints 0 = t_0 < ... < t_L = 1 (std::invalid_argument otherwise).
    PeriodicMesh(int degree, std::vector<double> breakpoints);

    int degree() const { return m_d; }
    int intervals() const { return static_cast<int>(m_t.size()) - 1; }
    /// L d distinct representation points.
    int points() const { return intervals() * m_d; }
    const std::vector<double>& breakpoints() const { return m_t; }
    /// The representation point i = l d + j (0 <= i < L d): t_l + (j / d) h_l.
    double point(int i) const;
    /// Gauss-Legendre nodes c_g in (0, 1) and weights w_g (sum 1), g = 0..d-1.
    const std::vector<double>& gauss_nodes() const { return m_c; }
    const std::vector<double>& gauss_weights() const { return m_w; }
    /// The collocation point t_l + c_g h_l.
    double collocation_point(int interval, int g) const { return m_t[interval] + m_c[g] * (m_t[interval + 1] - m_t[interval]); }
    double width(int interval) const { return m_t[interval + 1] - m_t[interval]; }

    /// The interval containing s (s in [0, 1]; 1 belongs to the last interval).
    int interval_of(double s) const;
    /// At s in interval l: l_j(s) and dl_j/ds (j = 0..d, of size d + 1 each), the Lagrange
    /// basis of that interval's points; the value there is sum_j l_j x_{l d + j} (index mod L d).
    void basis(int interval, double s, double* values, double* derivatives) const;

private:
    int m_d;
    std::vector<double> m_t, m_c, m_w;
};

}  // namespace ddemap
