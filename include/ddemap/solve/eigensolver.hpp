#pragma once
/// \file eigensolver.hpp
/// Eigen-solver backends behind one interface (a pluggable policy in the style of Spectra's
/// operation classes). A backend receives the DDE and the collocation degree M and returns
/// eigenvalues of the collocation matrix, at least the `wanted` rightmost ones. The dense
/// backend assembles the full matrix and computes all eigenvalues; a sparse backend may
/// exploit the structure (see collocation.hpp) and return only the rightmost ones.

#include <memory>
#include <string>
#include <vector>

#include "ddemap/problem/linear_dde.hpp"

namespace ddemap {

/// Outcome of one backend call (cf. Spectra's CompInfo).
enum class EigenStatus { Successful, NotConverging, NumericalIssue };

struct EigenResult {
    std::vector<cplx> values;  ///< eigenvalues, in no particular order
    EigenStatus status = EigenStatus::Successful;
};

class EigenSolverBackend {
public:
    virtual ~EigenSolverBackend() = default;
    virtual std::string name() const = 0;
    /// Eigenvalues of collocation_matrix(dde, degree); at least the `wanted` rightmost.
    virtual EigenResult eigenvalues(const LinearDDE& dde, int degree, int wanted) const = 0;
};

/// All eigenvalues by Eigen's dense QR algorithm (real arithmetic when the DDE is real).
class DenseEigenSolver final : public EigenSolverBackend {
public:
    std::string name() const override { return "dense"; }
    EigenResult eigenvalues(const LinearDDE& dde, int degree, int wanted) const override;
};

}  // namespace ddemap
