#include "ddemap/problem/linear_dde.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace ddemap {

namespace {

double spectral_norm(const MatrixXc& a) {
    if (a.size() == 0) return 0.0;
    Eigen::JacobiSVD<MatrixXc> svd(a);
    return svd.singularValues()(0);
}

/// mu_2(A) = lambda_max((A + A^H) / 2)
double log_norm(const MatrixXc& a) {
    const MatrixXc h = 0.5 * (a + a.adjoint());
    Eigen::SelfAdjointEigenSolver<MatrixXc> es(h, Eigen::EigenvaluesOnly);
    return es.eigenvalues().size() ? es.eigenvalues().maxCoeff() : 0.0;
}

bool all_finite(const MatrixXc& a) {
    for (Eigen::Index i = 0; i < a.size(); ++i) {
        if (!std::isfinite(a.data()[i].real()) || !std::isfinite(a.data()[i].imag())) return false;
    }
    return true;
}

bool all_finite(const SparseMatrixXd& m) {
    for (int k = 0; k < m.outerSize(); ++k)
        for (SparseMatrixXd::InnerIterator it(m, k); it; ++it)
            if (!std::isfinite(it.value())) return false;
    return true;
}

/// mu_2(A) = lambda_max((A + A^T)/2) <= max_i (a_ii + sum_{j != i} |a_ij + a_ji| / 2) (Gershgorin)
double log_norm_bound(const SparseMatrixXd& a) {
    const SparseMatrixXd sym = 0.5 * (a + SparseMatrixXd(a.transpose()));
    Eigen::VectorXd bound = Eigen::VectorXd::Zero(a.rows());
    for (int k = 0; k < sym.outerSize(); ++k)
        for (SparseMatrixXd::InnerIterator it(sym, k); it; ++it)
            bound(it.row()) += it.row() == it.col() ? it.value() : std::abs(it.value());
    return bound.size() ? bound.maxCoeff() : 0.0;
}

std::string delay_message(std::size_t k, double delay) {
    std::ostringstream os;
    os << "delay " << k + 1 << " = " << delay << ": expected a finite delay >= 0";
    return os.str();
}

std::string size_message(std::size_t k, Eigen::Index rows, Eigen::Index cols, Eigen::Index n) {
    std::ostringstream os;
    os << "delayed matrix " << k + 1 << " is " << rows << "x" << cols << ": expected " << n << "x" << n;
    return os.str();
}

std::string a0_message(Eigen::Index rows, Eigen::Index cols) {
    std::ostringstream os;
    os << "A0 is " << rows << "x" << cols << ": expected a square matrix of dimension >= 1";
    return os.str();
}

}  // namespace

// ------------------------------------------------------------------ root bounds

double RootBounds::delayed_norm(double a) const {
    if (terms.empty()) return 0.0;
    double termwise = 0.0;
    for (const auto& t : terms) termwise += t.norm * std::exp(-a * t.delay);
    if (entries.empty()) return termwise;
    std::vector<double> rows(static_cast<std::size_t>(n), 0.0), cols(static_cast<std::size_t>(n), 0.0);
    for (const auto& e : entries) {
        const double v = e.value * std::exp(-a * e.delay);
        rows[static_cast<std::size_t>(e.row)] += v;
        cols[static_cast<std::size_t>(e.col)] += v;
    }
    const double entrywise = std::sqrt(*std::max_element(rows.begin(), rows.end()) * *std::max_element(cols.begin(), cols.end()));
    return std::min(entrywise, termwise);
}

double RootBounds::right_bound() const {
    auto f = [&](double x) { return mu - x + delayed_norm(x); };
    double lo = mu, hi = mu + 1.0 + delayed_norm(mu);
    while (f(lo) < 0.0) lo -= std::max(1.0, std::abs(lo));
    while (f(hi) > 0.0) hi += std::max(1.0, std::abs(hi));
    for (int i = 0; i < 200 && hi - lo > 1e-15 * std::max(1.0, std::abs(hi)); ++i) {
        const double mid = 0.5 * (lo + hi);
        (f(mid) > 0.0 ? lo : hi) = mid;
    }
    return hi;
}

bool RootBounds::excludes(double x, double y) const {
    const double dx = std::max(0.0, x - mu), dy = std::max(0.0, y - std::min(n0, skew));
    return std::hypot(dx, dy) > delayed_norm(x) * (1.0 + 1e-12);
}

double relative_residual(const LinearDDE& dde, cplx lambda, const VectorXc& v) {
    const double norm = v.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return std::numeric_limits<double>::infinity();
    const double scale = dde.bounds().scale(lambda);
    const double r = dde.apply_characteristic(lambda, v).norm() / norm;
    return scale > 0.0 ? r / scale : r;
}

double relative_residual(const LinearDDE& dde, cplx lambda) {
    const MatrixXc d = dde.characteristic_matrix(lambda);
    Eigen::JacobiSVD<MatrixXc> svd(d);
    const double smin = svd.singularValues()(svd.singularValues().size() - 1);
    const double scale = dde.bounds().scale(lambda);
    return scale > 0.0 ? smin / scale : smin;
}

// ------------------------------------------------------------------ LinearDDE

LinearDDE::LinearDDE(MatrixXc a0, std::vector<DelayTerm> delayed) : m_a0(std::move(a0)) {
    const auto n = m_a0.rows();
    if (n < 1 || m_a0.cols() != n) throw std::invalid_argument(a0_message(m_a0.rows(), m_a0.cols()));
    if (!all_finite(m_a0)) throw std::invalid_argument("A0 has a non-finite entry: expected finite coefficients");
    for (std::size_t k = 0; k < delayed.size(); ++k) {
        auto& t = delayed[k];
        if (t.matrix.rows() != n || t.matrix.cols() != n) throw std::invalid_argument(size_message(k, t.matrix.rows(), t.matrix.cols(), n));
        if (!all_finite(t.matrix)) {
            std::ostringstream os;
            os << "delayed matrix " << k + 1 << " has a non-finite entry: expected finite coefficients";
            throw std::invalid_argument(os.str());
        }
        if (!std::isfinite(t.delay) || t.delay < 0.0) throw std::invalid_argument(delay_message(k, t.delay));
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
    m_n = static_cast<int>(n);
    m_real = m_a0.imag().cwiseAbs().maxCoeff() == 0.0;
    for (const auto& t : m_delayed) {
        m_delays.push_back(t.delay);
        if (t.matrix.imag().cwiseAbs().maxCoeff() != 0.0) m_real = false;
    }
    // bounds: exact 2-norms and log-norm of the (small) dense matrices
    m_bounds.n = m_n;
    m_bounds.n0 = spectral_norm(m_a0);
    m_bounds.mu = log_norm(m_a0);
    {
        const MatrixXc k = cplx(0.0, -0.5) * (m_a0 - m_a0.adjoint());  // Hermitian
        Eigen::SelfAdjointEigenSolver<MatrixXc> es(k, Eigen::EigenvaluesOnly);
        m_bounds.skew = es.eigenvalues().size() ? es.eigenvalues().cwiseAbs().maxCoeff() : 0.0;
    }
    for (const auto& t : m_delayed) {
        m_bounds.terms.push_back({spectral_norm(t.matrix), t.delay});
        for (int j = 0; j < m_n; ++j)
            for (int i = 0; i < m_n; ++i)
                if (t.matrix(i, j) != cplx(0.0)) m_bounds.entries.push_back({i, j, std::abs(t.matrix(i, j)), t.delay});
    }
}

LinearDDE::LinearDDE(SparseMatrixXd a0, std::vector<SparseDelayTerm> delayed) : m_sparse(true), m_sa0(std::move(a0)) {
    const auto n = m_sa0.rows();
    if (n < 1 || m_sa0.cols() != n) throw std::invalid_argument(a0_message(m_sa0.rows(), m_sa0.cols()));
    if (!all_finite(m_sa0)) throw std::invalid_argument("A0 has a non-finite entry: expected finite coefficients");
    for (std::size_t k = 0; k < delayed.size(); ++k) {
        auto& t = delayed[k];
        if (t.matrix.rows() != n || t.matrix.cols() != n) throw std::invalid_argument(size_message(k, t.matrix.rows(), t.matrix.cols(), n));
        if (!all_finite(t.matrix))
            throw std::invalid_argument("delayed matrix " + std::to_string(k + 1) + " has a non-finite entry: expected finite coefficients");
        if (!std::isfinite(t.delay) || t.delay < 0.0) throw std::invalid_argument(delay_message(k, t.delay));
        if (t.delay == 0.0) {
            m_sa0 += t.matrix;
            continue;
        }
        auto same = std::find_if(m_sdelayed.begin(), m_sdelayed.end(), [&](const SparseDelayTerm& u) { return u.delay == t.delay; });
        if (same != m_sdelayed.end())
            same->matrix += t.matrix;
        else
            m_sdelayed.push_back(std::move(t));
    }
    std::sort(m_sdelayed.begin(), m_sdelayed.end(), [](const SparseDelayTerm& a, const SparseDelayTerm& b) { return a.delay < b.delay; });
    std::vector<SparseDelayTerm> kept;
    for (auto& t : m_sdelayed) {
        t.matrix.prune(0.0);
        t.matrix.makeCompressed();
        if (t.matrix.nonZeros() > 0) kept.push_back(std::move(t));
    }
    m_sdelayed = std::move(kept);
    m_sa0.prune(0.0);
    m_sa0.makeCompressed();
    m_n = static_cast<int>(n);
    m_real = true;
    for (const auto& t : m_sdelayed) m_delays.push_back(t.delay);
    m_bounds.n = m_n;
    m_bounds.n0 = norm2_bound(m_sa0);
    m_bounds.mu = log_norm_bound(m_sa0);
    m_bounds.skew = norm2_bound(SparseMatrixXd(0.5 * (m_sa0 - SparseMatrixXd(m_sa0.transpose()))));
    for (const auto& t : m_sdelayed) {
        m_bounds.terms.push_back({norm2_bound(t.matrix), t.delay});
        for (int k = 0; k < t.matrix.outerSize(); ++k)
            for (SparseMatrixXd::InnerIterator it(t.matrix, k); it; ++it)
                if (it.value() != 0.0)
                    m_bounds.entries.push_back({static_cast<int>(it.row()), static_cast<int>(it.col()), std::abs(it.value()), t.delay});
    }
}

const MatrixXc& LinearDDE::a0() const {
    if (m_sparse) throw std::logic_error("LinearDDE::a0: sparse storage (use sparse_a0() or to_dense())");
    return m_a0;
}

const std::vector<DelayTerm>& LinearDDE::delayed() const {
    if (m_sparse) throw std::logic_error("LinearDDE::delayed: sparse storage (use sparse_delayed() or to_dense())");
    return m_delayed;
}

const SparseMatrixXd& LinearDDE::sparse_a0() const {
    if (!m_sparse) throw std::logic_error("LinearDDE::sparse_a0: dense storage (use a0() or to_sparse())");
    return m_sa0;
}

const std::vector<SparseDelayTerm>& LinearDDE::sparse_delayed() const {
    if (!m_sparse) throw std::logic_error("LinearDDE::sparse_delayed: dense storage (use delayed() or to_sparse())");
    return m_sdelayed;
}

LinearDDE LinearDDE::to_dense() const {
    if (!m_sparse) return *this;
    std::vector<DelayTerm> terms;
    for (const auto& t : m_sdelayed) terms.push_back({MatrixXc(Eigen::MatrixXd(t.matrix).cast<cplx>()), t.delay});
    return LinearDDE(MatrixXc(Eigen::MatrixXd(m_sa0).cast<cplx>()), terms);
}

LinearDDE LinearDDE::to_sparse() const {
    if (m_sparse) return *this;
    if (!m_real) throw std::invalid_argument("sparse storage needs real coefficients: this DDE has complex ones");
    std::vector<SparseDelayTerm> terms;
    for (const auto& t : m_delayed) terms.push_back({Eigen::MatrixXd(t.matrix.real()).sparseView(), t.delay});
    return LinearDDE(SparseMatrixXd(Eigen::MatrixXd(m_a0.real()).sparseView()), terms);
}

MatrixXc LinearDDE::characteristic_matrix(cplx lambda) const {
    if (m_sparse) return MatrixXc(sparse_characteristic_matrix(lambda));
    MatrixXc d = lambda * MatrixXc::Identity(m_n, m_n) - m_a0;
    for (const auto& t : m_delayed) d -= std::exp(-lambda * t.delay) * t.matrix;
    return d;
}

MatrixXc LinearDDE::characteristic_derivative(cplx lambda) const {
    if (m_sparse) return MatrixXc(sparse_characteristic_derivative(lambda));
    MatrixXc d = MatrixXc::Identity(m_n, m_n);
    for (const auto& t : m_delayed) d += (t.delay * std::exp(-lambda * t.delay)) * t.matrix;
    return d;
}

SparseMatrixXc LinearDDE::sparse_characteristic_matrix(cplx lambda) const {
    if (!m_sparse) return to_sparse().sparse_characteristic_matrix(lambda);
    SparseMatrixXc eye(m_n, m_n);
    eye.setIdentity();
    SparseMatrixXc d = lambda * eye - m_sa0.cast<cplx>();
    for (const auto& t : m_sdelayed) d -= std::exp(-lambda * t.delay) * t.matrix.cast<cplx>();
    return d;
}

SparseMatrixXc LinearDDE::sparse_characteristic_derivative(cplx lambda) const {
    if (!m_sparse) return to_sparse().sparse_characteristic_derivative(lambda);
    SparseMatrixXc d(m_n, m_n);
    d.setIdentity();
    for (const auto& t : m_sdelayed) d += (t.delay * std::exp(-lambda * t.delay)) * t.matrix.cast<cplx>();
    return d;
}

VectorXc LinearDDE::apply_characteristic(cplx lambda, const VectorXc& v) const {
    if (!m_sparse) return characteristic_matrix(lambda) * v;
    VectorXc out = lambda * v;
    VectorXc w = m_sa0.cast<cplx>() * v;
    out -= w;
    for (const auto& t : m_sdelayed) {
        w = t.matrix.cast<cplx>() * v;
        out -= std::exp(-lambda * t.delay) * w;
    }
    return out;
}

MatrixXc LinearDDE::ode_limit() const {
    if (m_sparse) return to_dense().ode_limit();
    MatrixXc a = m_a0;
    for (const auto& t : m_delayed) a += t.matrix;
    return a;
}

}  // namespace ddemap
