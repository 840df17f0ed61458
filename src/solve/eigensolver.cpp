#include "ddemap/solve/eigensolver.hpp"

#include <Eigen/Eigenvalues>

#include "ddemap/discretize/collocation.hpp"

namespace ddemap {

EigenResult DenseEigenSolver::eigenvalues(const LinearDDE& dde, int degree, int /*wanted*/) const {
    EigenResult out;
    const MatrixXc a = collocation_matrix(dde, degree);
    if (dde.is_real()) {
        const Eigen::MatrixXd ar = a.real();
        Eigen::EigenSolver<Eigen::MatrixXd> es(ar, /*computeEigenvectors=*/false);
        if (es.info() != Eigen::Success) {
            out.status = EigenStatus::NotConverging;
            return out;
        }
        const auto& ev = es.eigenvalues();
        out.values.assign(ev.data(), ev.data() + ev.size());
    } else {
        Eigen::ComplexEigenSolver<MatrixXc> es(a, /*computeEigenvectors=*/false);
        if (es.info() != Eigen::Success) {
            out.status = EigenStatus::NotConverging;
            return out;
        }
        const auto& ev = es.eigenvalues();
        out.values.assign(ev.data(), ev.data() + ev.size());
    }
    return out;
}

}  // namespace ddemap
