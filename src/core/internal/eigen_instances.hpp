#pragma once
/// \file eigen_instances.hpp
/// Eigen's dense decompositions for the matrix types ddemap uses, compiled once
/// (src/core/eigen_instances_*.cpp) instead of in every file that uses them. GCC spends most of
/// a file's compile time instantiating these templates (the eigenvalues of a MatrixXcd alone: 38 s
/// at -O3); with the declarations below, a file that decomposes a MatrixXcd links to the one copy.
///
/// The declarations cover a decomposition built from a plain matrix of the listed type, e.g.
/// `Eigen::ComplexEigenSolver<Eigen::MatrixXcd> es(Eigen::MatrixXcd(block))`: where `compute` is
/// a member template (Eigen 3.4), it is declared here for that argument type only. Built from a
/// block or an expression, it is instantiated where it is used: correct, only slow to compile.
/// Where a whole class costs much more than the members that do the work, only those are listed.
/// The precompiled header of every target (cmake/pch.hpp) includes this file.

#include <Eigen/Dense>
#include <Eigen/SparseLU>

// each instantiation file defines one of DDEMAP_EIGEN_INSTANTIATE_{EIG,SELFADJOINT,SVD,LU,SPARSELU}:
// the declarations of its group become definitions (one group a file, so that they compile in
// parallel)
#ifdef DDEMAP_EIGEN_INSTANTIATE_EIG
#define DDEMAP_EIGEN_EXTERN_EIG
#else
#define DDEMAP_EIGEN_EXTERN_EIG extern
#endif
#ifdef DDEMAP_EIGEN_INSTANTIATE_SELFADJOINT
#define DDEMAP_EIGEN_EXTERN_SELFADJOINT
#else
#define DDEMAP_EIGEN_EXTERN_SELFADJOINT extern
#endif
#ifdef DDEMAP_EIGEN_INSTANTIATE_SVD
#define DDEMAP_EIGEN_EXTERN_SVD
#else
#define DDEMAP_EIGEN_EXTERN_SVD extern
#endif
#ifdef DDEMAP_EIGEN_INSTANTIATE_LU
#define DDEMAP_EIGEN_EXTERN_LU
#else
#define DDEMAP_EIGEN_EXTERN_LU extern
#endif
#ifdef DDEMAP_EIGEN_INSTANTIATE_SPARSELU
#define DDEMAP_EIGEN_EXTERN_SPARSELU
#else
#define DDEMAP_EIGEN_EXTERN_SPARSELU extern
#endif

namespace ddemap::eigen_instances {
using MC = Eigen::MatrixXcd;
using MD = Eigen::MatrixXd;
using M5 = Eigen::Matrix<double, 5, 5>;
using SD = Eigen::SparseMatrix<double>;
using SC = Eigen::SparseMatrix<std::complex<double>>;
}  // namespace ddemap::eigen_instances

// eigenvalues (eigen_instances_eig.cpp)
DDEMAP_EIGEN_EXTERN_EIG template class Eigen::ComplexSchur<ddemap::eigen_instances::MC>;
DDEMAP_EIGEN_EXTERN_EIG template Eigen::ComplexSchur<ddemap::eigen_instances::MC>&
Eigen::ComplexSchur<ddemap::eigen_instances::MC>::compute<ddemap::eigen_instances::MC>(
    const Eigen::EigenBase<ddemap::eigen_instances::MC>&, bool);
DDEMAP_EIGEN_EXTERN_EIG template Eigen::ComplexSchur<ddemap::eigen_instances::MC>&
Eigen::ComplexSchur<ddemap::eigen_instances::MC>::computeFromHessenberg<ddemap::eigen_instances::MC, ddemap::eigen_instances::MC>(
    const ddemap::eigen_instances::MC&, const ddemap::eigen_instances::MC&, bool);
DDEMAP_EIGEN_EXTERN_EIG template class Eigen::ComplexEigenSolver<ddemap::eigen_instances::MC>;
DDEMAP_EIGEN_EXTERN_EIG template Eigen::ComplexEigenSolver<ddemap::eigen_instances::MC>::ComplexEigenSolver(
    const Eigen::EigenBase<ddemap::eigen_instances::MC>&, bool);
DDEMAP_EIGEN_EXTERN_EIG template Eigen::ComplexEigenSolver<ddemap::eigen_instances::MC>&
Eigen::ComplexEigenSolver<ddemap::eigen_instances::MC>::compute<ddemap::eigen_instances::MC>(
    const Eigen::EigenBase<ddemap::eigen_instances::MC>&, bool);
DDEMAP_EIGEN_EXTERN_EIG template class Eigen::EigenSolver<ddemap::eigen_instances::MD>;
DDEMAP_EIGEN_EXTERN_EIG template Eigen::EigenSolver<ddemap::eigen_instances::MD>::EigenSolver(
    const Eigen::EigenBase<ddemap::eigen_instances::MD>&, bool);
DDEMAP_EIGEN_EXTERN_EIG template Eigen::EigenSolver<ddemap::eigen_instances::MD>&
Eigen::EigenSolver<ddemap::eigen_instances::MD>::compute<ddemap::eigen_instances::MD>(
    const Eigen::EigenBase<ddemap::eigen_instances::MD>&, bool);

// Hermitian and symmetric eigenvalues (eigen_instances_selfadjoint.cpp): compute, where the work is
// (the whole class would add 18 s of members nothing uses)
DDEMAP_EIGEN_EXTERN_SELFADJOINT template Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::MD>&
Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::MD>::compute<ddemap::eigen_instances::MD>(
    const Eigen::EigenBase<ddemap::eigen_instances::MD>&, int);
DDEMAP_EIGEN_EXTERN_SELFADJOINT template Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::MC>&
Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::MC>::compute<ddemap::eigen_instances::MC>(
    const Eigen::EigenBase<ddemap::eigen_instances::MC>&, int);
DDEMAP_EIGEN_EXTERN_SELFADJOINT template Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::M5>&
Eigen::SelfAdjointEigenSolver<ddemap::eigen_instances::M5>::compute<ddemap::eigen_instances::M5>(
    const Eigen::EigenBase<ddemap::eigen_instances::M5>&, int);

// singular values (eigen_instances_svd.cpp)
DDEMAP_EIGEN_EXTERN_SVD template class Eigen::JacobiSVD<ddemap::eigen_instances::MC>;
DDEMAP_EIGEN_EXTERN_SVD template class Eigen::JacobiSVD<ddemap::eigen_instances::MD>;

// linear systems (eigen_instances_lu.cpp): the members that factorise (private or protected,
// which an explicit instantiation may name), not the whole classes (twice the compile time)
DDEMAP_EIGEN_EXTERN_LU template void Eigen::PartialPivLU<ddemap::eigen_instances::MC>::compute();
DDEMAP_EIGEN_EXTERN_LU template void Eigen::PartialPivLU<ddemap::eigen_instances::MD>::compute();
DDEMAP_EIGEN_EXTERN_LU template void Eigen::FullPivLU<ddemap::eigen_instances::MD>::computeInPlace();
DDEMAP_EIGEN_EXTERN_LU template void Eigen::ColPivHouseholderQR<ddemap::eigen_instances::MD>::computeInPlace();

// sparse linear systems (eigen_instances_sparselu.cpp)
// (the members that do the work: the whole class does not compile for complex scalars)
DDEMAP_EIGEN_EXTERN_SPARSELU template void Eigen::SparseLU<ddemap::eigen_instances::SD, Eigen::COLAMDOrdering<int>>::analyzePattern(
    const ddemap::eigen_instances::SD&);
DDEMAP_EIGEN_EXTERN_SPARSELU template void Eigen::SparseLU<ddemap::eigen_instances::SD, Eigen::COLAMDOrdering<int>>::factorize(
    const ddemap::eigen_instances::SD&);
DDEMAP_EIGEN_EXTERN_SPARSELU template void Eigen::SparseLU<ddemap::eigen_instances::SC, Eigen::COLAMDOrdering<int>>::analyzePattern(
    const ddemap::eigen_instances::SC&);
DDEMAP_EIGEN_EXTERN_SPARSELU template void Eigen::SparseLU<ddemap::eigen_instances::SC, Eigen::COLAMDOrdering<int>>::factorize(
    const ddemap::eigen_instances::SC&);
