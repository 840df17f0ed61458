#pragma once
/// \file chebyshev.hpp
/// Chebyshev points of the second kind, their differentiation matrix and barycentric
/// Lagrange interpolation (Trefethen, Spectral Methods in MATLAB, ch. 6; Berrut & Trefethen 2004).

#include <vector>

#include <Eigen/Dense>

namespace ddemap {

/// x_j = cos(j pi / M), j = 0..M (x_0 = 1, x_M = -1). Requires M >= 1.
Eigen::VectorXd chebyshev_points(int degree);

/// Differentiation matrix D with (D u)_j = p'(x_j), p the interpolant of u at x_0..x_M.
Eigen::MatrixXd chebyshev_differentiation(int degree);

/// Values l_j(x), j = 0..M, of the Lagrange basis at the Chebyshev points, by the barycentric
/// formula with weights w_j = (-1)^j (halved at both ends).
Eigen::VectorXd chebyshev_lagrange_row(int degree, double x);

}  // namespace ddemap
