#include "ddemap/solve/shift_invert.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <queue>
#include <random>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/UmfPackSupport>
#include <Spectra/GenEigsComplexShiftSolver.h>

#include "ddemap/discretize/chebyshev.hpp"
#include "ddemap/problem/root_bounds.hpp"
#include "core/internal/eigen_threads.hpp"
#include "internal/backends.hpp"
#include "internal/disc_cover.hpp"
#include "internal/gram_schmidt.hpp"

namespace ddemap {

namespace {

using SpC = Eigen::SparseMatrix<cplx>;
using SpD = Eigen::SparseMatrix<double>;
using detail::orthogonalise_twice;
using detail::times_columns;

/// The union of the patterns of A0, I and every A_k (compressed): the pattern of Delta(z) and
/// of the shifted matrix S, analysed once for every sparse LU and Gershgorin test.
SpD union_pattern(const LinearDDE& dde) {
    SpD pattern = dde.sparse_a0();
    SpD eye(dde.dimension(), dde.dimension());
    eye.setIdentity();
    pattern += eye;
    for (const auto& t : dde.sparse_delayed()) pattern += t.matrix;
    pattern.makeCompressed();
    return pattern;
}

/// UMFPACK's LU with the solve of the adjoint system too (UMFPACK_At: A^H x = b), which
/// Eigen's wrapper does not offer, and the size of the last factorisation (for the covering's
/// cost model: Covering::probe_steps).
class UmfLU : public Eigen::UmfPackLU<SpC> {
public:
    bool adjoint_solve(const Eigen::VectorXcd& b, Eigen::VectorXcd& x) const {
        x.resize(b.size());
        const int code = umfpack_zi_solve(UMFPACK_At, mp_matrix.outerIndexPtr(), mp_matrix.innerIndexPtr(),
                                          &Eigen::numext::real_ref(mp_matrix.valuePtr()[0]), nullptr, &Eigen::numext::real_ref(x.data()[0]),
                                          nullptr, &Eigen::numext::real_ref(b.data()[0]), nullptr, m_numeric, m_control.data(),
                                          m_umfpackInfo.data());
        return code == 0;
    }
    /// Factorises and records UMFPACK's flop count and the nonzeros of L and U.
    void factorize_counted(const SpC& a) {
        factorize(a);
        m_flops = std::max(0.0, m_umfpackInfo[UMFPACK_FLOPS]);
        m_nonzeros = std::max(0.0, m_umfpackInfo[UMFPACK_LNZ]) + std::max(0.0, m_umfpackInfo[UMFPACK_UNZ]);
    }
    double flops() const { return m_flops; }
    double nonzeros() const { return m_nonzeros; }
    /// After analyzePattern: UMFPACK's symbolic estimates of the factorisation (upper bounds):
    /// its flops, the nonzeros of L and U, and the bytes of the numeric object.
    double flops_estimate() const { return std::max(0.0, m_umfpackInfo[UMFPACK_FLOPS_ESTIMATE]); }
    double nonzeros_estimate() const {
        return std::max(0.0, m_umfpackInfo[UMFPACK_LNZ_ESTIMATE]) + std::max(0.0, m_umfpackInfo[UMFPACK_UNZ_ESTIMATE]);
    }
    double bytes_estimate() const {
        return std::max(0.0, m_umfpackInfo[UMFPACK_NUMERIC_SIZE_ESTIMATE]) * std::max(0.0, m_umfpackInfo[UMFPACK_SIZE_OF_UNIT]);
    }

private:
    double m_flops = 0.0, m_nonzeros = 0.0;
};

/// Switches off UMFPACK's iterative refinement in solves (UMFPACK_IRSTEP = 0). Refinement
/// computes the residual and the componentwise backward error after every solve, a complex
/// modulus (hypot) per nonzero: on a 10^4-state ring that was a fifth of the whole run. Arnoldi
/// and the Lanczos norm estimate need backward-stable solves, not componentwise-accurate ones,
/// and every root found is refined by Newton (SparseNewton keeps the refinement).
template <class Lu>
void no_refinement(Lu& lu) {
    lu.umfpackControl()(UMFPACK_IRSTEP) = 0.0;
}

/// Spectra operation: y = Re((A_M - sigma I)^{-1} x) for the collocation matrix A_M.
class StructuredShiftInvert {
public:
    using Scalar = double;

    StructuredShiftInvert(const LinearDDE& dde, int degree) : m_m(degree), m_n(dde.dimension()) {
        const double tau = dde.max_delay();
        m_d = chebyshev_differentiation(degree) * (2.0 / tau);
        for (const auto& t : dde.sparse_delayed()) {
            m_l.push_back(chebyshev_lagrange_row(degree, 1.0 - 2.0 * t.delay / tau));
            m_ak.push_back(t.matrix.cast<cplx>());
        }
        m_a0 = dde.sparse_a0().cast<cplx>();
        m_pattern = union_pattern(dde).cast<cplx>();
        m_pattern.makeCompressed();
        m_eye.resize(m_n, m_n);
        m_eye.setIdentity();
        no_refinement(m_lu);
        m_lu.analyzePattern(m_pattern);
    }

    Eigen::Index rows() const { return static_cast<Eigen::Index>(m_m + 1) * m_n; }
    Eigen::Index cols() const { return rows(); }

    /// Factorises for the shift; false when S is singular to working precision.
    bool factor(cplx sigma) {
        if (m_ok && sigma == m_sigma) return true;
        const int m = m_m;
        Eigen::MatrixXcd b = m_d.block(1, 1, m, m).cast<cplx>();
        b.diagonal().array() -= sigma;
        m_blu.compute(b);
        m_g = m_blu.solve(m_d.block(1, 0, m, 1).cast<cplx>());
        m_c.clear();
        for (const auto& l : m_l) m_c.push_back(l(0) - (l.tail(m).cast<cplx>().transpose() * m_g)(0));
        // UMFPACK keeps using the matrix after factorising it (in solves): it is a member
        m_s = m_a0 - sigma * m_eye;
        for (std::size_t k = 0; k < m_ak.size(); ++k) m_s += m_c[k] * m_ak[k];
        m_s += cplx(0.0) * m_pattern;  // the analysed pattern, explicit zeros included
        m_s.makeCompressed();
        m_lu.factorize_counted(m_s);
        ++m_factorizations;
        m_sigma = sigma;
        m_ok = m_lu.info() == Eigen::Success && m_g.allFinite();
        return m_ok;
    }

    /// Spectra's contract; a singular shift leaves the operator returning NaN (Arnoldi then fails).
    void set_shift(double sr, double si) { factor(cplx(sr, si)); }

    /// u = (A_M - sigma I)^{-1} b for complex b, blocks u_j of n entries
    Eigen::VectorXcd solve(const Eigen::VectorXcd& b) const {
        const int m = m_m, n = m_n;
        Eigen::Map<const Eigen::MatrixXcd> bb(b.data(), n, m + 1);  // column j = block j
        const Eigen::MatrixXcd w = m_blu.solve(bb.rightCols(m).transpose());  // M x n: B^{-1} b[1:]
        Eigen::VectorXcd r = bb.col(0);
        for (std::size_t k = 0; k < m_ak.size(); ++k) {
            const Eigen::VectorXcd h = (m_l[k].tail(m).cast<cplx>().transpose() * w).transpose();
            r -= m_ak[k] * h;
        }
        Eigen::VectorXcd u0 = m_lu.solve(r);
        Eigen::VectorXcd u(static_cast<Eigen::Index>(m + 1) * n);
        u.head(n) = u0;
        Eigen::Map<Eigen::MatrixXcd> ub(u.data() + n, n, m);  // column j-1 = block j
        ub.noalias() = w.transpose();
        ub.noalias() -= u0 * m_g.transpose();
        return u;
    }

    /// The same solve for b in compact form, blocks b_j = Q a_j^T (a: (M+1) x r coefficients, Q:
    /// n x r): with W = B^{-1} a[1:] (written to w, M x r) the history blocks of u are
    /// u_j = Q w_{j-1}^T - g_j u0, and u0 = S^{-1} (Q a_0^T - sum_k A_k Q (W^T l_k[1:])) is returned.
    /// Cost: one sparse solve and O((M + delays) n r + M^2 r) (the (M+1) n vector is never formed).
    Eigen::VectorXcd solve_compact(const Eigen::Ref<const Eigen::MatrixXcd>& q, const Eigen::Ref<const Eigen::MatrixXcd>& a,
                                   Eigen::MatrixXcd& w) const {
        const int m = m_m;
        w = m_blu.solve(a.bottomRows(m));
        // the coefficients of Q for block 0 and for each delayed term, then Q times all of them in one pass
        Eigen::MatrixXcd x(q.cols(), static_cast<Eigen::Index>(m_ak.size()) + 1);
        x.col(0) = a.row(0).transpose();
        for (std::size_t k = 0; k < m_ak.size(); ++k)
            x.col(static_cast<Eigen::Index>(k) + 1).noalias() = w.transpose() * m_l[k].tail(m).cast<cplx>();
        const Eigen::MatrixXcd qx = times_columns(q, x);
        Eigen::VectorXcd r = qx.col(0);
        for (std::size_t k = 0; k < m_ak.size(); ++k) r -= m_ak[k] * qx.col(static_cast<Eigen::Index>(k) + 1);
        return m_lu.solve(r);
    }
    int degree() const { return m_m; }
    int dimension() const { return m_n; }
    /// g = B^{-1} (2/tau) D[1:, 0] of the current shift
    const Eigen::VectorXcd& g() const { return m_g; }
    bool factored() const { return m_ok; }

    void perform_op(const double* x_in, double* y_out) const {
        const Eigen::Index len = rows();
        if (!m_ok) {
            Eigen::Map<Eigen::VectorXd>(y_out, len).setConstant(std::numeric_limits<double>::quiet_NaN());
            return;
        }
        const Eigen::VectorXcd b = Eigen::Map<const Eigen::VectorXd>(x_in, len).cast<cplx>();
        Eigen::Map<Eigen::VectorXd>(y_out, len) = solve(b).real();
    }

    int factorizations() const { return m_factorizations; }
    /// the last factorisation of S: UMFPACK's flops and the nonzeros of L and U
    double lu_flops() const { return m_lu.flops(); }
    double lu_nonzeros() const { return m_lu.nonzeros(); }
    int delays() const { return static_cast<int>(m_ak.size()); }

private:
    int m_m, m_n;
    Eigen::MatrixXd m_d;
    std::vector<Eigen::VectorXd> m_l;
    std::vector<SpC> m_ak;
    SpC m_a0, m_eye;
    SpC m_pattern;
    SpC m_s;
    UmfLU m_lu;
    Eigen::PartialPivLU<Eigen::MatrixXcd> m_blu;
    Eigen::VectorXcd m_g;
    std::vector<cplx> m_c;
    cplx m_sigma{0.0, 0.0};
    bool m_ok = false;
    int m_factorizations = 0;
};

/// Ritz values of a compact Arnoldi run: theta ~ 1/(lambda - sigma), largest |theta| first, and
/// how many of them, from the largest on, are converged without a gap.
struct CompactRitz {
    std::vector<cplx> theta;
    int converged = 0;   ///< length of the converged prefix of `theta`
    int steps = 0;       ///< Arnoldi steps taken (sparse solves)
    int rank = 0;        ///< columns of Q (at the end)
    int restarts = 0;    ///< Krylov-Schur restarts
    int max_rank = 0;    ///< columns of Q at most
};

/// Swaps the diagonal entries i and i+1 of the upper triangular s (complex Schur form
/// H = U s U^H) by one unitary rotation G: its first column is the eigenvector
/// (s_{i,i+1}, s_{i+1,i+1} - s_ii) of the 2 x 2 block for s_{i+1,i+1}, so G^H s G stays
/// triangular with the two entries exchanged (LAPACK ztrexc); u <- u G.
void schur_swap(Eigen::MatrixXcd& s, Eigen::MatrixXcd& u, Eigen::Index i) {
    const cplx a = s(i, i), c = s(i + 1, i + 1);
    cplx x1 = s(i, i + 1), x2 = c - a;
    const double nx = std::hypot(std::abs(x1), std::abs(x2));
    if (nx == 0.0) return;  // a == c and a zero coupling: nothing to exchange
    x1 /= nx;
    x2 /= nx;
    Eigen::Matrix2cd g;
    g << x1, -std::conj(x2), x2, std::conj(x1);
    s.middleRows(i, 2) = (g.adjoint() * s.middleRows(i, 2)).eval();
    s.middleCols(i, 2) = (s.middleCols(i, 2) * g).eval();
    u.middleCols(i, 2) = (u.middleCols(i, 2) * g).eval();
    s(i + 1, i) = 0.0;
    s(i, i) = c;
    s(i + 1, i + 1) = a;
}

/// Shift-invert Arnoldi on T = (A_M - sigma I)^{-1} in compact form (TOAR-like): every Krylov
/// vector of C^{(M+1) n} is stored as V_i = Q a_i, block j of it Q a_i[j, :]^T, with one
/// orthonormal n x r matrix Q for the whole basis and small (M+1) x r coefficients a_i. T maps
/// span(Q) blocks into span(Q, u0) blocks (StructuredShiftInvert::solve_compact), so each step
/// adds at most one column to Q, orthogonalised against Q (twice), and the Arnoldi
/// orthogonalisation runs on the coefficients ((M+1) r numbers instead of (M+1) n): with Q
/// orthonormal, <V_i, V_l> = <a_i, a_l>_F. Cost per step: one sparse solve, O(n r) for Q,
/// O((M+1) r k) for the rest.
///
/// The Krylov relation T V_k = V_k H_k + v_{k+1} h_k^T is kept throughout. Ritz values are the
/// eigenvalues theta of H_k, largest |theta| first; one counts as converged when its residual
/// |h_k^T y| / |y| <= tol |theta| (y its eigenvector of H_k; for an Arnoldi basis
/// h_k^T y = h_{k+1,k} y_k), and the run stops when `nev` of them, from the largest on, are
/// converged without a gap, or (a `goal` radius given) as soon as the disc of the converged
/// prefix reaches the goal (the cell the shift was placed for is then covered).
///
/// Without restarts (restarts = 0) the basis grows to `basis` vectors and stops there.
/// With restarts (Krylov-Schur, Stewart 2001): at `basis` vectors, H_k = U S U^H (complex
/// Schur form) is reordered so that the `keep` Ritz values of largest |theta| lead (schur_swap),
/// and the basis is truncated to V_k U[:, :keep] (coefficients a_i combined, Q untouched), with
/// H = S[:keep, :keep] and h^T = h_k^T U[:, :keep]; v_{k+1} stays the next vector. This is again a
/// Krylov relation of the same form (exact), and Arnoldi continues from it. A leading block of
/// Schur vectors whose couplings satisfy ||h[:j]|| <= 0.01 tol min |theta| is locked (its
/// couplings set to zero: an invariant subspace to that accuracy; the norms set to zero are
/// summed and added to every later residual, so the convergence test stays a bound). When r, the columns of Q,
/// would outgrow its storage, Q is compressed (TOAR): the stacked coefficients
/// [a_0; ...; a_keep] = X Sigma W^H (SVD), Q <- Q conj(W[:, :r']), a_i <- a_i W[:, :r'] (block j
/// of V_i is Q a_i[j, :]^T, and every transposed row a_i[j, :]^T lies in the span of conj(W)'s
/// columns), dropping singular values <= 1e-14 sigma_1 and those beyond the exact rank when
/// below 1e-13 sigma_1 (the kept subspace is a
/// Krylov space K_{keep+1}(T, w), and the blocks of T^j w lie in span(blocks of w, j new
/// columns), so r' <= keep + M + 2 in exact arithmetic).
class CompactKrylov {
public:
    CompactKrylov(const StructuredShiftInvert& op, int basis)
        : m_op(op), m_m(op.degree()), m_n(op.dimension()), m_rows(op.degree() + 1), m_kmax(std::max(2, basis)) {
        m_rcap = m_kmax + 2;
        m_q.resize(m_n, m_rcap);
        // column i: vec(a_i), (M+1) x rcap; its rows past (M+1) r_i (r_i: the rank when it was
        // written) are zero, set when the column is written (a run often stops long before
        // `basis` columns: zeroing them all up front cost more than the run)
        m_v.resize(m_rows * m_rcap, m_kmax + 1);
        m_v.col(0).setZero();
        m_h = Eigen::MatrixXcd::Zero(m_kmax + 1, m_kmax);
        std::mt19937 rng(20261123);
        std::uniform_real_distribution<double> unif(-1.0, 1.0);
        Eigen::VectorXcd q0(m_n);
        for (int i = 0; i < m_n; ++i) q0(i) = unif(rng);
        m_q.col(0) = q0 / q0.norm();
        Eigen::VectorXcd a0(m_rows);
        for (Eigen::Index j = 0; j < m_rows; ++j) a0(j) = unif(rng);
        m_v.col(0).head(m_rows) = a0 / a0.norm();
    }

    /// The run described above; `first_check`: steps before Ritz values are first computed.
    /// `goal` > 0: also stop once the converged prefix's disc |z - sigma| < 1/|theta_last|
    /// (shrunk by the same 1e-6 margin as the covering's) reaches that radius.
    /// `between` (may be empty) is called after every step and before every restart (it may
    /// throw, e.g. Cancelled: a long shift reports, and can be stopped, while it runs).
    /// `costly` (may be empty): asked at a check where something converged but not yet nev,
    /// with the steps taken, those up to the next check and the converged count; true stops the
    /// run there (its disc is then the converged prefix's, as at any other stop).
    CompactRitz run(int nev, int first_check, int restarts, int keep, double tol, double goal, int probe,
                    const std::function<void()>& between, const std::function<bool(int, int, int)>& costly) {
        CompactRitz out;
        // a goal may be met long before nev values converge: look from 20 steps on
        int check = std::min(goal > 0.0 ? std::min(first_check, 20) : first_check, m_kmax);
        if (probe > 0) check = std::min(check, probe);
        keep = std::clamp(keep, 1, m_kmax - 1);
        for (;;) {
            step();
            ++out.steps;
            if (between) between();
            out.max_rank = std::max(out.max_rank, m_r);
            if (m_k < check && !m_invariant && m_k < m_kmax) continue;
            ritz(tol, out);
            if (out.converged >= nev || m_invariant) return out;
            // a probe: nothing converged yet, the shift sees a cluster from afar (the caller
            // moves it to the dominant Ritz value's estimate)
            if (probe > 0 && out.steps >= probe && out.converged == 0) return out;
            if (goal > 0.0 && out.converged >= 1 &&
                1.0 / (std::abs(out.theta[static_cast<std::size_t>(out.converged - 1)]) * (1.0 + 1e-6)) > goal)
                return out;
            if (m_k >= m_kmax) {
                if (out.restarts >= restarts) return out;
                if (between) between();
                restart(keep, tol);
                ++out.restarts;
                check = std::min(m_kmax, m_k + std::max(10, (m_kmax - m_k) / 2));
            } else {
                check = std::min(m_kmax, m_k + std::max(10, m_k / 2));
                if (out.converged >= 1 && costly && costly(m_k, check, out.converged)) return out;
            }
        }
    }

private:
    /// One Arnoldi step: v_{k+1} from T v_k.
    void step() {
        const int m = m_m, k = m_k;
        if (m_r == m_rcap) grow_rank_storage();
        Eigen::Map<const Eigen::MatrixXcd> a(m_v.col(k).data(), m_rows, m_r);
        Eigen::VectorXcd u0 = m_op.solve_compact(m_q.leftCols(m_r), a, m_w);
        const Eigen::VectorXcd p = orthogonalise_twice(m_q.leftCols(m_r), u0);
        const double rho = u0.norm();
        const bool grow = rho > 1e-14 * std::max(p.norm(), 1e-300);
        const int r1 = grow ? m_r + 1 : m_r;
        if (grow) m_q.col(m_r) = u0 / rho;
        const Eigen::VectorXcd& g = m_op.g();
        Eigen::MatrixXcd c(m_rows, r1);
        c.row(0).head(m_r) = p.transpose();
        c.bottomRows(m).leftCols(m_r) = m_w - g * p.transpose();
        if (grow) {
            c(0, m_r) = rho;
            c.bottomRows(m).col(m_r) = -rho * g;
        }
        m_r = r1;
        const Eigen::Index len1 = m_rows * m_r;
        Eigen::Map<Eigen::VectorXcd> x(c.data(), len1);
        // classical Gram-Schmidt twice on the coefficients
        const Eigen::VectorXcd hk = orthogonalise_twice(m_v.topLeftCorner(len1, k + 1), x);
        const double beta = x.norm();
        m_h.col(k).head(k + 1) = hk;
        m_h(k + 1, k) = beta;
        ++m_k;
        if (beta <= 1e-14 * hk.norm() || !std::isfinite(beta)) {
            m_invariant = std::isfinite(beta);
            m_h(m_k, m_k - 1) = 0.0;
        } else {
            m_v.col(m_k).head(len1) = x / beta;
            m_v.col(m_k).tail(m_v.rows() - len1).setZero();
        }
    }

    /// Ritz values of H_k and the converged prefix (written to out).
    void ritz(double tol, CompactRitz& out) const {
        const int k = m_k;
        out.theta.clear();
        out.converged = 0;
        out.rank = m_r;
        Eigen::ComplexEigenSolver<Eigen::MatrixXcd> es(Eigen::MatrixXcd(m_h.topLeftCorner(k, k)));
        if (es.info() != Eigen::Success) return;
        const Eigen::VectorXcd ev = es.eigenvalues();
        std::vector<int> order(static_cast<std::size_t>(k));
        for (int i = 0; i < k; ++i) order[static_cast<std::size_t>(i)] = i;
        std::sort(order.begin(), order.end(), [&](int x, int y) { return std::abs(ev(x)) > std::abs(ev(y)); });
        // every check follows at least one Arnoldi step: the last row of H is h_{k+1,k} e_k^T
        const double hk1 = std::abs(m_h(k, k - 1));
        bool prefix = true;
        for (int i : order) {
            const cplx th = ev(i);
            out.theta.push_back(th);
            const Eigen::VectorXcd y = es.eigenvectors().col(i);
            const double res = hk1 * std::abs(y(k - 1)) / y.norm();
            // + the couplings set to zero by locking (a bound of their share of the residual)
            prefix = prefix && std::isfinite(th.real()) && std::isfinite(th.imag()) && res + m_dropped <= tol * std::abs(th);
            if (prefix) ++out.converged;
        }
    }

    /// Krylov-Schur truncation to the `keep` Ritz values of largest |theta| (see the class).
    void restart(int keep, double tol) {
        const int k = m_k;
        Eigen::ComplexSchur<Eigen::MatrixXcd> cs(Eigen::MatrixXcd(m_h.topLeftCorner(k, k)));
        Eigen::MatrixXcd s = cs.matrixT();
        Eigen::MatrixXcd u = cs.matrixU();
        for (int t = 0; t < keep; ++t) {
            int j = t;
            for (int i = t + 1; i < k; ++i)
                if (std::abs(s(i, i)) > std::abs(s(j, j))) j = i;
            for (int i = j - 1; i >= t; --i) schur_swap(s, u, i);
        }
        Eigen::RowVectorXcd b = m_h.row(k).head(k) * u.leftCols(keep);
        // locking: a leading block of Schur vectors that is invariant to 0.01 tol
        double smallest = std::numeric_limits<double>::infinity();
        int lock = 0;
        for (int j = 0; j < keep; ++j) {
            smallest = std::min(smallest, std::abs(s(j, j)));
            if (b.head(j + 1).norm() > 1e-2 * tol * smallest) break;
            lock = j + 1;
        }
        m_dropped += b.head(lock).norm();
        b.head(lock).setZero();
        m_locked = std::max(m_locked, lock);
        const Eigen::Index len = m_rows * m_r;
        const Eigen::MatrixXcd kept = m_v.topLeftCorner(len, k) * u.leftCols(keep);
        const Eigen::VectorXcd next = m_v.col(k).head(len);
        m_v.topLeftCorner(len, keep) = kept;
        m_v.col(keep).head(len) = next;
        m_v.bottomLeftCorner(m_v.rows() - len, keep + 1).setZero();
        m_h.setZero();
        m_h.topLeftCorner(keep, keep) = s.topLeftCorner(keep, keep).triangularView<Eigen::Upper>();
        m_h.row(keep).head(keep) = b;
        m_k = keep;
        // room for the next cycle's new columns of Q
        if (m_r + (m_kmax - keep) > m_rcap) compress();
    }

    /// TOAR compression of Q (see the class).
    void compress() {
        const int nvec = m_k + 1;
        Eigen::MatrixXcd c(static_cast<Eigen::Index>(nvec) * m_rows, m_r);
        for (int i = 0; i < nvec; ++i) c.middleRows(static_cast<Eigen::Index>(i) * m_rows, m_rows) = Eigen::Map<const Eigen::MatrixXcd>(m_v.col(i).data(), m_rows, m_r);
        // JacobiSVD (compiled once, core/internal/eigen_instances.hpp): c is tall and thin, and
        // JacobiSVD reduces it by a QR to its r x r factor first (r <= basis + 2), so that QR, like
        // BDCSVD's bidiagonalisation, is most of the work
        Eigen::JacobiSVD<Eigen::MatrixXcd> svd(c, Eigen::ComputeThinV);
        const Eigen::VectorXd& sv = svd.singularValues();
        int r2 = 0;
        while (r2 < sv.size() && sv(r2) > 1e-14 * sv(0)) ++r2;
        // the exact rank is at most keep + M + 2 (see the class): values beyond are rounding
        // (they pile up over the restarts), unless they are not small (then nothing is cut)
        const int bound = m_k + m_rows + 1;
        if (r2 > bound && sv(bound) <= 1e-13 * sv(0)) r2 = bound;
        r2 = std::max(r2, 1);
        const Eigen::MatrixXcd w = svd.matrixV().leftCols(r2);
        const Eigen::MatrixXcd q2 = m_q.leftCols(m_r) * w.conjugate();
        m_q.leftCols(r2) = q2;
        for (int i = 0; i < nvec; ++i) {
            const Eigen::MatrixXcd a2 = Eigen::Map<const Eigen::MatrixXcd>(m_v.col(i).data(), m_rows, m_r) * w;
            m_v.col(i).setZero();
            Eigen::Map<Eigen::MatrixXcd>(m_v.col(i).data(), m_rows, r2) = a2;
        }
        m_r = r2;
    }

    /// More columns for Q (and rows for the coefficients): compression could not make room.
    void grow_rank_storage() {
        const Eigen::Index extra = std::max<Eigen::Index>(m_rcap / 2, 16);
        const Eigen::Index old = m_rcap;
        m_rcap += extra;
        m_q.conservativeResize(Eigen::NoChange, m_rcap);
        m_v.conservativeResize(m_rows * m_rcap, Eigen::NoChange);
        m_v.bottomRows(m_rows * (m_rcap - old)).setZero();
    }

    const StructuredShiftInvert& m_op;
    int m_m, m_n;
    Eigen::Index m_rows;
    int m_kmax;
    Eigen::Index m_rcap;
    Eigen::MatrixXcd m_q, m_v, m_h, m_w;
    int m_r = 1;
    int m_k = 0;
    int m_locked = 0;       ///< leading Schur vectors locked
    double m_dropped = 0.0; ///< sum of the norms of the couplings set to zero
    bool m_invariant = false;
};

/// Factorises op at sigma, nudged off an exactly singular shift (at most 4 times by
/// 1e-7 max(1, |sigma|), along the real axis for a real shift); false when it stays singular.
bool factor_near(StructuredShiftInvert& op, cplx& sigma) {
    const double nudge = 1e-7 * std::max(1.0, std::abs(sigma));
    for (int attempt = 0; attempt < 4 && !op.factor(sigma); ++attempt) sigma += cplx(nudge, sigma.imag() != 0.0 ? nudge : 0.0);
    return op.factored();
}

/// The compact Arnoldi run of one shift (op factorised at sigma): `basis` vectors at most,
/// `restarts` Krylov-Schur restarts (0: none) keeping `keep` Schur vectors.
/// A shift on an eigenvalue (a bound that is attained, as beta of a circulant system, or the
/// root lambda = 0 of a ring at a cell's centre) gives that one |theta| ~ 1/eps, and every
/// Krylov vector then carries a component eps |theta_1| along it: the other Ritz values lose that
/// much accuracy (converged duplicates 2e-10 apart). Such a run (eps |theta_1| > tol |theta_2| /
/// 100: more than a hundredth of the convergence test) is made again a tenth of the distance to
/// the next eigenvalue away (along the real axis for a real shift); `sigma` is set to the shift
/// used, and false is returned when op could not be factorised there.
bool compact_arnoldi(StructuredShiftInvert& op, cplx& sigma, int nev, int first_check, int basis, int restarts, int keep, double tol,
                     double goal, int probe, const std::function<void()>& between, const std::function<bool(int, int, int)>& costly,
                     CompactRitz& out) {
    out = CompactKrylov(op, basis).run(nev, first_check, restarts, keep, tol, goal, probe, between, costly);
    const auto& th = out.theta;
    const double eps = std::numeric_limits<double>::epsilon();
    if (th.size() < 2 || !(eps * std::abs(th[0]) > 0.01 * tol * std::abs(th[1])) || !(std::abs(th[1]) > 0.0)) return true;
    const cplx away = -(1.0 / th[0]) / std::abs(1.0 / th[0]);
    sigma += (0.1 / std::abs(th[1])) * (sigma.imag() == 0.0 ? cplx(away.real() < 0.0 ? -1.0 : 1.0, 0.0) : away);
    const int steps = out.steps;
    if (!op.factor(sigma)) {
        out = CompactRitz{};
        out.steps = steps;
        return false;
    }
    out = CompactKrylov(op, basis).run(nev, first_check, restarts, keep, tol, goal, probe, between, costly);
    out.steps += steps;
    return true;
}

}  // namespace

SparseEigenResult sparse_collocation_eigenvalues(const LinearDDE& input, int degree, const std::vector<cplx>& shifts, int nev,
                                                 const SparseEigenOptions& options) {
    const LinearDDE dde = input.to_sparse();
    if (dde.is_ode()) throw std::invalid_argument("the sparse path needs at least one delay");
    if (degree < 2) throw std::invalid_argument("collocation degree must be >= 2");
    if (options.arnoldi != "spectra" && options.arnoldi != "compact")
        throw std::invalid_argument("arnoldi = '" + options.arnoldi + "': expected spectra or compact");
    StructuredShiftInvert op(dde, degree);
    const Eigen::Index size = op.rows();
    if (nev < 1 || nev > size - 3) throw std::invalid_argument("nev: expected 1 <= nev <= size - 3");
    if (options.arnoldi == "compact" && (options.basis <= nev || options.basis >= size || options.restarts < 0))
        throw std::invalid_argument("compact Arnoldi: expected nev < basis < (M+1) n and restarts >= 0");
    if (!(options.tolerance > 0.0)) throw std::invalid_argument("tolerance: expected > 0");
    SparseEigenResult out;
    for (cplx sigma : shifts) {
        Eigen::VectorXcd ev;
        if (options.arnoldi == "compact") {
            if (!factor_near(op, sigma)) {
                out.status = Status::NumericalIssue;
                continue;
            }
            CompactRitz rz;
            if (!compact_arnoldi(op, sigma, nev, std::min(options.basis, 2 * nev + 20), options.basis, options.restarts,
                                 std::max(nev, options.basis / 2), options.tolerance, 0.0, 0, {}, {}, rz)) {
                out.status = Status::NumericalIssue;
                continue;
            }
            out.restarts += rz.restarts;
            if (rz.converged < nev) out.status = Status::NumericalIssue;
            ev.resize(rz.converged);
            for (int i = 0; i < rz.converged; ++i) ev(i) = sigma + 1.0 / rz.theta[static_cast<std::size_t>(i)];
        } else {
            const Eigen::Index ncv = std::min<Eigen::Index>(size, std::max<Eigen::Index>(2 * nev + 1, 20));
            Spectra::GenEigsComplexShiftSolver<StructuredShiftInvert> solver(op, nev, ncv, sigma.real(), sigma.imag());
            solver.init();
            solver.compute(Spectra::SortRule::LargestMagn, 1000, options.tolerance);
            if (solver.info() != Spectra::CompInfo::Successful) out.status = Status::NumericalIssue;
            ev = solver.eigenvalues();
        }
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


namespace {

using detail::scale_of;  // max(1, |z|), internal/backends.hpp
using Bounds = RootBounds;

}  // namespace

namespace {

using detail::Disc;

/// A rectangle of the covering and what was tried on it.
struct Cell : detail::Rect {
    bool shifted = false;
    int splits = 0;  ///< splits since a shift was last tried (a root on a corner stops the halving)
    int halvings = 0;  ///< splits instead of a resolvent test (an expensive LU, a Gershgorin root-free centre)
};

/// Root-free cells by the Gershgorin theorem for Delta(z) (nonlinear in z): Delta(z) is
/// nonsingular when D^{-1} Delta(z) D is strictly diagonally dominant by rows for a positive
/// diagonal D. Over a cell (centre z_c, half-diagonal h, left edge x0) with
///     diag_i = |Delta_ii(z_c)| - h (1 + q_ii),
///     W_ij = min(|Delta_ij(z_c)| + h q_ij, |A0_ij| + sum_k |A_k,ij| e^{-x0 tau_k})   (j != i),
///     q_ij = sum_k |A_k,ij| tau_k e^{-x0 tau_k}  (a Lipschitz bound of Delta_ij over the cell),
/// no root lies in the cell if (W d)_i < diag_i d_i for every row; d is the Perron vector of
/// diag^{-1} W (power iteration), the best scaling when one exists.
class Gershgorin {
public:
    explicit Gershgorin(const LinearDDE& dde) : m_n(dde.dimension()), m_p(union_pattern(dde)) {
        auto aligned = [&](const SpD& m) {
            SpD a = m + 0.0 * m_p;
            a.makeCompressed();
            return std::vector<double>(a.valuePtr(), a.valuePtr() + a.nonZeros());
        };
        m_a0 = aligned(dde.sparse_a0());
        for (const auto& t : dde.sparse_delayed()) {
            m_ak.push_back(aligned(t.matrix));
            m_tau.push_back(t.delay);
        }
    }

    /// True when no root of Delta lies in [x0, x1] x [y0, y1] (h = 0: the single point).
    bool excludes(double x0, double x1, double y0, double y1) const {
        const cplx zc(0.5 * (x0 + x1), 0.5 * (y0 + y1));
        const double h = 0.5 * std::hypot(x1 - x0, y1 - y0);
        const std::size_t nk = m_tau.size();
        std::vector<cplx> e(nk);
        std::vector<double> elo(nk);
        for (std::size_t k = 0; k < nk; ++k) {
            e[k] = std::exp(-zc * m_tau[k]);
            elo[k] = std::exp(-x0 * m_tau[k]);
        }
        const Eigen::Index nnz = m_p.nonZeros();
        std::vector<double> w(nnz, 0.0);
        Eigen::VectorXd diag(m_n);
        const int* outer = m_p.outerIndexPtr();
        const int* inner = m_p.innerIndexPtr();
        for (int j = 0; j < m_n; ++j) {
            for (int p = outer[j]; p < outer[j + 1]; ++p) {
                const int i = inner[p];
                cplx v = -m_a0[p];
                double q = 0.0, global = std::abs(m_a0[p]);
                for (std::size_t k = 0; k < nk; ++k) {
                    const double a = m_ak[k][p];
                    if (a == 0.0) continue;
                    v -= a * e[k];
                    q += std::abs(a) * m_tau[k] * elo[k];
                    global += std::abs(a) * elo[k];
                }
                if (i == j) {
                    diag(i) = std::abs(v + zc) - h * (1.0 + q);
                } else {
                    w[p] = std::min(std::abs(v) + h * q, global);
                }
            }
        }
        if (diag.minCoeff() <= 0.0) return false;
        auto times_w = [&](const Eigen::VectorXd& d) {
            Eigen::VectorXd t = Eigen::VectorXd::Zero(m_n);
            for (int j = 0; j < m_n; ++j)
                for (int p = outer[j]; p < outer[j + 1]; ++p) t(inner[p]) += w[p] * d(j);
            return t;
        };
        Eigen::VectorXd d = Eigen::VectorXd::Ones(m_n);
        for (int it = 0; it < 60; ++it) {
            const Eigen::VectorXd t = times_w(d);
            const Eigen::ArrayXd ratio = t.array() / (diag.array() * d.array());
            if ((ratio < 1.0 - 1e-12).all()) return true;
            // Collatz-Wielandt: rho(diag^{-1} W) >= min_i ratio_i, and no scaling d makes the
            // rows dominant once rho >= 1
            if ((ratio >= 1.0).all()) return false;  // (a NaN ratio is not >= 1: no early claim)
            d = (t.array() / diag.array()).matrix() + d;  // Perron vector of diag^{-1} W (shifted by I)
            d /= d.maxCoeff();
            if (d.minCoeff() <= 0.0 || !d.allFinite()) return false;
        }
        return false;
    }

    /// The work of a cell test in flops, roughly (60 Perron iterations over the pattern, and
    /// the assembly; more with many delays), for the covering's cost model.
    double work() const { return 62.0 * 4.0 * static_cast<double>(m_p.nonZeros()) + 4.0 * m_n; }

private:
    int m_n;
    SpD m_p;
    std::vector<double> m_a0;
    std::vector<std::vector<double>> m_ak;
    std::vector<double> m_tau;
};


/// The covering's cost model, in flops (a complex multiply-add is 8), of one sparse LU and of
/// one solve with it: UMFPACK's flop count F and the nonzeros Z of L and U, n rows,
///     LU  F + 1000 n   (UMFPACK's cost per row besides flops: 2.2 ms at n = 10^4, F = 1.4e5),
///     solve  8 Z + 100 n.
double lu_work(double flops, double n) { return flops + 1000.0 * n; }
double solve_work(double nonzeros, double n) { return 8.0 * nonzeros + 100.0 * n; }

/// Root-free discs of the DDE itself from the resolvent norm, two bounds; the disc is that of
/// the larger radius. With h = z - z_c, E_k = e^{-z_c tau_k}, Delta = Delta(z_c), s = sigma_min(Delta):
///  1. sigma_min(Delta(z)) >= s - r L,   L = 1 + sum_k tau_k ||A_k|| e^{-x0 tau_k}     (L >= ||Delta'||),
///     sigma_min(Delta(z)) >= s - r L1 - r^2 M2 / 2,   L1 >= ||Delta'(z_c)||,  M2 = sum_k tau_k^2 ||A_k|| e^{-x0 tau_k} (>= ||Delta''||),
///     so Delta(z) is nonsingular in the disc |h| < r right of x0 for the larger radius of s / L and
///     2 s / (L1 + sqrt(L1^2 + 2 M2 s)). The second is the larger near z_c when the delayed terms
///     of Delta' = I + sum_k tau_k A_k e^{-z tau_k} partly cancel (L1 is the bound
///     sqrt(||.||_1 ||.||_inf) of that matrix at z_c).
///  2. Delta(z) = Delta [I + Delta^{-1} (h Delta'(z_c) - sum_k E_k rho(h tau_k) A_k)], rho(w) = e^{-w} - 1 + w,
///     |rho(w)| <= g(|w|) = e^{|w|} - 1 - |w|, so Delta(z) is nonsingular in the whole disc |h| < r when
///         r a + sum_k |E_k| g(r tau_k) ||A_k|| / s <= 1,   a = ||Delta^{-1} Delta'(z_c)||.
///     a <= ||Delta^{-1}|| ||Delta'(z_c)|| <= L1 / s, and much less when Delta'(z_c) is
///     small along Delta's near-null directions (a non-normal Delta: a random network).
/// The norms ||Delta^{-1}|| = 1 / s and a are estimated by Lanczos on Delta^{-H} Delta^{-1} and
/// Delta'^H Delta^{-H} Delta^{-1} Delta' (one sparse LU of Delta(z_c), two solves per step,
/// reorthogonalised) until the estimate changes by less than 1e-4 over a step, and taken 25%
/// larger (Lanczos approaches them from below). Independent of the collocation degree.
class ResolventExclusion {
public:
    explicit ResolventExclusion(const LinearDDE& dde) : m_dde(dde), m_n(dde.dimension()) {
        m_pattern = union_pattern(dde).cast<cplx>();
        m_pattern.makeCompressed();
        no_refinement(m_lu);
        m_lu.analyzePattern(m_pattern);
        for (const auto& t : dde.bounds().terms) m_terms.push_back({t.norm, t.delay});
    }

    /// The radius of a root-free disc around z_c (right of x0), 0 when Delta(z_c) is singular.
    /// With a finite `need` (the covering's cell), bound 2 is tried only when bound 1 falls short
    /// of it and the LU costs more than another Lanczos run; without, both bounds always.
    double free_radius(cplx zc, double x0, double need = std::numeric_limits<double>::infinity()) {
        ++m_tests;
        m_d = m_dde.sparse_characteristic_matrix(zc) + cplx(0.0) * m_pattern;
        m_d.makeCompressed();
        m_lu.factorize_counted(m_d);
        if (m_lu.info() != Eigen::Success) return 0.0;
        int steps = 0;
        const double inverse2 = top_eigenvalue(nullptr, m_previous, steps);  // ||Delta^{-1}||^2
        if (!(inverse2 > 0.0)) return 0.0;
        m_steps += steps;
        ++m_settled;
        const SpC derivative = m_dde.sparse_characteristic_derivative(zc);
        const double smin = 1.0 / (1.25 * std::sqrt(inverse2));
        double lipschitz = 1.0, second = 0.0;
        for (const auto& [norm, delay] : m_terms) {
            lipschitz += delay * norm * std::exp(-x0 * delay);
            second += delay * delay * norm * std::exp(-x0 * delay);
        }
        const double local = std::min(lipschitz, norm2_bound(derivative));
        const double first = std::max(smin / lipschitz, 2.0 * smin / (local + std::sqrt(local * local + 2.0 * second * smin)));
        // bound 2 costs another Lanczos run, about as long as the first: tried only when the
        // first did not reach `need` and the LU costs at least as much as that run (the
        // covering's cost model), so that a test it saves is worth more than it costs (a random
        // network's filled LU; not a ring's or a grid's)
        if (std::isfinite(need) &&
            (first >= need || lu_work(m_lu.flops(), m_n) < steps * 2.0 * solve_work(m_lu.nonzeros(), m_n)))
            return first;
        // bound 2: the largest r with f(r) = r a + sum_k |E_k| g(r tau_k) ||A_k|| / s <= 1 (f is
        // increasing and f(1 / a) >= 1: bisection keeps the side where f <= 1)
        steps = 0;
        const double a2 = top_eigenvalue(&derivative, m_previous_derivative, steps);  // ||Delta^{-1} Delta'||^2
        if (!(a2 > 0.0)) return first;
        m_steps += steps;
        const double a = 1.25 * std::sqrt(a2);
        auto f = [&](double r) {
            double v = r * a;
            for (const auto& [norm, delay] : m_terms) {
                const double w = r * delay;
                v += std::exp(-zc.real() * delay) * (std::expm1(w) - w) * norm / smin;
            }
            return v;
        };
        double lo = 0.0, hi = 1.0 / a;
        for (int it = 0; it < 60 && hi - lo > 1e-14 * hi; ++it) {
            const double mid = 0.5 * (lo + hi);
            (f(mid) <= 1.0 ? lo : hi) = mid;
        }
        return std::max(first, lo);
    }
    int tests() const { return m_tests; }
    /// Lanczos steps (two sparse solves each) over the tests whose first estimate settled, bound
    /// 2's runs included, and the number of those tests
    long steps() const { return m_steps; }
    int settled() const { return m_settled; }

private:
    /// The largest eigenvalue of B^H B, B = Delta^{-1} P (P = I when null) with the LU at hand, by
    /// Lanczos from `previous` (the last test's leading vector, at a nearby point nearly the
    /// same) plus as much of a random vector, so that the start misses no direction more than a
    /// random start would; settled when it changes by less than 1e-4 over a step (6 steps at
    /// least). 0 when not settled in 40 steps or a solve fails. Adds the steps to `steps`.
    double top_eigenvalue(const SpC* p, Eigen::VectorXcd& previous, int& steps) {
        const int kmax = std::min(m_n, 40);
        std::mt19937 rng(977);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        Eigen::MatrixXcd basis(m_n, kmax + 1);
        Eigen::VectorXcd x(m_n);
        for (int i = 0; i < m_n; ++i) x(i) = cplx(u(rng), u(rng));
        if (previous.size() == m_n) x = previous + x / x.norm();
        basis.col(0) = x / x.norm();
        Eigen::MatrixXd t = Eigen::MatrixXd::Zero(kmax + 1, kmax + 1);
        double estimate = 0.0;
        int used = 0;
        for (int k = 0; k < kmax; ++k) {
            used = k + 1;
            const Eigen::VectorXcd y = p ? Eigen::VectorXcd(m_lu.solve(Eigen::VectorXcd(*p * basis.col(k))))
                                         : Eigen::VectorXcd(m_lu.solve(basis.col(k)));
            Eigen::VectorXcd w;
            if (!m_lu.adjoint_solve(y, w) || !w.allFinite()) return 0.0;  // w = Delta^{-H} Delta^{-1} P q_k
            if (p) w = p->adjoint() * w;
            // against the whole basis twice while that costs less than the step's two solves
            // (about 3 n (k + 1) against 2 nnz(L + U) multiply-adds), then only against q_k and
            // q_{k-1} (local reorthogonalisation: the top Ritz value converges first, before
            // orthogonality to older vectors is lost, and no Ritz value exceeds the top eigenvalue
            // by more than rounding, Paige 1980)
            const bool full = 3.0 * m_n * (k + 1.0) <= 2.0 * m_lu.nonzeros();
            const int from = full ? 0 : std::max(0, k - 1);
            t(k, k) = orthogonalise_twice(basis.middleCols(from, k + 1 - from), w)(k - from).real();
            const double beta = w.norm();
            t(k + 1, k) = t(k, k + 1) = beta;
            Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(t.topLeftCorner(k + 1, k + 1)), Eigen::EigenvaluesOnly);
            const double next = es.eigenvalues().maxCoeff();
            const bool settled = k > 4 && std::abs(next - estimate) <= 1e-4 * next;
            estimate = next;
            if (settled || beta <= 1e-13 * next) break;
            if (k + 1 == kmax) return 0.0;  // not settled: no claim
            basis.col(k + 1) = w / beta;
        }
        if (!(estimate > 0.0) || !std::isfinite(estimate)) return 0.0;
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(t.topLeftCorner(used, used)));
        Eigen::Index top;
        es.eigenvalues().maxCoeff(&top);
        previous = basis.leftCols(used) * es.eigenvectors().col(top).cast<cplx>();
        previous /= previous.norm();
        steps += used;
        return estimate;
    }

    const LinearDDE& m_dde;
    int m_n;
    SpC m_pattern, m_d;
    UmfLU m_lu;
    std::vector<std::pair<double, double>> m_terms;
    int m_tests = 0;
    int m_settled = 0;
    long m_steps = 0;
    Eigen::VectorXcd m_previous;  ///< the last test's leading Lanczos vector (a start for the next)
    Eigen::VectorXcd m_previous_derivative;  ///< the same for Delta^{-1} Delta' (bound 2)
};

}  // namespace

double root_free_radius(const LinearDDE& input, cplx z, double x0) {
    const LinearDDE dde = input.to_sparse();
    if (!dde.is_real() || dde.is_ode()) throw std::invalid_argument("root_free_radius: expected a real DDE with at least one delay");
    if (!std::isfinite(z.real()) || !std::isfinite(z.imag()) || !std::isfinite(x0))
        throw std::invalid_argument("root_free_radius: expected a finite point and x0");
    ResolventExclusion test(dde);
    return test.free_radius(z, x0);
}

namespace {

/// The covering: discs of completeness around the shifts, root-free Gershgorin cells, and
/// the distinct eigenvalues met.
class Covering {
public:
    /// `resolvent` (may be null: the reference covering) adds root-free discs of the DDE itself.
    Covering(StructuredShiftInvert& op, const Gershgorin& gersh, const ShiftInvertRootOptions& o, ResolventExclusion* resolvent)
        : m_op(op), m_gersh(gersh), m_o(o), m_res(resolvent) {}

    /// Reports every shift to `progress` (may be empty), counting `before` shifts of earlier degrees.
    void report_to(const BranchProgress& progress, long before) {
        m_progress = &progress;
        m_before = before;
    }

    /// Runs one shift (nudged off a singular point); false after max_shifts.
    /// With restarts, the run stops as soon as its disc has radius `goal` (the cell's reach).
    /// `probe` > 0 (compact): a run with nothing converged after that many steps stops, and
    /// hint() is then the estimate sigma + 1/theta_1 of the eigenvalue it saw best.
    bool shift_at(cplx sigma, double goal, int probe = 0) {
        m_hint.reset();
        const cplx requested = sigma;  // (factor_near may nudge sigma)
        if (m_shifts >= m_o.max_shifts) return false;
        // the shifts finished so far; may throw Cancelled (caught by rightmost_roots)
        if (m_progress && *m_progress) (*m_progress)(m_before + m_shifts, m_o.max_shifts, sigma.real());
        ++m_shifts;
        factor_near(m_op, sigma);
        const Eigen::Index size = m_op.rows();
        const int nev = static_cast<int>(std::min<Eigen::Index>(m_o.eigenvalues_per_shift, size - 3));
        const Eigen::Index ncv = std::min<Eigen::Index>(size, 5 * nev / 2 + 20);
        if (m_o.arnoldi == "compact") {
            if (!m_op.factored()) {
                ++m_failed;
                return true;  // no disc: the cell is split and tried again
            }
            // every converged Ritz value from the largest |theta| on is an eigenvalue 1/theta + sigma;
            // together they are the eigenvalues in the disc |z - sigma| < 1/|theta_last|
            const int kmax = static_cast<int>(std::min<Eigen::Index>(size - 1, std::max<Eigen::Index>(ncv, m_o.compact_max_steps)));
            // restarted: the half of the basis with the largest |theta| is kept (at least nev)
            const int keep = std::min(kmax - 1, std::max(nev, kmax / 2));
            CompactRitz rz;
            // with resolvent tests at hand, a run whose disc holds `count` eigenvalues stops where
            // its steps up to the next check would cost more than five tests: the cells the
            // larger disc would still reach are then tested (or shifted at) on their own. Five,
            // measured on the bench files (BENCHMARKS.md): with 2 to 4 the 5,000-car ring took
            // 113 shifts instead of 90 (its band of roots along the floor is covered by Arnoldi
            // discs, not by tests), with 8 the 3-delay 1-D problem at 10^4 states 201 LUs instead
            // of 108; the 1-D and 2-D problems gain 2-7 fold from 2 to 8 alike. Fewer than
            // `count` in the disc: no stop (a CCC ring's strip then widened to 5,000 shifts).
            std::function<bool(int, int, int)> costly;
            if (m_res && m_o.compact_restarts == 0)
                costly = [this](int k, int next, int converged) {
                    if (converged < m_count) return false;
                    double work = 0.0;
                    for (int j = k + 1; j <= next; ++j) work += step_work(j);
                    return work > 5.0 * test_work();
                };
            const bool factored = compact_arnoldi(m_op, sigma, nev, static_cast<int>(std::min<Eigen::Index>(ncv, kmax)), kmax,
                                                  m_o.compact_restarts, keep, m_o.arnoldi_tolerance,
                                                  m_o.compact_restarts > 0 ? goal : 0.0, probe, [&] {
                                                      // a long run reports again (same count) after each step
                                                      if (m_progress && *m_progress)
                                                          (*m_progress)(m_before + m_shifts - 1, m_o.max_shifts, sigma.real());
                                                  }, costly, rz);
            m_steps += rz.steps;
            if (!factored) {
                ++m_failed;
                return true;
            }
            m_restarts += rz.restarts;
            m_max_rank = std::max(m_max_rank, rz.max_rank);
            double thmin = std::numeric_limits<double>::infinity();
            for (int i = 0; i < rz.converged; ++i) {
                const cplx th = rz.theta[static_cast<std::size_t>(i)];
                add(sigma + 1.0 / th, sigma);
                thmin = std::min(thmin, std::abs(th));
            }
            if (rz.converged < 1 || !(thmin > 0.0)) {
                ++m_failed;
                m_failed_at.push_back({requested, probe});
                if (!rz.theta.empty() && std::abs(rz.theta.front()) > 0.0) {
                    const cplx z = sigma + 1.0 / rz.theta.front();
                    if (std::isfinite(z.real()) && std::isfinite(z.imag())) m_hint = z.imag() < 0.0 ? std::conj(z) : z;
                }
                return true;
            }
            m_discs.push_back({sigma, 1.0 / (thmin * (1.0 + 1e-6))});  // margin for the Ritz values' own error
            return true;
        }
        Spectra::GenEigsComplexShiftSolver<StructuredShiftInvert> solver(m_op, nev, ncv, sigma.real(), sigma.imag());
        solver.init();
        solver.compute(Spectra::SortRule::LargestMagn, m_o.arnoldi_max_restarts, m_o.arnoldi_tolerance);
        const Eigen::VectorXcd ev = solver.eigenvalues();
        double numin = std::numeric_limits<double>::infinity();
        for (Eigen::Index i = 0; i < ev.size(); ++i) {
            const cplx z = ev(i);
            if (!std::isfinite(z.real()) || !std::isfinite(z.imag())) continue;
            add(z, sigma);
            const cplx nu = 0.5 * (1.0 / (z - sigma) + 1.0 / (z - std::conj(sigma)));
            numin = std::min(numin, std::abs(nu));
        }
        if (solver.info() != Spectra::CompInfo::Successful || ev.size() < nev || !std::isfinite(numin)) {
            ++m_failed;
            return true;  // no disc: the cell is split and tried again
        }
        numin *= 1.0 + 1e-6;  // margin for the Ritz values' own error
        const double b = std::abs(sigma.imag());
        double rho;
        if (b == 0.0) {
            rho = 1.0 / numin;
        } else {
            // smaller root of c rho^2 - 2 (c b + 1) rho + 2 b = 0, c = 2 nu_min, in stable form
            const double c = 2.0 * numin, p = c * b + 1.0;
            rho = 2.0 * b / (p + std::sqrt(p * p - 2.0 * c * b));
        }
        m_discs.push_back({sigma, rho});
        return true;
    }

    /// Shifts at sigma for the cell c. A run that converges nothing (a cluster seen from afar:
    /// its eigenvalues have nearly equal |1/(lambda - sigma)|, and Arnoldi does not separate
    /// them) is moved to the eigenvalue it saw best, where the cluster's members are far apart
    /// in 1/(lambda - sigma), at most twice, when that estimate lies in the cell's reach (inside
    /// the rectangle, and not in a disc already). `probe`: each run stops after that many
    /// steps when nothing has converged.
    /// False when the shift budget ran out.
    bool shift_near(cplx sigma, const Cell& c, double beta, int probe = 0) {
        const double far = reach(c, sigma);
        for (int hop = 0;; ++hop) {
            if (!shift_at(sigma, reach(c, sigma), probe)) return false;
            if (hop == 2 || !m_hint) return true;
            const cplx next = *m_hint;
            if (next.real() < m_floor || next.real() > beta || next.imag() > m_height || std::abs(next - sigma) > far) return true;
            for (const auto& d : m_discs)
                if (!d.root_free && std::abs(next - d.centre) < d.radius) return true;
            // not onto the estimate itself: a shift within rounding of an eigenvalue makes
            // the operator's other directions inaccurate (its LU is nearly singular)
            sigma = next + 0.05 * (sigma - next);
        }
    }

    /// Covers [floor, beta] x [0, H(floor)], floor starting at alpha and raised, as eigenvalues
    /// are found, to the count-th rightmost one met (cells left of it are no longer needed).
    /// Cells are taken rightmost first. The first shift is a probe on the real axis just right of beta,
    /// moved to the eigenvalues nearest it (shift_near): the rightmost ones found first raise
    /// the floor before the rectangle is split. False when the shift budget ran out.
    bool cover(double alpha, double beta, const Bounds& bounds, int count) {
        m_floor = alpha;
        m_count = std::max(1, count);
        const double height = bounds.height(alpha);
        m_height = std::min(m_height, height);
        if (m_discs.empty()) {
            const Cell all{{alpha, beta, 0.0, height}};
            // a little right of beta: the bound can be attained (a circulant system's rightmost root)
            const cplx seed(beta + 0.05 * (beta - alpha), 0.0);
            if (!shift_near(seed, all, beta, m_o.arnoldi == "compact" ? std::max(20, m_o.compact_max_steps / 4) : 0)) return false;
            raise_floor(bounds, count);
        }
        auto later = [](const Cell& a, const Cell& b) { return a.x1 != b.x1 ? a.x1 < b.x1 : a.y0 > b.y0; };
        std::priority_queue<Cell, std::vector<Cell>, decltype(later)> queue(later);
        // roughly square cells to start with
        const double w = beta - alpha;
        const int cap = m_res ? 64 : std::numeric_limits<int>::max();  // cells are split as needed anyway
        // (clamped in double before the conversion: the ratio of the sides is not bounded)
        const double dcap = static_cast<double>(cap);
        const int nx = static_cast<int>(std::clamp(std::ceil(w / std::max(height, 1e-300)), 1.0, dcap));
        const int ny = static_cast<int>(std::clamp(std::ceil(height / std::max(w, 1e-300)), 1.0, dcap));
        for (int i = 0; i < nx; ++i)
            for (int j = 0; j < ny; ++j)
                queue.push(Cell{{alpha + w * i / nx, alpha + w * (i + 1) / nx, height * j / ny, height * (j + 1) / ny}});
        while (!queue.empty()) {
            Cell c = queue.top();
            queue.pop();
            if (c.x1 < m_floor || c.y0 > m_height) continue;
            c.x0 = std::max(c.x0, m_floor);
            c.y1 = std::min(c.y1, m_height);
            if (const auto left = uncovered(c)) {
                c = *left;  // the rest lies in discs
            } else {
                continue;
            }
            if (bounds.excludes(c.x0, c.y0) || m_gersh.excludes(c.x0, c.x1, c.y0, c.y1)) {
                ++m_excluded;
                continue;
            }
            const double cw = c.x1 - c.x0, ch = c.y1 - c.y0;
            if (std::max(cw, ch) <= 1e-13 * scale_of(cplx(c.x1, c.y1))) return false;
            const double mx = 0.5 * (c.x0 + c.x1), my = 0.5 * (c.y0 + c.y1);
            const cplx centre(mx, c.y0 == 0.0 ? 0.0 : my);
            // where even the centre is root-free (Gershgorin), smaller cells will be too (asked
            // once, when needed)
            std::optional<bool> free_centre;
            auto empty_centre = [&] {
                if (!free_centre) free_centre = m_gersh.excludes(mx, mx, my, my) && std::max(cw, ch) > 1e-3 * scale_of(centre);
                return *free_centre;
            };
            auto split = [&queue](const Cell& whole, int splits, int halvings) {
                Cell a = whole, b = whole;
                a.shifted = b.shifted = false;
                a.splits = b.splits = splits;
                a.halvings = b.halvings = halvings;
                if (whole.x1 - whole.x0 >= whole.y1 - whole.y0) {
                    a.x1 = b.x0 = 0.5 * (whole.x0 + whole.x1);
                } else {
                    a.y1 = b.y0 = 0.5 * (whole.y0 + whole.y1);
                }
                queue.push(a);
                queue.push(b);
            };
            // where a resolvent test's LU costs a hundred Gershgorin tests (heavy fill: a random
            // network) and the centre is root-free by Gershgorin, the halves, then the quarters
            // and eighths, are tried by Gershgorin first
            if (m_res && !c.shifted && c.halvings < 3 && test_work() > 100.0 * m_gersh.work() && empty_centre()) {
                split(c, c.splits, c.halvings + 1);
                continue;
            }
            bool near_root = true;
            if (m_res && !c.shifted) {
                // a root-free disc of the DDE around the cell's centre, valid right of x0: the
                // cell lies right of both the floor and mx - h, and the Lipschitz bound of Delta
                // is the smaller the farther right it holds
                const double h = 0.5 * std::hypot(cw, ch);
                const double x0 = std::max(m_floor, mx - h);
                // a test costs an LU of Delta: it reports (the shifts done so far) and may be cancelled
                if (m_progress && *m_progress) (*m_progress)(m_before + m_shifts, m_o.max_shifts, mx);
                const double r = m_res->free_radius(cplx(mx, my), x0, h);
                if (r >= h) {
                    ++m_excluded;
                    continue;
                }
                if (r > 0.0) m_discs.push_back({cplx(mx, my), r, true, x0});
                // otherwise split (twice at most before a shift) unless the disc is much smaller
                // than the cell (a root near its centre): the halves may be root-free
                near_root = r < 0.25 * h || c.splits >= 2;
            }
            // a root-free centre: split instead of a (slow) shift far from the spectrum
            if (!c.shifted && near_root && !empty_centre()) {
                bool again = false;
                for (const auto& d : m_discs) again = again || (!d.root_free && d.centre == centre);
                // a cell's shift gives up when nothing converged (a cluster seen from afar, or
                // eigenvalues outside the cell's reach) once it cost as much as two resolvent
                // tests: it is moved or the cell split, and the halves' tests are cheaper than
                // the rest of such a run. Not again where a run converged nothing in as many
                // steps as this one may take (0: the whole basis): it would again (same operator,
                // same start).
                const int probe = m_o.arnoldi == "compact" ? probe_steps() : 0;
                for (const auto& [at, steps] : m_failed_at)
                    again = again || (at == centre && (steps == 0 || (probe > 0 && steps >= probe)));
                if (!again) {
                    if (!shift_near(centre, c, beta, probe)) return false;
                    raise_floor(bounds, count);
                }
                c.shifted = true;
                if (const auto left = uncovered(c)) {
                    c = *left;
                } else {
                    continue;
                }
            }
            split(c, c.shifted ? 0 : c.splits + 1, c.halvings);
        }
        return true;
    }

    /// The final floor: every eigenvalue with Re >= floor (and |Im| <= R(floor)) was found.
    double floor() const { return m_floor; }

    /// Distinct eigenvalues with Im >= 0 (real problem: conjugates implied).
    const std::vector<cplx>& values() const { return m_values; }
    int shifts() const { return m_shifts; }
    int steps() const { return m_steps; }
    /// max |z| over the cells covered by Arnoldi discs (the part that relies on the collocation)
    double extent() const { return m_extent; }
    int failed() const { return m_failed; }
    int excluded() const { return m_excluded; }
    /// compact: Krylov-Schur restarts over all shifts, and the largest rank of Q met
    int restarts() const { return m_restarts; }
    int max_rank() const { return m_max_rank; }

private:
    /// The steps a cell's probe may take before it gives up: the most, in [20, basis / 2], whose
    /// work is at most that of two resolvent tests (the halves of a split cell). Work in flops
    /// (a complex multiply-add is 8), from the last shift's LU (UMFPACK's flop count F, nonzeros
    /// Z of L and U; the pattern is the same at every shift), the dimension n, degree M, K
    /// delays, and S, the Lanczos steps per settled test so far (25 before any):
    ///     LU     F + 1000 n        (UMFPACK's cost per row besides flops: 2.2 ms at n = 10^4, F = 1.4e5)
    ///     solve  8 Z + 100 n
    ///     test   LU + S (2 solve + 12 n S)      (reorthogonalised in full: 3 passes over S/2 vectors)
    ///     probe  LU + sum_{j <= P} (solve + 8 (4 + K) n j + 24 (M + 1) j^2)
    /// (after j steps Q has about j columns, read 1 + K times in the solve and 3 times by CGS2,
    /// and the coefficients (M + 1) j x j are read 3 times). Where LUs are cheap and the basis
    /// costly (a ring of 10^4 states: P = 36) a probe stops early; where LUs fill in (a random
    /// network: one LU costs 100 steps) it runs to half the basis, as before this model.
    int probe_steps() const {
        const double test = test_work();
        const int cap = std::max(20, m_o.compact_max_steps / 2);
        double work = 0.0;  // the LU is paid whether the run goes on or not
        int p = 0;
        while (p < cap) {
            work += step_work(p + 1);
            if (work > 2.0 * test) break;
            ++p;
        }
        return std::max(std::min(20, cap), p);
    }
    /// The model's work of one sparse solve (see probe_steps).
    double solve_work() const { return ddemap::solve_work(m_op.lu_nonzeros(), m_op.dimension()); }
    /// The model's work of a resolvent test (see probe_steps).
    double test_work() const {
        const double n = m_op.dimension();
        const double s = m_res && m_res->settled() > 0 ? static_cast<double>(m_res->steps()) / m_res->settled() : 25.0;
        return lu_work(m_op.lu_flops(), n) + s * (2.0 * solve_work() + 12.0 * n * s);
    }
    /// The model's work of Arnoldi step j (see probe_steps).
    double step_work(int j) const {
        const double n = m_op.dimension(), m1 = m_op.degree() + 1.0, k = m_op.delays();
        return solve_work() + 8.0 * (4.0 + k) * n * j + 24.0 * m1 * double(j) * j;
    }
    /// The distance from sigma to the cell's farthest corner (a little more).
    static double reach(const Cell& c, cplx sigma) {
        double r = 0.0;
        for (double x : {c.x0, c.x1})
            for (double y : {c.y0, c.y1}) r = std::max(r, std::abs(cplx(x, y) - sigma));
        return r * (1.0 + 1e-9);
    }
    /// The part of the cell not yet covered (detail::uncovered_part, 64 pieces at most): nullopt
    /// when the union of the discs covers it, else the bounding box of the pieces left, the
    /// cell's flags kept. A piece inside an Arnoldi disc (not root-free) needs the collocation to
    /// resolve it: its farthest corner raises extent().
    std::optional<Cell> uncovered(const Cell& c) {
        const auto left = detail::uncovered_part(c, m_discs, 6, [this](const detail::Rect& p) {
            for (double x : {p.x0, p.x1})
                for (double y : {p.y0, p.y1}) m_extent = std::max(m_extent, std::abs(cplx(x, y)));
        });
        if (!left) return std::nullopt;
        Cell part = c;
        static_cast<detail::Rect&>(part) = *left;
        return part;
    }
    /// An eigenvalue z = sigma + 1/theta from a Ritz value converged to |residual| <= tol |theta|:
    /// its error is about tol |z - sigma| (|d theta| / |theta|^2, times the eigenvalue's condition),
    /// so the same eigenvalue met twice (from two shifts, or a pair's two members from one
    /// complex shift, the far one less accurate) can differ by more than rounding: on a stiff
    /// system (||A0|| = 2e7) a pair's members came out 2.9e-10 apart. Values closer than ten
    /// times their two errors are one eigenvalue.
    void add(cplx z, cplx sigma) {
        const double error = std::max(1e-10 * scale_of(z), 10.0 * m_o.arnoldi_tolerance * std::abs(z - sigma));
        if (z.imag() < 0.0) z = std::conj(z);
        if (z.imag() <= 1e-12 * scale_of(z)) z.imag(0.0);  // a real eigenvalue, not a pair
        for (std::size_t i = 0; i < m_values.size(); ++i)
            if (std::abs(m_values[i] - z) <= std::max(error, m_errors[i])) return;
        m_values.push_back(z);
        m_errors.push_back(error);
    }

    StructuredShiftInvert& m_op;
    const Gershgorin& m_gersh;
    const ShiftInvertRootOptions& m_o;
    std::vector<Disc> m_discs;
    std::vector<cplx> m_values;
    std::vector<double> m_errors;  ///< the error of each value (add)
    ResolventExclusion* m_res;
    double m_extent = 0.0;
    int m_shifts = 0;
    const BranchProgress* m_progress = nullptr;
    long m_before = 0;
    int m_steps = 0;
    int m_failed = 0;
    int m_excluded = 0;
    int m_restarts = 0;
    int m_max_rank = 0;
    double m_floor = 0.0;
    int m_count = 1;  ///< the roots asked for (cover)
    double m_height = std::numeric_limits<double>::infinity();
    std::vector<std::pair<cplx, int>> m_failed_at;  ///< shifts (as asked) whose run converged nothing, and its probe length
    std::optional<cplx> m_hint;  ///< the last probe's estimate of the eigenvalue it saw best (upper half)

    void raise_floor(const Bounds& bounds, int count) {
        std::vector<double> re;
        for (cplx z : m_values) {
            re.push_back(z.real());
            if (z.imag() > 0.0) re.push_back(z.real());
        }
        if (re.size() < std::size_t(count)) return;
        std::nth_element(re.begin(), re.begin() + (count - 1), re.end(), std::greater<double>());
        m_floor = std::max(m_floor, re[count - 1]);
        m_height = bounds.height(m_floor);
    }
};

/// Newton on [Delta(lambda) v = 0, c^H v = 1] (nonlinear inverse iteration, the one Newton loop):
///     u = Delta(lambda)^{-1} Delta'(lambda) v,  lambda <- lambda - 1 / (c^H u),  v <- u / (c^H u).
class SparseNewton {
public:
    explicit SparseNewton(const LinearDDE& dde) : m_dde(dde) {
        m_pattern = union_pattern(dde).cast<cplx>();
        m_pattern.makeCompressed();
        m_lu.analyzePattern(m_pattern);
    }

    bool refine(cplx guess, const RootOptions& o, Root& out) {
        const int n = m_dde.dimension();
        const bool real = guess.imag() == 0.0;
        std::mt19937 rng(12345);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        Eigen::VectorXcd r(n);
        for (int i = 0; i < n; ++i) r(i) = real ? cplx(u(rng), 0.0) : cplx(u(rng), u(rng));
        cplx lambda = guess;
        if (!factor(lambda)) return finish(guess, lambda, Eigen::VectorXcd(), 0.0, true, o, out);
        Eigen::VectorXcd v = m_lu.solve(r);
        if (!v.allFinite() || v.norm() == 0.0) return finish(guess, lambda, Eigen::VectorXcd(), 0.0, true, o, out);
        v /= v.norm();
        const Eigen::VectorXcd c = v;  // c^H v = 1
        bool first = true;
        const NewtonSummary s = newton(
            lambda,
            [&](const cplx& z, cplx& dz) {
                // Delta(lambda) singular: lambda is a root to working precision
                if (!first && !factor(z)) return NewtonStep::Exact;
                first = false;
                const Eigen::VectorXcd dv = m_dde.sparse_characteristic_derivative(z) * v;
                const Eigen::VectorXcd w = m_lu.solve(dv);
                const cplx chu = c.dot(w);
                if (!w.allFinite() || chu == cplx(0.0)) return NewtonStep::Exact;
                dz = 1.0 / chu;
                if (real) dz.imag(0.0);
                v = w / chu;
                return NewtonStep::Ok;
            },
            o.shift_invert.newton);
        m_iterations += s.iterations;
        const double step = s.status == Status::Converged && s.iterations == 0 ? 0.0 : s.last_step;
        return finish(guess, lambda, v, step, s.status == Status::Converged, o, out);
    }

    int factorizations() const { return m_factorizations; }
    int iterations() const { return m_iterations; }

private:
    bool factor(cplx lambda) {
        m_d = m_dde.sparse_characteristic_matrix(lambda) + cplx(0.0) * m_pattern;
        m_d.makeCompressed();
        m_lu.factorize(m_d);
        ++m_factorizations;
        return m_lu.info() == Eigen::Success;
    }
    bool finish(cplx guess, cplx lambda, const Eigen::VectorXcd& v, double step, bool converged, const RootOptions& o, Root& out) {
        out.value = lambda;
        out.eigenvalue = guess;
        out.newton_step = step;
        out.collocation_error = std::abs(lambda - guess);
        // Delta(lambda) singular to working precision: residual 0
        out.residual = v.size() > 0 && v.norm() > 0.0 ? relative_residual(m_dde, lambda, v) : 0.0;
        return (converged || step <= 1e-6 * scale_of(lambda)) && out.residual <= o.residual_tolerance &&
               std::isfinite(lambda.real()) && std::isfinite(lambda.imag());
    }

    const LinearDDE& m_dde;
    SpC m_pattern, m_d;
    Eigen::UmfPackLU<SpC> m_lu;
    int m_factorizations = 0;
    int m_iterations = 0;
};

bool rightmost_first_value(cplx a, cplx b) {
    if (a.real() != b.real()) return a.real() > b.real();
    return a.imag() > b.imag();
}

/// The eigenvalues right of alpha in full (conjugates added), rightmost first.
std::vector<cplx> with_conjugates(const std::vector<cplx>& upper, double alpha) {
    std::vector<cplx> out;
    for (cplx z : upper) {
        if (z.real() < alpha) continue;
        out.push_back(z);
        if (z.imag() > 0.0) out.push_back(std::conj(z));
    }
    std::sort(out.begin(), out.end(), rightmost_first_value);
    return out;
}

}  // namespace

namespace detail {

std::string shift_invert_why_not(const RootProblem& problem, const RootOptions& options) {
    const LinearDDE& dde = problem.dde;
    if (!dde.is_real() || dde.is_ode())
        return "method 'shift_invert': the sparse path needs real coefficients and at least one delay; expected auto or dense for this problem";
    const int m = options.degree > 0 ? options.degree : 8;
    if (static_cast<long>(m + 1) * dde.dimension() < 8)
        return "method 'shift_invert' needs (M+1) n >= 8; expected dense for n = " + std::to_string(dde.dimension());
    return {};
}

namespace {

/// The first collocation degree: the given one, or the one resolving the first strip's cells
/// (compact: those covered by Arnoldi discs, so a huge root bound of a stiff system does not set
/// it). The first strip is deep, Re >= min(0, beta) - 1 / tau.
int first_shift_invert_degree(const LinearDDE& dde, const RootOptions& options) {
    const ShiftInvertRootOptions& so = options.shift_invert;
    const double tau = dde.max_delay(), beta = dde.bounds().right_bound();
    const double first_radius = dde.bounds().radius(std::min(0.0, beta) - 1.0 / tau);
    const bool compact = so.arnoldi == "compact";
    return options.degree > 0 ? options.degree
                              : std::clamp(degree_for_radius(compact ? std::min(first_radius, std::abs(beta) + 8.0 * M_PI / tau) : first_radius, tau), 8,
                                           std::max(so.max_degree, options.degree));
}

}  // namespace

RootWorkEstimate shift_invert_estimate(const RootProblem& problem, const RootOptions& options) {
    const LinearDDE dde = problem.dde.to_sparse();
    const ShiftInvertRootOptions& so = options.shift_invert;
    const double n = dde.dimension(), m = first_shift_invert_degree(dde, options);
    UmfLU lu;
    no_refinement(lu);
    const SpC pattern = union_pattern(dde).cast<cplx>();
    lu.analyzePattern(pattern);
    // UMFPACK's symbolic estimates are upper bounds (3 times the flops and 2 times the nonzeros of
    // random systems, 30 times the flops of a 2-D grid): when they promise a small LU of under 20 s,
    // Delta is factorised once at the right bound of the roots and its true size is used (a
    // fraction of the 4 LUs per shift the search itself makes)
    // (otherwise a third of the bound's flops: the ratio on random systems, the worst for fill)
    double lu_flops = lu.flops_estimate() / 3.0, lu_nonzeros = lu.nonzeros_estimate(), lu_bytes = lu.bytes_estimate();
    bool measured = false;
    // (and at most 2e6 nonzeros: UMFPACK's time is not all flops, the ring of 10^6 cars, 1e7
    // nonzeros and 5e7 flops by the bound, took over a minute to factorise)
    if (lu.flops_estimate() / 4.5e9 < 20.0 && lu.nonzeros_estimate() <= 2e6) {
        const double beta = dde.bounds().right_bound();
        SpC d = dde.sparse_characteristic_matrix(cplx(std::isfinite(beta) ? std::max(beta, 0.0) + 0.5 : 1.0, 0.0)) + cplx(0.0) * pattern;
        d.makeCompressed();
        lu.factorize_counted(d);
        if (lu.info() == Eigen::Success && lu.nonzeros() > 0.0) {
            lu_flops = lu.flops();
            lu_bytes *= lu.nonzeros() / std::max(1.0, lu_nonzeros);
            lu_nonzeros = lu.nonzeros();
            measured = true;
        }
    }
    // one shift, as measured (BENCHMARKS.md): about 4 LU factorisations (the shift's and the
    // resolvent tests', at about 4.5e9 flops per second), 100 solves (Arnoldi and Lanczos
    // steps; 8 flops per nonzero of L and U) and 30 Arnoldi steps on the (M+1) n blocks with the
    // orthogonalisation; memory: two LUs, the compact basis (its rank stayed below 80), the blocks
    const double steps = std::min(30.0, static_cast<double>(so.compact_max_steps));
    const double per_shift = 4.0 * lu_flops / 4.5e9 + (100.0 * 8.0 * lu_nonzeros + steps * (m + 1.0) * n * 20.0 + steps * steps * n * 8.0) / 1e9;
    const double shifts = std::min(so.expected_shifts > 0.0 ? so.expected_shifts : 6.0, static_cast<double>(so.max_shifts));
    RootWorkEstimate e;
    e.units = shifts;
    e.seconds = shifts * per_shift;
    e.bytes = 2.0 * lu_bytes + 16.0 * n * (std::min(80.0, static_cast<double>(so.compact_max_steps)) + 2.0 * (m + 1.0)) + 3e7;
    std::ostringstream os;
    os.precision(3);
    os << "about " << std::ceil(shifts) << " Arnoldi shifts of " << per_shift << " s each: sparse LU of " << lu_nonzeros << " nonzeros and "
       << lu_flops << " flops (" << (measured ? "one factorised" : "a third of UMFPACK's symbolic upper bound") << "), M = " << m;
    e.basis = os.str();
    return e;
}

RootResult shift_invert_roots(const RootProblem& problem, const RootOptions& options) {
    const SingleThreadedEigen single;  // the Krylov products are too small for OpenMP's threads
    const LinearDDE dde = problem.dde.to_sparse();
    const ShiftInvertRootOptions& so = options.shift_invert;
    const int max_degree = std::max(so.max_degree, options.degree);
    const int n = dde.dimension();
    const Bounds& bounds = dde.bounds();
    const double tau = dde.max_delay();
    RootResult result;
    result.right_bound = bounds.right_bound();
    const double beta = result.right_bound;
    // a deep first strip: the floor rises as soon as `count` eigenvalues are known
    double alpha = std::min(0.0, beta) - 1.0 / tau;
    const bool compact = so.arnoldi == "compact";
    int m = first_shift_invert_degree(dde, options);
    const Gershgorin gersh(dde);
    ResolventExclusion resolvent(dde);
    int max_rank = 0;
    for (;;) {
        StructuredShiftInvert op(dde, m);
        if (op.rows() < 8)
            throw std::invalid_argument("the sparse path needs (M+1) n >= 8; use the dense path for n = " + std::to_string(n));
        Covering cover(op, gersh, so, compact ? &resolvent : nullptr);
        cover.report_to(options.progress, result.shifts);
        bool budget = true;
        std::vector<cplx> right;
        for (;;) {
            budget = cover.cover(alpha, beta, bounds, options.count);
            right = with_conjugates(cover.values(), cover.floor());
            if (!budget || right.size() >= std::size_t(options.count)) break;
            // fewer than `count` eigenvalues right of alpha: widen the strip, to the count-th
            // rightmost eigenvalue met so far when the discs reached that far left
            const std::vector<cplx> met = with_conjugates(cover.values(), -std::numeric_limits<double>::infinity());
            if (met.size() >= std::size_t(options.count) && met[options.count - 1].real() < alpha)
                alpha = met[options.count - 1].real();
            else
                alpha -= std::max(beta - alpha, 1.0 / tau);
        }
        alpha = cover.floor();
        result.shifts += cover.shifts();
        result.arnoldi_steps += cover.steps();
        result.arnoldi_restarts += cover.restarts();
        max_rank = std::max(max_rank, cover.max_rank());
        result.factorizations += op.factorizations();
        result.eigenvalues_found = static_cast<int>(cover.values().size());
        const double height = bounds.height(alpha);
        const double resolved = radius_for_degree(m, tau);
        // M must resolve every eigenvalue of the rectangle (compact: of the part covered by
        // Arnoldi discs; the rest is root-free by Gershgorin or the resolvent); otherwise raise M
        const double needed = compact ? cover.extent() : height;
        if (budget && options.degree == 0 && resolved < needed && m < max_degree) {
            m = std::min(max_degree, std::max(degree_for_radius(needed, tau), static_cast<int>(std::ceil(1.5 * m))));
            continue;
        }
        // the `count` rightmost (plus a cut-off conjugate partner)
        std::size_t keep = std::min<std::size_t>(right.size(), options.count);
        if (keep > 0 && keep < right.size() && right[keep - 1].imag() > 0.0 && right[keep] == std::conj(right[keep - 1])) ++keep;
        const bool cut = keep < right.size();
        right.resize(keep);
        result.degree = m;
        // all eigenvalues right of alpha were found; the listed ones are those right of the last kept
        result.strip_floor = cut && keep > 0 ? std::max(alpha, right.back().real()) : alpha;
        result.height = height;
        result.covered_radius = resolved;
        result.roots.clear();
        result.collocation_error = 0.0;
        int failed_newton = 0;
        if (so.refine) {
            SparseNewton newton(dde);
            for (cplx z : right) {
                if (z.imag() < 0.0) continue;
                Root r;
                if (!newton.refine(z, options, r)) ++failed_newton;
                result.roots.push_back(r);
                if (z.imag() > 0.0) {
                    Root c = r;
                    c.value = std::conj(r.value);
                    c.eigenvalue = std::conj(z);
                    result.roots.push_back(c);
                }
            }
            result.factorizations += newton.factorizations();
            result.newton_iterations += newton.iterations();
        } else {
            for (cplx z : right) {
                Root r;
                r.value = z;
                r.eigenvalue = z;
                r.newton_step = std::numeric_limits<double>::quiet_NaN();
                result.roots.push_back(r);
            }
        }
        double max_residual = 0.0;
        for (const auto& r : result.roots) {
            if (so.refine) result.collocation_error = std::max(result.collocation_error, r.collocation_error / scale_of(r.value));
            max_residual = std::max(max_residual, r.residual);
        }
        // two refined roots on one root: a duplicate, the collocation did not separate them. A
        // refined root is known to about its absolute backward error ||Delta v|| / ||v|| =
        // residual (|lambda| + R): Newton stops at that noise, which on a stiff system (||A0|| =
        // 2e7) is 1e-9, far above rounding
        auto noise = [&](const Root& x) { return x.residual * bounds.scale(x.value); };
        int duplicates = 0;
        for (std::size_t i = 0; i < result.roots.size(); ++i)
            for (std::size_t j = i + 1; j < result.roots.size(); ++j) {
                const Root &a = result.roots[i], &b = result.roots[j];
                if (std::abs(a.value - b.value) <= std::max(1e-10 * scale_of(a.value), 10.0 * (noise(a) + noise(b)))) ++duplicates;
            }
        const bool accurate = result.collocation_error <= so.collocation_tolerance;
        if (so.refine && options.degree == 0 && budget && (!accurate || duplicates > 0) && m < max_degree) {
            m = std::min(max_degree, static_cast<int>(std::ceil(1.5 * m)));
            continue;
        }
        std::stable_sort(result.roots.begin(), result.roots.end(),
                         [](const Root& a, const Root& b) { return rightmost_first_value(a.value, b.value); });
        std::ostringstream os;
        os.precision(3);
        if (!budget) {
            result.status = Status::BudgetExhausted;
            os << "the shift budget (" << so.max_shifts << ") ran out before the strip Re >= " << alpha << " was covered";
        } else if (so.refine && (failed_newton > 0 || duplicates > 0)) {
            result.status = Status::MaxDegreeReached;
            os << failed_newton << " Newton refinements failed and " << duplicates << " roots coincide at M=" << m;
        } else if (so.refine && !accurate) {
            result.status = Status::MaxDegreeReached;
            os << "max degree M=" << m << " reached with eigenvalues " << result.collocation_error << " from the roots";
        } else {
            result.status = Status::Converged;
            os << "every collocation eigenvalue (M=" << m << ") with Re >= " << alpha << " found by " << result.shifts
               << " shifts covering [" << alpha << ", " << beta << "] x [0, " << height << "] (no root lies right of " << beta
               << " or above " << height << " there)";
            if (so.refine)
                os << "; each refined by Newton (max residual " << max_residual << ", eigenvalues within "
                   << result.collocation_error << ")";
        }
        if (cover.failed() > 0) os << "; " << cover.failed() << " Arnoldi runs did not converge and were replaced by smaller cells";
        if (compact)
            os << "; compact Arnoldi (" << result.arnoldi_steps << " steps, " << result.arnoldi_restarts
               << " Krylov-Schur restarts, rank of Q <= " << max_rank << "), " << resolvent.tests()
               << " resolvent tests (root-free discs of Delta, Lanczos norm estimate x1.25, " << resolvent.steps() << " Lanczos steps)";
        result.factorizations += resolvent.tests();
        result.message = os.str();
        return result;
    }
}

}  // namespace detail

}  // namespace ddemap
