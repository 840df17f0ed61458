#pragma once
// Internal to the design layer: the sensitivity of a root of the plant to the law's parameters.

#include <Eigen/Dense>

#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap::detail {

/// d Re(lambda) / dx_j for a root lambda of the plant's D at the linearisation L:
///     d lambda / dx_j = -(dD/dx_j)(lambda) / D'(lambda),
/// the partials of D at the fixed lambda from `partials(f)`, which returns the gradient in x of a
/// function f of the linearisation (the caller's differences of the law).
template <class Partials>
Eigen::VectorXd plant_root_gradient(const Linearisation& L, cplx lambda, const Partials& partials) {
    cplx n, d, dn, dd;
    TransferFunction(L).evaluate(lambda, n, d, dn, dd);
    const Eigen::VectorXd re = partials([lambda](const Linearisation& l) { return TransferFunction(l).denominator(lambda).real(); });
    const Eigen::VectorXd im = partials([lambda](const Linearisation& l) { return TransferFunction(l).denominator(lambda).imag(); });
    Eigen::VectorXd g(re.size());
    for (Eigen::Index j = 0; j < g.size(); ++j) g[j] = (-cplx(re[j], im[j]) / dd).real();
    return g;
}

}  // namespace ddemap::detail
