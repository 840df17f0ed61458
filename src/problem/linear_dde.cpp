#include "ddemap/problem/linear_dde.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace ddemap {

namespace {
double spectral_norm(const MatrixXc& a) {
    if (a.size() == 0) return 0.0;
    Eigen::JacobiSVD<MatrixXc> svd(a);
    return svd.singularValues()(0);
}
bool all_finite(const MatrixXc& a) {
    for (Eigen::Index i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a.data()[i].real()) || !std::isfinite(a.data()[i].imag())) return false;
    }
    return true;
}
}  // namespace

LinearDDE::LinearDDE(MatrixXc a0, std::vector<DelayTerm> delayed) : m_a0(std::move(a0)) {
    const auto n = m_a0.rows();
    if (n < 1 || m_a0.cols() != n) {
        std::ostringstream os;
        os << "A0 is " << m_a0.rows() << "x" << m_a0.cols() << ": expected a square matrix of dimension >= 1";
        throw std::invalid_argument(os.str());
    }
    if (!all_finite(m_a0)) throw std::invalid_argument("A0 has a non-finite entry: expected finite coefficients");
    for (std::size_t k = 0; k < delayed.size(); ++k) {
        auto& t = delayed[k];
        if (t.matrix.rows() != n || t.matrix.cols() != n) {
            std::ostringstream os;
            os << "delayed matrix " << k + 1 << " is " << t.matrix.rows() << "x" << t.matrix.cols()
               << ": expected " << n << "x" << n;
            throw std::invalid_argument(os.str());
        }
        if (!all_finite(t.matrix)) {
            std::ostringstream os;
            os << "delayed matrix " << k + 1 << " has a non-finite entry: expected finite coefficients";
            throw std::invalid_argument(os.str());
        }
        if (!std::isfinite(t.delay) || t.delay < 0.0) {
            std::ostringstream os;
            os << "delay " << k + 1 << " = " << t.delay << ": expected a finite delay >= 0";
            throw std::invalid_argument(os.str());
        }
        if (t.delay == 0.0) {
            m_a0 += t.matrix;
            continue;
        }
        auto same = std::find_if(m_delayed.begin(), m_delayed.end(),
                                 [&](const DelayTerm& d) { return d.delay == t.delay; });
        if (same != m_delayed.end()) {
            same->matrix += t.matrix;
        } else {
            m_delayed.push_back(std::move(t));
        }
    }
    std::sort(m_delayed.begin(), m_delayed.end(),
              [](const DelayTerm& a, const DelayTerm& b) { return a.delay < b.delay; });
    m_norm0 = spectral_norm(m_a0);
    for (const auto& t : m_delayed) m_norms.push_back(spectral_norm(t.matrix));
}

double LinearDDE::max_delay() const { return m_delayed.empty() ? 0.0 : m_delayed.back().delay; }

bool LinearDDE::is_real() const {
    if (m_a0.imag().cwiseAbs().maxCoeff() != 0.0) return false;
    for (const auto& t : m_delayed)
        if (t.matrix.imag().cwiseAbs().maxCoeff() != 0.0) return false;
    return true;
}

MatrixXc LinearDDE::characteristic_matrix(cplx lambda) const {
    const auto n = m_a0.rows();
    MatrixXc d = lambda * MatrixXc::Identity(n, n) - m_a0;
    for (const auto& t : m_delayed) d -= std::exp(-lambda * t.delay) * t.matrix;
    return d;
}

MatrixXc LinearDDE::characteristic_derivative(cplx lambda) const {
    const auto n = m_a0.rows();
    MatrixXc d = MatrixXc::Identity(n, n);
    for (const auto& t : m_delayed) d += (t.delay * std::exp(-lambda * t.delay)) * t.matrix;
    return d;
}

MatrixXc LinearDDE::ode_limit() const {
    MatrixXc a = m_a0;
    for (const auto& t : m_delayed) a += t.matrix;
    return a;
}

double LinearDDE::root_bound(double sigma) const {
    double r = m_norm0;
    for (std::size_t k = 0; k < m_delayed.size(); ++k) r += m_norms[k] * std::exp(-sigma * m_delayed[k].delay);
    return r;
}

}  // namespace ddemap
