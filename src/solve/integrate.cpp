#include "ddemap/solve/integrate.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ddemap {

DdeSolver::DdeSolver(int dimension, double t0, History history, Rhs rhs)
    : m_n(dimension), m_history(std::move(history)), m_rhs(std::move(rhs)) {
    if (dimension < 1) throw std::invalid_argument("DDE dimension must be >= 1");
    m_hist_buffer.resize(m_n);
    m_t.push_back(t0);
    m_y.resize(m_n);
    m_history(t0, m_y.data());
    m_f.resize(m_n);
    m_rhs(t0, m_y.data(), *this, m_f.data());
}

double DdeSolver::value(int j, double t) const {
    if (t <= m_t.front()) {
        double* buf = const_cast<double*>(m_hist_buffer.data());
        m_history(t, buf);
        return buf[j];
    }
    if (t >= m_t.back()) return m_y[(m_t.size() - 1) * m_n + j];
    // step k with t_k <= t < t_{k+1}; the cursor makes monotone look-ups O(1)
    std::size_t k = std::min(m_cursor, m_t.size() - 2);
    if (!(m_t[k] <= t && t < m_t[k + 1])) {
        k = static_cast<std::size_t>(std::upper_bound(m_t.begin(), m_t.end(), t) - m_t.begin()) - 1;
    }
    m_cursor = k;
    const double h = m_t[k + 1] - m_t[k];
    const double s = (t - m_t[k]) / h;
    const double y0 = m_y[k * m_n + j], y1 = m_y[(k + 1) * m_n + j];
    const double f0 = m_f[k * m_n + j], f1 = m_f[(k + 1) * m_n + j];
    // cubic Hermite basis
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * h * f0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * h * f1;
}

void DdeSolver::step(double h) {
    const double t = m_t.back();
    const std::size_t base = (m_t.size() - 1) * m_n;
    std::vector<double> y(m_y.begin() + base, m_y.begin() + base + m_n);
    std::vector<double> k1(m_f.begin() + base, m_f.begin() + base + m_n), k2(m_n), k3(m_n), k4(m_n), tmp(m_n);
    for (int i = 0; i < m_n; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
    m_rhs(t + 0.5 * h, tmp.data(), *this, k2.data());
    for (int i = 0; i < m_n; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
    m_rhs(t + 0.5 * h, tmp.data(), *this, k3.data());
    for (int i = 0; i < m_n; ++i) tmp[i] = y[i] + h * k3[i];
    m_rhs(t + h, tmp.data(), *this, k4.data());
    for (int i = 0; i < m_n; ++i) tmp[i] = y[i] + h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    m_t.push_back(t + h);
    m_y.insert(m_y.end(), tmp.begin(), tmp.end());
    m_f.resize(m_f.size() + m_n);
    m_rhs(t + h, tmp.data(), *this, &m_f[m_f.size() - m_n]);
}

void DdeSolver::integrate(double t_end, double h_max, std::vector<double> breakpoints,
                          const std::function<bool(const DdeSolver&)>& after_step) {
    if (!(h_max > 0.0)) throw std::invalid_argument("step must be > 0");
    const double t = time();
    std::vector<double> marks;
    for (double b : breakpoints)
        if (b > t + 1e-12 && b < t_end - 1e-12) marks.push_back(b);
    marks.push_back(t_end);
    std::sort(marks.begin(), marks.end());
    marks.erase(std::unique(marks.begin(), marks.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }),
                marks.end());
    double from = t;
    for (double to : marks) {
        const double span = to - from;
        if (span <= 0.0) continue;
        const int n = std::max(1, static_cast<int>(std::ceil(span / h_max - 1e-9)));
        const double h = span / n;
        for (int i = 0; i < n; ++i) {
            step(i + 1 == n ? to - time() : h);
            if (after_step && !after_step(*this)) return;
        }
        from = to;
    }
}

}  // namespace ddemap
