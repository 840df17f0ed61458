#include "ddemap/solve/sparse_lu.hpp"

#include <stdexcept>

#include <Eigen/UmfPackSupport>

namespace ddemap {

struct SparseLU::Impl {
    Eigen::SparseMatrix<double> a;  // UMFPACK reads the matrix again in the solves
    Eigen::UmfPackLU<Eigen::SparseMatrix<double>> lu;
    bool ok = false;
};

SparseLU::SparseLU() : m_impl(std::make_unique<Impl>()) {}
SparseLU::~SparseLU() = default;

bool SparseLU::factorize(const Eigen::SparseMatrix<double>& a) {
    if (a.rows() != a.cols()) throw std::invalid_argument("SparseLU: expected a square matrix");
    m_impl->a = a;
    m_impl->a.makeCompressed();
    m_impl->lu.compute(m_impl->a);
    m_impl->ok = m_impl->lu.info() == Eigen::Success;
    return m_impl->ok;
}

Eigen::VectorXd SparseLU::solve(const Eigen::VectorXd& b) const {
    if (!m_impl->ok) throw std::logic_error("SparseLU::solve without a successful factorisation");
    return m_impl->lu.solve(b);
}

Eigen::MatrixXd SparseLU::solve(const Eigen::MatrixXd& b) const {
    if (!m_impl->ok) throw std::logic_error("SparseLU::solve without a successful factorisation");
    return m_impl->lu.solve(b);
}

}  // namespace ddemap
