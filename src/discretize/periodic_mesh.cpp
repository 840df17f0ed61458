#include "ddemap/discretize/periodic_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

namespace ddemap {

namespace {

/// Gauss-Legendre nodes and weights on [0, 1] by Golub-Welsch (the Jacobi matrix of the
/// Legendre polynomials, beta_k = k / sqrt(4 k^2 - 1)).
void gauss_legendre(int d, std::vector<double>& c, std::vector<double>& w) {
    Eigen::MatrixXd j = Eigen::MatrixXd::Zero(d, d);
    for (int k = 1; k < d; ++k) j(k, k - 1) = j(k - 1, k) = k / std::sqrt(4.0 * k * k - 1.0);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(j);
    c.resize(static_cast<std::size_t>(d));
    w.resize(static_cast<std::size_t>(d));
    for (int g = 0; g < d; ++g) {
        c[static_cast<std::size_t>(g)] = 0.5 * (es.eigenvalues()(g) + 1.0);
        const double v = es.eigenvectors()(0, g);
        w[static_cast<std::size_t>(g)] = v * v;  // 2 v^2 on [-1, 1], halved on [0, 1]
    }
}

}  // namespace

PeriodicMesh::PeriodicMesh(int degree, int intervals) : m_d(degree) {
    if (intervals < 1) throw std::invalid_argument("periodic mesh: expected at least one interval, got " + std::to_string(intervals));
    std::vector<double> t(static_cast<std::size_t>(intervals) + 1);
    for (int i = 0; i <= intervals; ++i) t[static_cast<std::size_t>(i)] = static_cast<double>(i) / intervals;
    *this = PeriodicMesh(degree, t);
}

PeriodicMesh::PeriodicMesh(int degree, std::vector<double> breakpoints) : m_d(degree), m_t(std::move(breakpoints)) {
    if (degree < 1 || degree > 20) throw std::invalid_argument("periodic mesh: expected a degree between 1 and 20, got " + std::to_string(degree));
    if (m_t.size() < 2 || m_t.front() != 0.0 || m_t.back() != 1.0)
        throw std::invalid_argument("periodic mesh: expected breakpoints from 0 to 1");
    for (std::size_t i = 1; i < m_t.size(); ++i)
        if (!(m_t[i] > m_t[i - 1])) throw std::invalid_argument("periodic mesh: expected increasing breakpoints");
    gauss_legendre(degree, m_c, m_w);
}

double PeriodicMesh::point(int i) const {
    const int l = i / m_d, j = i % m_d;
    const auto ul = static_cast<std::size_t>(l);
    return m_t[ul] + (static_cast<double>(j) / m_d) * (m_t[ul + 1] - m_t[ul]);
}

int PeriodicMesh::interval_of(double s) const {
    const auto it = std::upper_bound(m_t.begin(), m_t.end(), s);
    const int l = static_cast<int>(it - m_t.begin()) - 1;
    return std::clamp(l, 0, intervals() - 1);
}

void PeriodicMesh::basis(int interval, double s, double* values, double* derivatives) const {
    const double h = width(interval);
    const double x = (s - m_t[static_cast<std::size_t>(interval)]) / h * m_d;  // in [0, d]: nodes at 0..d
    for (int j = 0; j <= m_d; ++j) {
        double num = 1.0, den = 1.0, dsum = 0.0;
        for (int m = 0; m <= m_d; ++m) {
            if (m == j) continue;
            den *= static_cast<double>(j - m);
            num *= x - m;
        }
        // derivative: sum over m of prod_{k != j, m} (x - k)
        for (int m = 0; m <= m_d; ++m) {
            if (m == j) continue;
            double p = 1.0;
            for (int k = 0; k <= m_d; ++k)
                if (k != j && k != m) p *= x - k;
            dsum += p;
        }
        values[j] = num / den;
        derivatives[j] = dsum / den * (m_d / h);
    }
}

}  // namespace ddemap
