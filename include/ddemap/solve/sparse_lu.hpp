#pragma once
/// \file sparse_lu.hpp
/// A real sparse LU factorisation (UMFPACK through Eigen::UmfPackLU) behind a small interface,
/// so that higher layers solve sparse systems A x = b without depending on SuiteSparse's
/// headers. A is square; the factorisation is symbolic + numeric every time (the pattern may
/// change between calls).

#include <memory>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace ddemap {

class SparseLU {
public:
    SparseLU();
    ~SparseLU();
    SparseLU(const SparseLU&) = delete;
    SparseLU& operator=(const SparseLU&) = delete;

    /// Factorises A (square, compressed or not; a copy is kept for the solves). False when A is
    /// singular to working precision or the factorisation fails.
    bool factorize(const Eigen::SparseMatrix<double>& a);
    /// x = A^{-1} b (b of A's size); requires a successful factorize().
    Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
    /// X = A^{-1} B for several right-hand sides.
    Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace ddemap
