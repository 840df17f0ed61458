#include "ddemap/discretize/chebyshev.hpp"

#include <cmath>
#include <stdexcept>

namespace ddemap {

Eigen::VectorXd chebyshev_points(int degree) {
    if (degree < 1) throw std::invalid_argument("Chebyshev degree must be >= 1");
    Eigen::VectorXd x(degree + 1);
    for (int j = 0; j <= degree; ++j) x(j) = std::cos(M_PI * j / degree);
    // exact symmetry (cos is not exactly antisymmetric in floating point)
    for (int j = 0; j <= degree / 2; ++j) {
        const double v = 0.5 * (x(j) - x(degree - j));
        x(j) = v;
        x(degree - j) = -v;
    }
    return x;
}

Eigen::MatrixXd chebyshev_differentiation(int degree) {
    const int m = degree;
    const Eigen::VectorXd x = chebyshev_points(m);
    Eigen::VectorXd c(m + 1);
    for (int j = 0; j <= m; ++j) c(j) = ((j == 0 || j == m) ? 2.0 : 1.0) * ((j % 2) ? -1.0 : 1.0);
    Eigen::MatrixXd d(m + 1, m + 1);
    for (int i = 0; i <= m; ++i) {
        for (int j = 0; j <= m; ++j) {
            if (i == j) {
                d(i, j) = 0.0;
            } else {
                d(i, j) = (c(i) / c(j)) / (x(i) - x(j));
            }
        }
    }
    // negative-sum trick for the diagonal (more accurate than the closed form)
    for (int i = 0; i <= m; ++i) d(i, i) = -d.row(i).sum();
    return d;
}

Eigen::VectorXd chebyshev_lagrange_row(int degree, double x) {
    const int m = degree;
    const Eigen::VectorXd xs = chebyshev_points(m);
    Eigen::VectorXd l = Eigen::VectorXd::Zero(m + 1);
    for (int j = 0; j <= m; ++j) {
        if (x == xs(j)) {
            l(j) = 1.0;
            return l;
        }
    }
    double denom = 0.0;
    for (int j = 0; j <= m; ++j) {
        const double w = ((j == 0 || j == m) ? 0.5 : 1.0) * ((j % 2) ? -1.0 : 1.0);
        l(j) = w / (x - xs(j));
        denom += l(j);
    }
    return l / denom;
}

}  // namespace ddemap
