#pragma once
/// \file collocation.hpp
/// The discretisation: Chebyshev collocation of the infinitesimal generator of a linear DDE
/// (Breda, Maset, Vermiglio, SIAM J. Sci. Comput. 27 (2005) 482-495). It assembles, it never
/// solves.
///
/// Nodes theta_j = tau_max (x_j - 1) / 2, x_j = cos(j pi / M), j = 0..M. The (M+1)n square
/// matrix has block row 0 equal to the DDE,
///     A0 u_0 + sum_k A_k sum_j l_j(-tau_k) u_j,
/// and block rows j >= 1 equal to (2 / tau_max) sum_l D_{jl} u_l (D the Chebyshev
/// differentiation matrix). Its eigenvalues converge spectrally to the rightmost
/// characteristic roots.

#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// Dense collocation matrix of degree M (M >= 1) for a DDE with tau_max > 0.
/// For an ODE (tau_max = 0) it returns A0 (the generator is the matrix itself).
MatrixXc collocation_matrix(const LinearDDE& dde, int degree);

}  // namespace ddemap
