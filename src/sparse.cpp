#include "ddemap/sparse.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/UmfPackSupport>
#include <Spectra/GenEigsComplexShiftSolver.h>

#include "ddemap/chebyshev.hpp"

namespace ddemap {

double SparseDDE::max_delay() const {
    double d = 0.0;
    for (const auto& t : delayed) d = std::max(d, t.delay);
    return d;
}

void SparseDDE::validate() const {
    const auto n = a0.rows();
    if (n < 1 || a0.cols() != n) throw std::invalid_argument("A0 must be square with dimension >= 1");
    auto finite = [](const Eigen::SparseMatrix<double>& m) {
        for (int k = 0; k < m.outerSize(); ++k)
            for (Eigen::SparseMatrix<double>::InnerIterator it(m, k); it; ++it)
                if (!std::isfinite(it.value())) return false;
        return true;
    };
    if (!finite(a0)) throw std::invalid_argument("A0 has a non-finite entry");
    for (std::size_t k = 0; k < delayed.size(); ++k) {
        const auto& t = delayed[k];
        if (t.matrix.rows() != n || t.matrix.cols() != n) throw std::invalid_argument("delayed matrix " + std::to_string(k + 1) + " has the wrong size");
        if (!finite(t.matrix)) throw std::invalid_argument("delayed matrix " + std::to_string(k + 1) + " has a non-finite entry");
        if (!(std::isfinite(t.delay) && t.delay > 0.0)) throw std::invalid_argument("delay " + std::to_string(k + 1) + ": expected a finite delay > 0");
    }
}

LinearDDE SparseDDE::to_dense() const {
    std::vector<DelayTerm> terms;
    for (const auto& t : delayed) terms.push_back({MatrixXc(Eigen::MatrixXd(t.matrix).cast<cplx>()), t.delay});
    return LinearDDE(MatrixXc(Eigen::MatrixXd(a0).cast<cplx>()), terms);
}

namespace {

using SpC = Eigen::SparseMatrix<cplx>;

/// Spectra operation: y = Re((A_M - sigma I)^{-1} x) for the collocation matrix A_M.
class StructuredShiftInvert {
public:
    using Scalar = double;

    StructuredShiftInvert(const SparseDDE& dde, int degree) : m_dde(dde), m_m(degree), m_n(dde.dimension()) {
        const double tau = dde.max_delay();
        m_d = detail::chebyshev_differentiation(degree) * (2.0 / tau);
        for (const auto& t : dde.delayed) m_l.push_back(detail::chebyshev_lagrange_row(degree, 1.0 - 2.0 * t.delay / tau));
        // the pattern of S is the union of the patterns of A0, I and every A_k
        Eigen::SparseMatrix<double> pattern = dde.a0;
        Eigen::SparseMatrix<double> eye(m_n, m_n);
        eye.setIdentity();
        pattern += eye;
        for (const auto& t : dde.delayed) pattern += t.matrix;
        m_pattern = pattern.cast<cplx>();
        m_pattern.makeCompressed();
        m_lu.analyzePattern(m_pattern);
    }

    Eigen::Index rows() const { return static_cast<Eigen::Index>(m_m + 1) * m_n; }
    Eigen::Index cols() const { return rows(); }

    void set_shift(double sr, double si) {
        const cplx sigma(sr, si);
        const int m = m_m;
        Eigen::MatrixXcd b = m_d.block(1, 1, m, m).cast<cplx>();
        b.diagonal().array() -= sigma;
        m_blu.compute(b);
        m_g = m_blu.solve(m_d.block(1, 0, m, 1).cast<cplx>());
        m_c.clear();
        for (const auto& l : m_l) m_c.push_back(l(0) - (l.tail(m).cast<cplx>().transpose() * m_g)(0));
        // UMFPACK keeps using the matrix after factorizing it (in solves): it is a member
        SpC& s = m_s;
        s = m_dde.a0.cast<cplx>();
        SpC eye(m_n, m_n);
        eye.setIdentity();
        s -= sigma * eye;
        for (std::size_t k = 0; k < m_dde.delayed.size(); ++k) s += m_c[k] * m_dde.delayed[k].matrix.cast<cplx>();
        // same pattern as analysed: add explicit zeros where needed
        s += 0.0 * m_pattern;
        s.makeCompressed();
        m_lu.factorize(s);
        if (m_lu.info() != Eigen::Success) throw std::runtime_error("UMFPACK could not factorize the shifted system");
        ++m_factorizations;
    }

    /// u = (A_M - sigma I)^{-1} b for complex b, blocks u_j of n entries
    Eigen::VectorXcd solve(const Eigen::VectorXcd& b) const {
        const int m = m_m, n = m_n;
        Eigen::Map<const Eigen::MatrixXcd> bb(b.data(), n, m + 1);  // column j = block j
        const Eigen::MatrixXcd w = m_blu.solve(bb.rightCols(m).transpose());  // M x n: B^{-1} b[1:]
        Eigen::VectorXcd r = bb.col(0);
        for (std::size_t k = 0; k < m_dde.delayed.size(); ++k) {
            const Eigen::VectorXcd h = (m_l[k].tail(m).cast<cplx>().transpose() * w).transpose();
            r -= m_dde.delayed[k].matrix.cast<cplx>() * h;
        }
        const Eigen::VectorXcd u0 = m_lu.solve(r);
        Eigen::VectorXcd u(static_cast<Eigen::Index>(m + 1) * n);
        u.head(n) = u0;
        const Eigen::MatrixXcd ublock = w - m_g * u0.transpose();  // M x n
        for (int j = 1; j <= m; ++j) u.segment(static_cast<Eigen::Index>(j) * n, n) = ublock.row(j - 1).transpose();
        return u;
    }

    void perform_op(const double* x_in, double* y_out) const {
        const Eigen::Index len = rows();
        Eigen::VectorXcd b = Eigen::Map<const Eigen::VectorXd>(x_in, len).cast<cplx>();
        Eigen::Map<Eigen::VectorXd>(y_out, len) = solve(b).real();
    }

    int factorizations() const { return m_factorizations; }

private:
    const SparseDDE& m_dde;
    int m_m, m_n;
    Eigen::MatrixXd m_d;
    std::vector<Eigen::VectorXd> m_l;
    SpC m_pattern;
    SpC m_s;
    Eigen::UmfPackLU<SpC> m_lu;
    Eigen::PartialPivLU<Eigen::MatrixXcd> m_blu;
    Eigen::VectorXcd m_g;
    std::vector<cplx> m_c;
    int m_factorizations = 0;
};

}  // namespace

SparseEigenResult sparse_collocation_eigenvalues(const SparseDDE& dde, int degree, const std::vector<cplx>& shifts, int nev) {
    dde.validate();
    if (dde.delayed.empty()) throw std::invalid_argument("the sparse path needs at least one delay");
    if (degree < 2) throw std::invalid_argument("collocation degree must be >= 2");
    StructuredShiftInvert op(dde, degree);
    const Eigen::Index size = op.rows();
    if (nev < 1 || nev > size - 3) throw std::invalid_argument("nev: expected 1 <= nev <= size - 3");
    SparseEigenResult out;
    for (cplx sigma : shifts) {
        const Eigen::Index ncv = std::min<Eigen::Index>(size, std::max<Eigen::Index>(2 * nev + 1, 20));
        Spectra::GenEigsComplexShiftSolver<StructuredShiftInvert> solver(op, nev, ncv, sigma.real(), sigma.imag());
        solver.init();
        solver.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
        if (solver.info() != Spectra::CompInfo::Successful) out.status = RootStatus::EigenFailure;
        const Eigen::VectorXcd ev = solver.eigenvalues();
        for (Eigen::Index i = 0; i < ev.size(); ++i) {
            const cplx z = ev(i);
            const bool dup = std::any_of(out.values.begin(), out.values.end(),
                                         [&](cplx w) { return std::abs(w - z) <= 1e-9 * std::max(1.0, std::abs(z)); });
            if (!dup) out.values.push_back(z);
        }
    }
    out.factorizations = op.factorizations();
    return out;
}

}  // namespace ddemap
