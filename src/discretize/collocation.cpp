#include "ddemap/discretize/collocation.hpp"

#include <stdexcept>

#include "ddemap/discretize/chebyshev.hpp"

namespace ddemap {

MatrixXc collocation_matrix(const LinearDDE& dde, int degree) {
    if (dde.is_ode()) return dde.a0();
    if (degree < 1) throw std::invalid_argument("collocation degree must be >= 1");
    const int n = dde.dimension();
    const int m = degree;
    const double tau = dde.max_delay();
    MatrixXc a = MatrixXc::Zero((m + 1) * n, (m + 1) * n);
    // block row 0: the DDE
    a.block(0, 0, n, n) = dde.a0();
    for (const auto& t : dde.delayed()) {
        const double x = 1.0 - 2.0 * t.delay / tau;  // theta = -tau_k mapped to [-1, 1]
        const Eigen::VectorXd l = chebyshev_lagrange_row(m, x);
        for (int j = 0; j <= m; ++j) {
            if (l(j) != 0.0) a.block(0, j * n, n, n) += l(j) * t.matrix;
        }
    }
    // block rows j >= 1: d/dtheta
    const Eigen::MatrixXd d = chebyshev_differentiation(m) * (2.0 / tau);
    for (int j = 1; j <= m; ++j)
        for (int l = 0; l <= m; ++l)
            for (int i = 0; i < n; ++i) a(j * n + i, l * n + i) = d(j, l);
    return a;
}

}  // namespace ddemap
