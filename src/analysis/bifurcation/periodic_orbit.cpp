#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"

#include <algorithm>
#include <complex>
#include <functional>
#include <map>
#include <memory>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
// GCC 12 reports a false -Wuse-after-free inside Spectra's Hessenberg eigenvector code
// (as in wave_stability.cpp: clang has no such warning and warns of its name)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <Spectra/GenEigsSolver.h>
#include <Spectra/MatOp/DenseGenMatProd.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "analysis/bifurcation/internal/orbit_continuation.hpp"
#include "analysis/bifurcation/internal/orbit_mesh.hpp"
#include "core/internal/eigen_threads.hpp"
#include "core/internal/text.hpp"
#include "ddemap/solve/integrate.hpp"

namespace ddemap {

namespace {

constexpr double kPi = 3.14159265358979323846;
using Triplet = Eigen::Triplet<double>;
using SpD = Eigen::SparseMatrix<double>;

/// The problem on a mesh: system, parameter index, weights of the continuation norm.
struct Setup {
    Setup(const NonlinearDDE& s, const PeriodicMesh& me) : sys(s), mesh(me) {}
    const NonlinearDDE& sys;
    const PeriodicMesh& mesh;
    int n = 0, m = 0, j = 0, d = 0, L = 0, P = 0;  // dimension, delays, parameter, degree, intervals, points
    std::vector<double> base;                       // parameter values (p_j replaced)
    Eigen::VectorXd w;                              // weights of the norm (size N + 2)
    int N() const { return P * n; }
    std::vector<double> params(double p) const {
        std::vector<double> v = base;
        v[static_cast<std::size_t>(j)] = p;
        return v;
    }
    double norm(const Eigen::VectorXd& v) const { return std::sqrt((w.array() * v.array().square()).sum()); }
};

/// What is evaluated at one collocation point.
struct PointData {
    double s = 0.0;
    int interval = 0;
    std::vector<double> l, dl;        // basis at s
    std::vector<double> sk;           // unwrapped delayed positions s - tau_k / T
    std::vector<int> lk;              // their intervals (of the wrapped position)
    std::vector<std::vector<double>> lkv, lkd;  // basis at the wrapped positions
    Eigen::VectorXd x, dx, stacked, f, fp;
    std::vector<Eigen::VectorXd> dxk;  // x'(s_k)
    std::vector<Eigen::MatrixXd> A;
};

Eigen::VectorXd combine(const Setup& c, const Eigen::VectorXd& u, int interval, const std::vector<double>& coef) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(c.n);
    for (int jj = 0; jj <= c.d; ++jj) {
        const int pt = (interval * c.d + jj) % c.P;
        v += coef[static_cast<std::size_t>(jj)] * u.segment(static_cast<Eigen::Index>(pt) * c.n, c.n);
    }
    return v;
}

/// Evaluates the collocation point (interval, g) of the orbit u = (X, T, p); false when f is not
/// finite there. With `derivatives` the Jacobian blocks and df/dp too.
bool evaluate_point(const Setup& c, const Eigen::VectorXd& u, const std::vector<double>& tau, int interval, int g, bool derivatives,
                    PointData& pd) {
    const double T = u(c.N()), p = u(c.N() + 1);
    const std::vector<double> pv = c.params(p);
    pd.interval = interval;
    pd.s = c.mesh.collocation_point(interval, g);
    pd.l.assign(static_cast<std::size_t>(c.d) + 1, 0.0);
    pd.dl.assign(static_cast<std::size_t>(c.d) + 1, 0.0);
    c.mesh.basis(interval, pd.s, pd.l.data(), pd.dl.data());
    pd.x = combine(c, u, interval, pd.l);
    pd.dx = combine(c, u, interval, pd.dl);
    pd.stacked.resize(static_cast<Eigen::Index>(c.n) * (c.m + 1));
    pd.stacked.head(c.n) = pd.x;
    pd.sk.resize(static_cast<std::size_t>(c.m));
    pd.lk.resize(static_cast<std::size_t>(c.m));
    pd.lkv.assign(static_cast<std::size_t>(c.m), std::vector<double>(static_cast<std::size_t>(c.d) + 1));
    pd.lkd.assign(static_cast<std::size_t>(c.m), std::vector<double>(static_cast<std::size_t>(c.d) + 1));
    pd.dxk.resize(static_cast<std::size_t>(c.m));
    for (int k = 0; k < c.m; ++k) {
        const auto uk = static_cast<std::size_t>(k);
        const double sk = pd.s - tau[uk] / T;
        double wrapped = sk - std::floor(sk);
        if (wrapped >= 1.0) wrapped = 0.0;
        pd.sk[uk] = sk;
        pd.lk[uk] = c.mesh.interval_of(wrapped);
        c.mesh.basis(pd.lk[uk], wrapped, pd.lkv[uk].data(), pd.lkd[uk].data());
        pd.stacked.segment(static_cast<Eigen::Index>(k + 1) * c.n, c.n) = combine(c, u, pd.lk[uk], pd.lkv[uk]);
        pd.dxk[uk] = combine(c, u, pd.lk[uk], pd.lkd[uk]);
    }
    pd.f = c.sys.f(pd.stacked, pv);
    if (!pd.f.allFinite()) return false;
    if (derivatives) {
        pd.A = c.sys.jacobians(pd.stacked, pv);
        pd.fp = c.sys.parameter_derivative(pd.stacked, c.j, pv);
        for (const auto& a : pd.A)
            if (!a.allFinite()) return false;
        if (!pd.fp.allFinite()) return false;
    }
    return true;
}

void add_block(std::vector<Triplet>& t, int row, int col, const Eigen::MatrixXd& b, double factor) {
    for (Eigen::Index cc = 0; cc < b.cols(); ++cc)
        for (Eigen::Index r = 0; r < b.rows(); ++r)
            if (b(r, cc) != 0.0) t.emplace_back(row + static_cast<int>(r), col + static_cast<int>(cc), factor * b(r, cc));
}

/// x' of the orbit u at every collocation point (row l d + g), for the phase condition.
Eigen::MatrixXd derivative_at_collocation(const Setup& c, const Eigen::VectorXd& u) {
    Eigen::MatrixXd r(c.P, c.n);
    std::vector<double> l(static_cast<std::size_t>(c.d) + 1), dl(static_cast<std::size_t>(c.d) + 1);
    for (int i = 0; i < c.L; ++i)
        for (int g = 0; g < c.d; ++g) {
            c.mesh.basis(i, c.mesh.collocation_point(i, g), l.data(), dl.data());
            r.row(i * c.d + g) = combine(c, u, i, dl).transpose();
        }
    return r;
}

/// F(u) (N + 1: collocation and phase) and, with J, the bordered Jacobian [dF/du; a^T] and its
/// last residual a . u - b appended (N + 2 rows).
bool assemble(const Setup& c, const Eigen::VectorXd& u, const Eigen::MatrixXd& ref, const Eigen::VectorXd* a, double b,
              Eigen::VectorXd& F, SpD* J) {
    const int N = c.N();
    const double T = u(N), p = u(N + 1);
    if (!(T > 0.0) || !std::isfinite(p)) return false;
    const std::vector<double> pv = c.params(p);
    std::vector<double> tau, dtau;
    try {
        tau = c.sys.delays(pv);
        dtau = c.sys.delay_derivatives(pv, c.j);
    } catch (const std::exception&) {
        return false;
    }
    for (double t : tau)
        if (!(t >= 0.0) || !std::isfinite(t)) return false;
    F.setZero(N + (a ? 2 : 1));
    std::vector<Triplet> trip;
    if (J) trip.reserve(static_cast<std::size_t>(N) * static_cast<std::size_t>((c.d + 1) * (c.m + 1) * 4 + 4));
    PointData pd;
    for (int i = 0; i < c.L; ++i) {
        const double h = c.mesh.width(i);
        for (int g = 0; g < c.d; ++g) {
            if (!evaluate_point(c, u, tau, i, g, J != nullptr, pd)) return false;
            const int row = (i * c.d + g) * c.n;
            F.segment(row, c.n) = pd.dx - T * pd.f;
            const double wg = c.mesh.gauss_weights()[static_cast<std::size_t>(g)] * h;
            const Eigen::VectorXd r = ref.row(i * c.d + g).transpose();
            F(N) += wg * pd.x.dot(r);
            if (!J) continue;
            for (int jj = 0; jj <= c.d; ++jj) {
                const int col = ((i * c.d + jj) % c.P) * c.n;
                const double lj = pd.l[static_cast<std::size_t>(jj)], dlj = pd.dl[static_cast<std::size_t>(jj)];
                for (int q = 0; q < c.n; ++q) trip.emplace_back(row + q, col + q, dlj);
                add_block(trip, row, col, pd.A[0], -T * lj);
                for (int q = 0; q < c.n; ++q)
                    if (r(q) != 0.0) trip.emplace_back(N, col + q, wg * lj * r(q));
            }
            Eigen::VectorXd dT = -pd.f, dp = -T * pd.fp;
            for (int k = 0; k < c.m; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                for (int jj = 0; jj <= c.d; ++jj) {
                    const int col = ((pd.lk[uk] * c.d + jj) % c.P) * c.n;
                    add_block(trip, row, col, pd.A[uk + 1], -T * pd.lkv[uk][static_cast<std::size_t>(jj)]);
                }
                const Eigen::VectorXd ad = pd.A[uk + 1] * pd.dxk[uk];
                dT -= ad * (tau[uk] / T);
                dp += ad * dtau[uk];
            }
            for (int q = 0; q < c.n; ++q) {
                trip.emplace_back(row + q, N, dT(q));
                trip.emplace_back(row + q, N + 1, dp(q));
            }
        }
    }
    if (a) {
        F(N + 1) = a->dot(u) - b;
        if (J)
            for (int q = 0; q < N + 2; ++q)
                if ((*a)(q) != 0.0) trip.emplace_back(N + 1, q, (*a)(q));
    }
    if (J) {
        J->resize(N + 2, N + 2);
        J->setFromTriplets(trip.begin(), trip.end());
    }
    return F.allFinite();
}

struct Linearization;

struct Correction {
    bool ok = false;
    int iterations = 0;
    int jacobians = 0;  // linearisations (condensed) or sparse LU factorisations
    double residual = std::numeric_limits<double>::infinity();
    Eigen::VectorXd tangent;  // [J; a^T]^{-1} e_last at the result (not normalised)
    std::shared_ptr<const Linearization> lin;  // at the result (condensed path only)
};

/// Newton on [F(u); a . u - b] = 0 with the phase reference `ref` (x' of the previous orbit),
/// every step with a sparse LU of the whole bordered Jacobian: the path for windows too large
/// for the condensed form (see Linearization).
Correction correct_sparse(const Setup& c, Eigen::VectorXd& u, const Eigen::MatrixXd& ref, const Eigen::VectorXd& a, double b,
                   const PeriodicOrbitOptions& o) {
    Correction r;
    Eigen::VectorXd F;
    SpD J;
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    auto factorize = [&lu](SpD& m) {
        m.makeCompressed();
        lu.compute(m);
        return lu.info() == Eigen::Success;
    };
    double last_step = std::numeric_limits<double>::infinity();
    for (int it = 0; it <= o.max_iterations; ++it) {
        if (it > 0 && last_step <= o.tolerance * std::max(1.0, u.lpNorm<Eigen::Infinity>())) {
            // converged: the residual at u, the tangent from the last factorisation (one step
            // earlier, an O(|du|) difference in a direction that is normalised anyway)
            if (!assemble(c, u, ref, &a, b, F, nullptr)) return r;
            r.residual = F.head(c.N() + 1).lpNorm<Eigen::Infinity>();
            r.ok = r.residual <= o.residual_tolerance;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(c.N() + 2);
            e(c.N() + 1) = 1.0;
            r.tangent = lu.solve(e);
            if (!r.tangent.allFinite()) r.ok = false;
            return r;
        }
        if (it == o.max_iterations) break;
        if (!assemble(c, u, ref, &a, b, F, &J)) return r;
        if (!factorize(J)) return r;
        ++r.jacobians;
        r.residual = F.head(c.N() + 1).lpNorm<Eigen::Infinity>();
        const Eigen::VectorXd du = lu.solve(F);
        if (!du.allFinite()) return r;
        u -= du;
        ++r.iterations;
        last_step = du.lpNorm<Eigen::Infinity>();
    }
    return r;
}

/// Floquet multipliers of the orbit u (see the header), sorted by decreasing modulus.
bool multipliers(const Setup& c, const Eigen::VectorXd& u, std::vector<cplx>& out) {
    const int N = c.N(), n = c.n, d = c.d, P = c.P;
    const double T = u(N);
    const std::vector<double> pv = c.params(u(N + 1));
    const std::vector<double> tau = c.sys.delays(pv);
    double rmax = 0.0;
    for (double t : tau) rmax = std::max(rmax, t / T);
    long gmin = 0;
    if (rmax > 0.0) {
        const double smin = -rmax;
        const double fl = std::floor(smin);
        double w = smin - fl;
        if (w >= 1.0) w = 0.0;
        gmin = static_cast<long>(fl) * P + static_cast<long>(c.mesh.interval_of(w)) * d;
    }
    const long nh = 1 - gmin;  // history points gmin..0
    if (nh * n > 4000) return false;  // the dense eigenvalue problem would be too large
    std::vector<Triplet> t1, t0;
    auto put = [&](long g, int row, const Eigen::MatrixXd& blk, double factor) {
        if (g >= 1) add_block(t1, row, static_cast<int>((g - 1) * n), blk, factor);
        else add_block(t0, row, static_cast<int>((g - gmin) * n), blk, factor);
    };
    const Eigen::MatrixXd eye = Eigen::MatrixXd::Identity(n, n);
    PointData pd;
    for (int i = 0; i < c.L; ++i)
        for (int g = 0; g < d; ++g) {
            if (!evaluate_point(c, u, tau, i, g, true, pd)) return false;
            const int row = (i * d + g) * n;
            for (int jj = 0; jj <= d; ++jj) {
                const long gl = i * d + jj;  // 0..P, not wrapped
                put(gl, row, eye, pd.dl[static_cast<std::size_t>(jj)]);
                put(gl, row, pd.A[0], -T * pd.l[static_cast<std::size_t>(jj)]);
            }
            for (int k = 0; k < c.m; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                const long per = static_cast<long>(std::floor(pd.sk[uk]));
                for (int jj = 0; jj <= d; ++jj) {
                    const long gl = per * P + static_cast<long>(pd.lk[uk]) * d + jj;
                    put(gl, row, pd.A[uk + 1], -T * pd.lkv[uk][static_cast<std::size_t>(jj)]);
                }
            }
        }
    SpD m1(N, N), m0(N, static_cast<int>(nh * n));
    m1.setFromTriplets(t1.begin(), t1.end());
    m0.setFromTriplets(t0.begin(), t0.end());
    // many right-hand sides: the supernodal LU solves them as a block
    m1.makeCompressed();
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(m1);
    if (lu.info() != Eigen::Success) return false;
    const Eigen::MatrixXd y = -lu.solve(Eigen::MatrixXd(m0));
    if (!y.allFinite()) return false;
    const auto H = static_cast<Eigen::Index>(nh * n);
    Eigen::MatrixXd mono = Eigen::MatrixXd::Zero(H, H);
    for (long h = 0; h < nh; ++h) {
        const long g = gmin + h + P;
        if (g <= 0) mono.block(h * n, (g - gmin) * n, n, n) = eye;
        else mono.block(h * n, 0, n, H) = y.block((g - 1) * n, 0, n, H);
    }
    Eigen::EigenSolver<Eigen::MatrixXd> es(mono, false);
    if (es.info() != Eigen::Success) return false;
    out.clear();
    for (Eigen::Index k = 0; k < H; ++k) out.push_back(es.eigenvalues()(k));
    std::sort(out.begin(), out.end(), [](cplx a, cplx b) { return std::abs(a) > std::abs(b); });
    return true;
}

using RowMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using SpR = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// The collocation Jacobian at an orbit in the condensed form of the Floquet problem. Ordered as
/// in multipliers(): the unknowns are the values at the points g = 1..P of the period (M1, whose
/// column block g - 1 is the orbit's point g mod P) and at the history window g = gmin..0 (M0,
/// H = (1 - gmin) n columns), so that dF/dX = M1 + M0 E with E picking the window's points from
/// the orbit. M1 is block lower triangular by mesh intervals (a delayed point is never later
/// than its collocation point): L diagonal blocks of d n x d n, factorised densely, and the
/// entries left of them (`lower`). Its forward sweep gives
///     Y = -M1^{-1} [M0, dF/dT, dF/dp]      (N x (H + 2)),
/// and with it the Newton system J du = r of the whole bordered Jacobian reduces exactly (a Schur
/// complement) to the dense (H + 2) x (H + 2) system K in the window values z and (dT, dp):
///     Y_{b(h)} w - z_h = -x_{b(h)},  ph . Y w = r_ph - ph . x,  a . Y w + (a_T, a_p) . (dT, dp) = r_a - a . x,
/// with x = M1^{-1} r_coll, w = (z, dT, dp), b(h) the M1 block of window point h, and
/// du = x + Y w. The rows of Y at the points one period after the window are the monodromy
/// matrix of the Floquet multipliers. Cost: one sweep with H + 2 right-hand sides per
/// linearisation, one with one right-hand side per Newton step.
struct Linearization {
    long gmin = 0, nh = 0;
    int H = 0;
    std::vector<Eigen::PartialPivLU<Eigen::MatrixXd>> diag;
    SpR lower;
    RowMat Y;
};

/// The bordering of a linearisation for one corrector: phase row and arclength row (in M1 order) and K.
struct Border {
    Eigen::VectorXd ph, a;
    Eigen::PartialPivLU<Eigen::MatrixXd> K;
};

/// failed: f or its derivatives not finite at u; too_large: see below; unstable: a singular
/// diagonal block or Y not finite (the sparse LU of the whole Jacobian is used instead).
enum class LinStatus { ok, too_large, failed, unstable };

/// The largest window (H = n times its points) and Y (N (H + 2) doubles) of the condensed form;
/// beyond them the sparse LU of the whole Jacobian is used (correct_sparse).
constexpr int kMaxWindow = 4000;
constexpr double kMaxCondensed = 1.6e7;

/// The M1 block (0..P-1) of the orbit's point q (0..P-1): point P of M1 is point 0.
inline int m1_block(int q, int P) { return q == 0 ? P - 1 : q - 1; }
/// The orbit's point of window point g (any integer): g mod P.
inline int wrap_point(long g, int P) { return static_cast<int>(((g % P) + P) % P); }

/// x := M1^{-1} x (any number of columns), by the forward sweep over the intervals.
void sweep(const Setup& c, const Linearization& lz, RowMat& x) {
    const int dn = c.d * c.n;
    for (int i = 0; i < c.L; ++i) {
        const int r0 = i * dn;
        for (int q = r0; q < r0 + dn; ++q)
            for (SpR::InnerIterator it(lz.lower, q); it; ++it) x.row(q) -= it.value() * x.row(it.col());
        const Eigen::MatrixXd blk = lz.diag[static_cast<std::size_t>(i)].solve(x.middleRows(r0, dn));
        x.middleRows(r0, dn) = blk;
    }
}

/// The linearisation at u (Linearization); too_large when the window or Y exceed the limits above.
LinStatus linearize(const Setup& c, const Eigen::VectorXd& u, Linearization& lz) {
    const int N = c.N(), n = c.n, d = c.d, P = c.P, dn = d * n;
    const double T = u(N);
    if (!(T > 0.0) || !std::isfinite(u(N + 1))) return LinStatus::failed;
    const std::vector<double> pv = c.params(u(N + 1));
    std::vector<double> tau, dtau;
    try {
        tau = c.sys.delays(pv);
        dtau = c.sys.delay_derivatives(pv, c.j);
    } catch (const std::exception&) {
        return LinStatus::failed;
    }
    double rmax = 0.0;
    for (double t : tau) {
        if (!(t >= 0.0) || !std::isfinite(t)) return LinStatus::failed;
        rmax = std::max(rmax, t / T);
    }
    long gmin = 0;
    if (rmax > 0.0) {
        const double fl = std::floor(-rmax);
        double w = -rmax - fl;
        if (w >= 1.0) w = 0.0;
        gmin = static_cast<long>(fl) * P + static_cast<long>(c.mesh.interval_of(w)) * d;
    }
    const long nh = 1 - gmin;
    if (nh * n > kMaxWindow || static_cast<double>(N) * static_cast<double>(nh * n + 2) > kMaxCondensed) return LinStatus::too_large;
    lz.gmin = gmin;
    lz.nh = nh;
    lz.H = static_cast<int>(nh * n);
    const int H = lz.H;
    std::vector<Eigen::MatrixXd> D(static_cast<std::size_t>(c.L), Eigen::MatrixXd::Zero(dn, dn));
    std::vector<Triplet> low;
    low.reserve(static_cast<std::size_t>(N) * static_cast<std::size_t>((c.d + 1) * (c.m + 1) * 2));
    RowMat B = RowMat::Zero(N, H + 2);  // -[M0, dF/dT, dF/dp]
    bool structure = true;
    auto put = [&](int i, long g, int row, const Eigen::MatrixXd* blk, double factor) {
        if (factor == 0.0) return;
        if (g >= 1) {
            const long col = (g - 1) * n;
            if (col >= static_cast<long>(i) * dn && col < static_cast<long>(i + 1) * dn) {
                auto db = D[static_cast<std::size_t>(i)].block(row - i * dn, col - static_cast<long>(i) * dn, n, n);
                if (blk) db += factor * *blk;
                else db.diagonal().array() += factor;
            } else if (col < static_cast<long>(i) * dn) {
                for (int cc = 0; cc < n; ++cc)
                    for (int r = 0; r < n; ++r) {
                        const double v = blk ? (*blk)(r, cc) : (r == cc ? 1.0 : 0.0);
                        if (v != 0.0) low.emplace_back(row + r, static_cast<int>(col) + cc, factor * v);
                    }
            } else {
                structure = false;  // a point later than the interval: not block lower triangular
            }
        } else {
            auto mb = B.block(row, (g - gmin) * n, n, n);
            if (blk) mb -= factor * *blk;
            else mb.diagonal().array() -= factor;
        }
    };
    PointData pd;
    for (int i = 0; i < c.L; ++i)
        for (int g = 0; g < d; ++g) {
            if (!evaluate_point(c, u, tau, i, g, true, pd)) return LinStatus::failed;
            const int row = (i * d + g) * n;
            for (int jj = 0; jj <= d; ++jj) {
                const long gl = static_cast<long>(i) * d + jj;
                put(i, gl, row, nullptr, pd.dl[static_cast<std::size_t>(jj)]);
                put(i, gl, row, &pd.A[0], -T * pd.l[static_cast<std::size_t>(jj)]);
            }
            Eigen::VectorXd dT = -pd.f, dp = -T * pd.fp;
            for (int k = 0; k < c.m; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                const long per = static_cast<long>(std::floor(pd.sk[uk]));
                for (int jj = 0; jj <= d; ++jj)
                    put(i, per * P + static_cast<long>(pd.lk[uk]) * d + jj, row, &pd.A[uk + 1], -T * pd.lkv[uk][static_cast<std::size_t>(jj)]);
                const Eigen::VectorXd ad = pd.A[uk + 1] * pd.dxk[uk];
                dT -= ad * (tau[uk] / T);
                dp += ad * dtau[uk];
            }
            B.block(row, H, n, 1) = -dT;
            B.block(row, H + 1, n, 1) = -dp;
        }
    if (!structure) return LinStatus::too_large;
    lz.lower.resize(N, N);
    lz.lower.setFromTriplets(low.begin(), low.end());
    lz.lower.makeCompressed();
    lz.diag.clear();
    lz.diag.reserve(D.size());
    for (const Eigen::MatrixXd& m : D) {
        lz.diag.emplace_back(m);
        if (!(std::abs(lz.diag.back().determinant()) > 0.0)) return LinStatus::unstable;
    }
    sweep(c, lz, B);
    if (!B.allFinite()) return LinStatus::unstable;
    lz.Y = std::move(B);
    return LinStatus::ok;
}

/// The phase row d(phase)/dX (N, in the orbit's order) for the reference x' values `ref`.
Eigen::VectorXd phase_row(const Setup& c, const Eigen::MatrixXd& ref) {
    Eigen::VectorXd ph = Eigen::VectorXd::Zero(c.N());
    std::vector<double> l(static_cast<std::size_t>(c.d) + 1), dl(static_cast<std::size_t>(c.d) + 1);
    for (int i = 0; i < c.L; ++i)
        for (int g = 0; g < c.d; ++g) {
            c.mesh.basis(i, c.mesh.collocation_point(i, g), l.data(), dl.data());
            const double wg = c.mesh.gauss_weights()[static_cast<std::size_t>(g)] * c.mesh.width(i);
            for (int jj = 0; jj <= c.d; ++jj) {
                const int col = ((i * c.d + jj) % c.P) * c.n;
                ph.segment(col, c.n) += (wg * l[static_cast<std::size_t>(jj)]) * ref.row(i * c.d + g).transpose();
            }
        }
    return ph;
}

/// K of the linearisation for the phase row ph (orbit order) and the arclength row a (N + 2).
bool border(const Setup& c, const Linearization& lz, const Eigen::VectorXd& ph, const Eigen::VectorXd& a, Border& bd) {
    const int N = c.N(), n = c.n, P = c.P, H = lz.H;
    bd.ph.resize(N);
    bd.a.resize(N);
    for (int q = 0; q < P; ++q) {
        const int b = m1_block(q, P);
        bd.ph.segment(b * n, n) = ph.segment(q * n, n);
        bd.a.segment(b * n, n) = a.segment(q * n, n);
    }
    Eigen::MatrixXd K(H + 2, H + 2);
    for (long h = 0; h < lz.nh; ++h) {
        const int b = m1_block(wrap_point(lz.gmin + h, P), P);
        K.middleRows(h * n, n) = lz.Y.middleRows(static_cast<Eigen::Index>(b) * n, n);
        K.block(h * n, h * n, n, n).diagonal().array() -= 1.0;
    }
    K.row(H) = bd.ph.transpose() * lz.Y;
    K.row(H + 1) = bd.a.transpose() * lz.Y;
    K(H + 1, H) += a(N);
    K(H + 1, H + 1) += a(N + 1);
    if (!K.allFinite()) return false;
    bd.K.compute(K);
    return std::abs(bd.K.determinant()) > 0.0;
}

/// du with J du = r (the bordered Jacobian of assemble(), N + 2 rows) from the condensed form.
Eigen::VectorXd condensed_solve(const Setup& c, const Linearization& lz, const Border& bd, const Eigen::VectorXd& r) {
    const int N = c.N(), n = c.n, P = c.P, H = lz.H;
    RowMat x = r.head(N);
    sweep(c, lz, x);
    const Eigen::Map<const Eigen::VectorXd> xv(x.data(), N);
    Eigen::VectorXd rk(H + 2);
    for (long h = 0; h < lz.nh; ++h) {
        const int b = m1_block(wrap_point(lz.gmin + h, P), P);
        rk.segment(h * n, n) = -xv.segment(static_cast<Eigen::Index>(b) * n, n);
    }
    rk(H) = r(N) - bd.ph.dot(xv);
    rk(H + 1) = r(N + 1) - bd.a.dot(xv);
    const Eigen::VectorXd w = bd.K.solve(rk);
    const Eigen::VectorXd dx = xv + lz.Y * w;
    Eigen::VectorXd du(N + 2);
    for (int q = 0; q < P; ++q) du.segment(q * n, n) = dx.segment(static_cast<Eigen::Index>(m1_block(q, P)) * n, n);
    du(N) = w(H);
    du(N + 1) = w(H + 1);
    return du;
}

/// Newton on [F(u); a . u - b] = 0 (see correct_sparse) in the condensed form: chord steps with
/// the linearisation `start` (e.g. at the previous orbit of the branch), a new linearisation at
/// the current iterate when a step contracts by less than kChordContraction, and one at the
/// result (for the tangent, the multipliers and the next corrector).
constexpr double kChordContraction = 0.3;
/// The chord steps go on to this fraction of the Newton tolerance while they contract (the
/// linearisation for the multipliers is taken there, and |mu_trivial - 1| follows its distance
/// from the orbit); a step within the tolerance that no longer contracts is at the rounding
/// floor of the condensed solve and ends them.
constexpr double kChordTolerance = 1e-2;

Correction correct(const Setup& c, Eigen::VectorXd& u, const Eigen::MatrixXd& ref, const Eigen::VectorXd& a, double b,
                   const PeriodicOrbitOptions& o, std::shared_ptr<const Linearization> start) {
    Correction r;
    const int N = c.N();
    auto fresh = [&](std::shared_ptr<const Linearization>& lz) {
        auto next = std::make_shared<Linearization>();
        const LinStatus st = linearize(c, u, *next);
        ++r.jacobians;
        if (st != LinStatus::ok) return st;
        lz = std::move(next);
        return st;
    };
    std::shared_ptr<const Linearization> lz = std::move(start);
    if (!lz) {
        const LinStatus st = fresh(lz);
        if (st == LinStatus::too_large || st == LinStatus::unstable) return correct_sparse(c, u, ref, a, b, o);
        if (st != LinStatus::ok) return r;
    }
    const Eigen::VectorXd ph = phase_row(c, ref);
    Border bd;
    if (!border(c, *lz, ph, a, bd)) return correct_sparse(c, u, ref, a, b, o);
    Eigen::VectorXd F;
    double previous = std::numeric_limits<double>::infinity();
    int refreshes = 0;
    bool converged = false;
    for (int step = 0; step < 3 * o.max_iterations; ++step) {
        if (!assemble(c, u, ref, &a, b, F, nullptr)) return r;
        r.residual = F.head(N + 1).lpNorm<Eigen::Infinity>();
        Eigen::VectorXd du = condensed_solve(c, *lz, bd, F);
        if (!du.allFinite()) return r;
        double size = du.lpNorm<Eigen::Infinity>();
        const double target = o.tolerance * std::max(1.0, u.lpNorm<Eigen::Infinity>());
        const bool slow = step > 0 && size > kChordContraction * previous;
        if (slow && size <= target) {  // within the tolerance and at the rounding floor of the condensed solve
            converged = true;
            break;
        }
        if (slow) {
            if (r.jacobians >= o.max_iterations) return r;
            ++refreshes;
            if (fresh(lz) != LinStatus::ok || !border(c, *lz, ph, a, bd)) return r;
            du = condensed_solve(c, *lz, bd, F);
            if (!du.allFinite()) return r;
            size = du.lpNorm<Eigen::Infinity>();
        }
        u -= du;
        ++r.iterations;
        previous = size;
        if (size <= kChordTolerance * target) {
            converged = true;
            break;
        }
    }
    if (!converged || !assemble(c, u, ref, &a, b, F, nullptr)) return r;
    // the linearisation at the result (for the tangent [J; a^T]^{-1} e_last, the multipliers and
    // the next chord), first used for one Newton step: the chord steps converge linearly, so the
    // result of their last step is only about kChordContraction * tolerance accurate
    if (fresh(lz) != LinStatus::ok || !border(c, *lz, ph, a, bd)) return r;
    const Eigen::VectorXd du = condensed_solve(c, *lz, bd, F);
    if (!du.allFinite()) return r;
    u -= du;
    ++r.iterations;
    if (!assemble(c, u, ref, &a, b, F, nullptr)) return r;
    r.residual = F.head(N + 1).lpNorm<Eigen::Infinity>();
    if (!(r.residual <= o.residual_tolerance)) return r;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 2);
    e(N + 1) = 1.0;
    r.tangent = condensed_solve(c, *lz, bd, e);
    if (!r.tangent.allFinite()) return r;
    r.lin = lz;
    r.ok = true;
    return r;
}

/// The eigenvalues of the monodromy matrix: all of them (dense QR) up to kDenseMultipliers, else
/// the largest in modulus by Arnoldi (Spectra), at least kArnoldiMultipliers and, doubling
/// their number, until the smallest one found is below kArnoldiFloor in modulus (so every
/// multiplier outside the disc of that radius is listed); dense QR when Arnoldi fails.
constexpr int kDenseMultipliers = 200;
constexpr int kArnoldiMultipliers = 16;
constexpr double kArnoldiFloor = 0.5;

bool monodromy_eigenvalues(const Eigen::MatrixXd& mono, std::vector<cplx>& out) {
    const auto H = mono.rows();
    out.clear();
    if (H > kDenseMultipliers) {
        Spectra::DenseGenMatProd<double> op(mono);
        const double scale = mono.lpNorm<Eigen::Infinity>();
        for (Eigen::Index nev = kArnoldiMultipliers; 2 * nev + 20 <= H / 2; nev *= 2) {
            Spectra::GenEigsSolver<Spectra::DenseGenMatProd<double>> es(op, nev, 2 * nev + 20);
            es.init();
            es.compute(Spectra::SortRule::LargestMagn, 1000, 1e-13);
            if (es.info() != Spectra::CompInfo::Successful) break;
            const Eigen::VectorXcd ev = es.eigenvalues();
            const Eigen::MatrixXcd vec = es.eigenvectors();
            if (ev.size() == 0) break;
            // every Ritz pair checked: |M v - mu v| <= 1e-9 |M| |v|
            bool good = true;
            for (Eigen::Index k = 0; k < ev.size() && good; ++k)
                good = (mono * vec.col(k) - ev(k) * vec.col(k)).norm() <= 1e-9 * scale * vec.col(k).norm();
            if (!good) break;
            if (std::abs(ev(ev.size() - 1)) < kArnoldiFloor) {
                for (Eigen::Index k = 0; k < ev.size(); ++k) out.push_back(ev(k));
                break;
            }
        }
    }
    if (out.empty()) {
        Eigen::EigenSolver<Eigen::MatrixXd> es(mono, false);
        if (es.info() != Eigen::Success) return false;
        for (Eigen::Index k = 0; k < H; ++k) out.push_back(es.eigenvalues()(k));
    }
    std::sort(out.begin(), out.end(), [](cplx a, cplx b) { return std::abs(a) > std::abs(b); });
    return true;
}

/// Floquet multipliers from the linearisation at the orbit: the monodromy matrix maps the window
/// values to the values one period later (rows of Y, or of the identity for window points that
/// are still in the window one period later).
bool condensed_multipliers(const Setup& c, const Linearization& lz, std::vector<cplx>& out) {
    const int n = c.n, P = c.P, H = lz.H;
    Eigen::MatrixXd mono = Eigen::MatrixXd::Zero(H, H);
    for (long h = 0; h < lz.nh; ++h) {
        const long g = lz.gmin + h + P;
        if (g <= 0) mono.block(h * n, (g - lz.gmin) * n, n, n).setIdentity();
        else mono.middleRows(h * n, n) = lz.Y.block((g - 1) * n, 0, n, H);
    }
    return monodromy_eigenvalues(mono, out);
}

PeriodicOrbit make_orbit(const Setup& c, const Eigen::VectorXd& u, const Correction& r, bool floquet) {
    PeriodicOrbit o;
    o.period = u(c.N());
    o.par = u(c.N() + 1);
    o.profile.resize(c.P, c.n);
    for (int i = 0; i < c.P; ++i) o.profile.row(i) = u.segment(static_cast<Eigen::Index>(i) * c.n, c.n).transpose();
    o.min = o.profile.colwise().minCoeff().transpose();
    o.max = o.profile.colwise().maxCoeff().transpose();
    // the extremes sampled at 8 d points per interval (besides the mesh points): the sampling
    // error is at most (h T / (8 d))^2 |x''| / 8
    const int per = 8 * c.d;
    for (int i = 0; i < c.L; ++i)
        for (int k = 1; k < per; ++k) {
            const Eigen::VectorXd x = orbit_value(c.mesh, o.profile, c.mesh.breakpoints()[static_cast<std::size_t>(i)] + c.mesh.width(i) * k / per);
            o.min = o.min.cwiseMin(x);
            o.max = o.max.cwiseMax(x);
        }
    o.breakpoints = c.mesh.breakpoints();
    o.residual = r.residual;
    o.iterations = r.iterations;
    const bool have = floquet && (r.lin ? condensed_multipliers(c, *r.lin, o.multipliers) : multipliers(c, u, o.multipliers));
    if (have && !o.multipliers.empty()) {
        std::size_t k1 = 0;
        for (std::size_t k = 1; k < o.multipliers.size(); ++k)
            if (std::abs(o.multipliers[k] - 1.0) < std::abs(o.multipliers[k1] - 1.0)) k1 = k;
        o.trivial_distance = std::abs(o.multipliers[k1] - 1.0);
        o.max_nontrivial = 0.0;
        for (std::size_t k = 0; k < o.multipliers.size(); ++k)
            if (k != k1) o.max_nontrivial = std::max(o.max_nontrivial, std::abs(o.multipliers[k]));
        o.stable = o.max_nontrivial < 1.0;
        orbit_continuation::check_accuracy(o);
    } else if (floquet) {
        // asked for and not computed: no verdict (never "unstable" by default)
        o.multipliers.clear();
        o.stable = false;
        o.undecided = "no Floquet multipliers: the monodromy matrix of this mesh (" + std::to_string(c.P) + " mesh points per period, " +
                      std::to_string(c.n) + (c.n == 1 ? " state" : " states") + ", over the delay's history) is above the dense limit of 4000 rows, "
                      "or its eigensolver failed; fewer --intervals or a lower --degree give them";
    }
    return o;
}

/// max over the variables of max - min: 0 for an equilibrium.
double amplitude(const PeriodicOrbit& o) { return (o.max - o.min).maxCoeff(); }

Setup make_setup(const NonlinearDDE& system, const PeriodicMesh& mesh, const PeriodicOrbitOptions& o, double period_scale) {
    std::string why;
    if (!o.is_valid(&why)) throw std::invalid_argument("periodic orbit options: " + why);
    if (!system.has_delay_derivatives())
        throw std::invalid_argument("periodic orbits: the system must give exact delay derivatives (has_delay_derivatives())");
    Setup c(system, mesh);
    c.n = system.dimension();
    c.m = system.delay_count();
    c.j = system.parameter_index(o.parameter);
    c.d = mesh.degree();
    c.L = mesh.intervals();
    c.P = mesh.points();
    c.base = system.parameter_values();
    const int N = c.N();
    c.w.resize(N + 2);
    c.w.head(N).setConstant(1.0 / c.P);
    c.w(N) = 1.0 / (period_scale * period_scale);
    const double sp = std::abs(o.to - o.from);
    c.w(N + 1) = 1.0 / (sp * sp);
    return c;
}

/// The mesh that equidistributes |x^(d+1)|^(1/(d+1)) of the orbit u (analysis/bifurcation/internal/orbit_mesh.hpp).
std::vector<double> adapted_breakpoints(const Setup& c, const Eigen::VectorXd& u) {
    return orbit_mesh::equidistributed_breakpoints(c.mesh, c.n, u);
}

/// The same problem on another mesh of the same degree and number of intervals.
Setup with_mesh(const Setup& c, const PeriodicMesh& mesh) {
    Setup s(c.sys, mesh);
    s.n = c.n;
    s.m = c.m;
    s.j = c.j;
    s.d = c.d;
    s.L = c.L;
    s.P = c.P;
    s.base = c.base;
    s.w = c.w;
    return s;
}

/// u (or a tangent) on the mesh of `from` re-represented on the mesh of `to`: the X part
/// interpolated at the new points, T and p kept.
Eigen::VectorXd resample(const Setup& from, const Setup& to, const Eigen::VectorXd& u) {
    Eigen::MatrixXd profile(from.P, from.n);
    for (int i = 0; i < from.P; ++i) profile.row(i) = u.segment(static_cast<Eigen::Index>(i) * from.n, from.n).transpose();
    Eigen::VectorXd v(to.N() + 2);
    for (int i = 0; i < to.P; ++i) v.segment(static_cast<Eigen::Index>(i) * to.n, to.n) = orbit_value(from.mesh, profile, to.mesh.point(i));
    v(to.N()) = u(from.N());
    v(to.N() + 1) = u(from.N() + 1);
    return v;
}

/// How a branch recognises that it came back to where its orbits are born: the size of an orbit
/// (0 there) and the name of that end. A branch from a Hopf point: the amplitude max - min, which
/// falls to 0 at an equilibrium ("hopf"); the period-doubled branch: the distance between the
/// orbit and itself half a period later, 0 on the orbit of half the period ("period_doubling").
struct BranchEnd {
    std::function<double(const PeriodicMesh&, const PeriodicOrbit&)> size;
    std::string stop;
};

BranchEnd hopf_end() {
    return {[](const PeriodicMesh&, const PeriodicOrbit& o) { return amplitude(o); }, "hopf"};
}

/// max over the mesh points s of max |x(s) - x(s + 1/2)| (the infinity norm over the variables).
double half_period_distance(const PeriodicMesh& mesh, const PeriodicOrbit& o) {
    double r = 0.0;
    for (int i = 0; i < mesh.points(); ++i)
        r = std::max(r, (o.profile.row(i).transpose() - orbit_value(mesh, o.profile, mesh.point(i) + 0.5)).lpNorm<Eigen::Infinity>());
    return r;
}

/// Follows the branch from the corrected first orbit u with unit tangent t.
void follow(const Setup& c0, Eigen::VectorXd u, Eigen::VectorXd t, const Correction& first, const PeriodicOrbitOptions& o,
            OrbitBranch& b, const BranchEnd& end = hopf_end()) {
    // the mesh of the next orbit (adapted to the last one when o.adapt); Setup refers to it
    std::unique_ptr<PeriodicMesh> mesh;
    std::unique_ptr<Setup> cp = std::make_unique<Setup>(c0);
    const int N = c0.N();
    const double lo = std::min(o.from, o.to), hi = std::max(o.from, o.to);
    const double T0 = u(N);
    const Setup* cur = cp.get();
    std::shared_ptr<const Linearization> lin_u = first.lin;  // at u: the chord matrix of the next corrector
    auto adapt = [&]() {
        if (!o.adapt) return;
        auto next_mesh = std::make_unique<PeriodicMesh>(c0.mesh.degree(), adapted_breakpoints(*cur, u));
        auto next = std::make_unique<Setup>(with_mesh(*cur, *next_mesh));
        u = resample(*cur, *next, u);
        t = resample(*cur, *next, t);
        t /= next->norm(t);
        mesh = std::move(next_mesh);
        cp = std::move(next);
        cur = cp.get();
        lin_u.reset();  // the next corrector starts with a linearisation on the new mesh
    };
    auto report = [&] {
        if (o.progress) o.progress(static_cast<long>(b.points.size()), o.max_points, b.points.back().par);
    };
    b.points.push_back(make_orbit(*cur, u, first, o.floquet));
    report();
    const double amp0 = end.size(cur->mesh, b.points.front());
    double amp_max = amp0;
    b.newton_iterations += first.iterations;
    b.jacobians += first.jacobians;
    StepControl step(orbit_continuation::step_control_options(o));
    b.stop = "max_points";
    adapt();
    while (static_cast<int>(b.points.size()) < o.max_points) {
        const Setup& c = *cur;
        const double h = step.h();
        const Eigen::MatrixXd ref = derivative_at_collocation(c, u);
        Eigen::VectorXd v = u + h * t;
        const Eigen::VectorXd a = c.w.cwiseProduct(t);
        Correction r = correct(c, v, ref, a, a.dot(u + h * t), o, lin_u);
        b.newton_iterations += r.iterations;
        b.jacobians += r.jacobians;
        const bool jump = r.ok && step.jumped(c.norm(v - u));
        if (!r.ok || jump) {
            if (!step.reject()) {
                b.stop = "step_below_minimum";
                b.status = jump ? Status::NumericalIssue : Status::MaxIterations;
                std::ostringstream s;
                s << "the corrector failed at " << b.parameter << " = " << v(N + 1) << " with the step below " << o.min_step;
                b.message = s.str();
                return;
            }
            continue;
        }
        Eigen::VectorXd tn = r.tangent / c.norm(r.tangent);
        if (tn.dot(c.w.cwiseProduct(t)) < 0.0) tn = -tn;
        // the end of the parameter range: the orbit on the face
        const double p = v(N + 1);
        if (p < lo || p > hi) {
            const double bound = p < lo ? lo : hi;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 2);
            e(N + 1) = 1.0;
            Eigen::VectorXd w = v;
            const Correction rb = correct(c, w, ref, e, bound, o, r.lin);
            b.newton_iterations += rb.iterations;
            b.jacobians += rb.jacobians;
            if (rb.ok) {
                b.points.push_back(make_orbit(c, w, rb, o.floquet));
                report();
            } else {
                b.status = Status::MaxIterations;
                b.message = "the orbit on the end of the parameter range did not converge";
            }
            b.stop = "bound";
            return;
        }
        PeriodicOrbit orbit = make_orbit(c, v, r, o.floquet);
        // the branch reached an equilibrium (a Hopf point) and went through it onto the same
        // orbits, phase-shifted: near the Hopf point p - p_H ~ amplitude^2, so the parameter turns
        // back within the step while the amplitude is near zero. A fold of orbits turns the
        // parameter too, but at an amplitude of the order of the branch's; so a turn with both
        // orbits below a quarter of the largest amplitude seen is taken as the Hopf point: the
        // branch ends there (once it ran on, looped, and listed the Hopf points as folds)
        const double size_last = end.size(c.mesh, b.points.back()), size_next = end.size(c.mesh, orbit);
        amp_max = std::max(amp_max, size_last);
        if (t(N + 1) * tn(N + 1) < 0.0 && std::max(size_last, size_next) < 0.25 * amp_max) {
            b.stop = end.stop;
            return;
        }
        const int after = static_cast<int>(b.points.size()) - 1;
        // folds, period doublings and tori of this step (analysis/bifurcation/internal/orbit_continuation.hpp)
        {
            const Eigen::VectorXd ak = c.w.cwiseProduct(t);
            Eigen::VectorXd best = v;
            Correction bestc = r;
            orbit_continuation::Probe probe;
            probe.fold_trial = [&](double s, double& g) {
                Eigen::VectorXd w = u + s * t;
                const Correction rc = correct(c, w, ref, ak, ak.dot(u + s * t), o, lin_u);
                b.newton_iterations += rc.iterations;
                b.jacobians += rc.jacobians;
                if (!rc.ok) return false;
                g = (rc.tangent / c.norm(rc.tangent))(N + 1) * (rc.tangent.dot(ak) < 0.0 ? -1.0 : 1.0);
                best = w;
                bestc = rc;
                return true;
            };
            probe.fold_orbit = [&] { return make_orbit(c, best, bestc, o.floquet); };
            probe.orbit_at = [&](double s, PeriodicOrbit& out) {
                Eigen::VectorXd w = u + s * t;
                const Correction rc = correct(c, w, ref, ak, ak.dot(u + s * t), o, lin_u);
                b.newton_iterations += rc.iterations;
                b.jacobians += rc.jacobians;
                if (!rc.ok) return false;
                out = make_orbit(c, w, rc, true);
                return true;
            };
            orbit_continuation::Step st;
            st.after = after;
            st.length = ak.dot(v - u);
            st.h = h;
            st.t_par = t(N + 1);
            st.tn_par = tn(N + 1);
            st.par_scale = std::abs(o.to - o.from);
            orbit_continuation::special_points(st, b.points.back(), orbit, o.floquet, "periodic orbits", probe, b);
        }
        const bool collapsed = size_next < 0.5 * amp0;
        b.points.push_back(std::move(orbit));
        report();
        if (collapsed) {  // the size fell back towards 0: the branch ends where such orbits are born (a Hopf point, a period doubling)
            b.stop = end.stop;
            return;
        }
        u = v;
        t = tn;
        lin_u = r.lin;
        // an easy step: the chord iterations converged with at most one new Jacobian besides the
        // one at the result (sparse path: at most 3 Newton steps)
        step.accept(r.lin ? r.jacobians <= 2 : r.iterations <= 3);
        if (u(N) > o.max_period_factor * T0) {
            b.stop = "period";
            return;
        }
        adapt();
    }
}

void finish(OrbitBranch& b) {
    for (const PeriodicOrbit& p : b.points) {
        b.max_residual = std::max(b.max_residual, p.residual);
        if (std::isfinite(p.trivial_distance)) b.max_trivial_distance = std::max(b.max_trivial_distance, p.trivial_distance);
    }
    if (b.message.empty()) {
        std::ostringstream s;
        s << b.points.size() << " orbits, ended: " << b.stop;
        b.message = s.str();
    }
}

/// Starts a branch off a point u0 of another solution set (an equilibrium at a Hopf point, an
/// orbit traversed twice at a period doubling) along the direction t0 (T and p components 0): the
/// first orbit corrected from u0 + initial_step t0 with the step condition along t0, then
/// followed (with `failed`, the message when the first orbit does not converge).
void branch_off(const Setup& c, const Eigen::VectorXd& u0, Eigen::VectorXd t0, const PeriodicOrbitOptions& options, const std::string& failed,
                const BranchEnd& end, OrbitBranch& b) {
    t0 /= c.norm(t0);
    Eigen::VectorXd u = u0 + options.initial_step * t0;
    const Eigen::MatrixXd ref = derivative_at_collocation(c, u);
    const Eigen::VectorXd a = c.w.cwiseProduct(t0);
    const Correction r = correct(c, u, ref, a, a.dot(u), options, nullptr);
    if (!r.ok) {
        b.status = Status::MaxIterations;
        b.stop = "first_orbit_failed";
        b.message = failed;
        b.newton_iterations = r.iterations;
        b.jacobians = r.jacobians;
        return;
    }
    const Eigen::VectorXd t = r.tangent / c.norm(r.tangent);
    follow(c, u, t, r, options, b, end);
    finish(b);
}

std::string method_text(const PeriodicMesh& mesh) {
    std::ostringstream s;
    s << "piecewise polynomial collocation, degree " << mesh.degree() << " on " << mesh.intervals()
      << " intervals at Gauss-Legendre points; Newton (chord steps) on the system condensed to the history window by a forward sweep over the intervals; pseudo-arclength; Floquet multipliers of the collocated monodromy matrix";
    return s.str();
}

}  // namespace

bool PeriodicOrbitOptions::is_valid(std::string* why) const {
    const char* w = nullptr;
    if (parameter.empty()) w = "parameter: expected a name";
    else if (!std::isfinite(from) || !std::isfinite(to) || from == to) w = "from, to: expected two different finite values";
    else if (degree < 1 || degree > 20) w = "degree: expected an integer between 1 and 20";
    else if (intervals < 2 || intervals > 100000) w = "intervals: expected an integer between 2 and 100000";
    else if (max_points < 2) w = "max_points: expected an integer >= 2";
    else if (!(min_step > 0.0 && initial_step >= min_step && max_step >= initial_step && std::isfinite(max_step)))
        w = "steps: expected 0 < min_step <= initial_step <= max_step";
    else if (max_iterations < 1) w = "max_iterations: expected an integer >= 1";
    else if (!(tolerance > 0.0) || !(residual_tolerance > 0.0)) w = "tolerance, residual_tolerance: expected values > 0";
    else if (!(max_period_factor > 1.0)) w = "max_period_factor: expected a value > 1";
    if (w && why) *why = w;
    return w == nullptr;
}

Eigen::VectorXd orbit_value(const PeriodicMesh& mesh, const Eigen::MatrixXd& profile, double s) {
    double w = s - std::floor(s);
    if (w >= 1.0) w = 0.0;
    const int l = mesh.interval_of(w), d = mesh.degree();
    std::vector<double> v(static_cast<std::size_t>(d) + 1), dv(static_cast<std::size_t>(d) + 1);
    mesh.basis(l, w, v.data(), dv.data());
    Eigen::VectorXd x = Eigen::VectorXd::Zero(profile.cols());
    for (int j = 0; j <= d; ++j) x += v[static_cast<std::size_t>(j)] * profile.row((l * d + j) % mesh.points()).transpose();
    return x;
}

OrbitGuess orbit_guess_from_samples(const PeriodicMesh& mesh, const std::vector<double>& times, const Eigen::MatrixXd& states,
                                    double period, double par) {
    if (times.size() < 2 || static_cast<Eigen::Index>(times.size()) != states.rows())
        throw std::invalid_argument("orbit guess: expected at least two samples, one state row per time");
    if (!(period > 0.0) || times.back() - times.front() < period * (1.0 - 1e-12))
        throw std::invalid_argument("orbit guess: the samples must cover one period");
    for (std::size_t i = 1; i < times.size(); ++i)
        if (!(times[i] > times[i - 1])) throw std::invalid_argument("orbit guess: expected increasing times");
    OrbitGuess g;
    g.par = par;
    g.period = period;
    g.profile.resize(mesh.points(), states.cols());
    std::size_t k = 0;
    for (int i = 0; i < mesh.points(); ++i) {
        const double t = times.front() + mesh.point(i) * period;
        while (k + 2 < times.size() && times[k + 1] < t) ++k;
        const double th = std::clamp((t - times[k]) / (times[k + 1] - times[k]), 0.0, 1.0);
        g.profile.row(i) = (1.0 - th) * states.row(static_cast<Eigen::Index>(k)) + th * states.row(static_cast<Eigen::Index>(k + 1));
    }
    return g;
}

OrbitBranch orbit_branch_from_simulation(const NonlinearDDE& system, const SimulatedOrbitGuess& g, const PeriodicOrbitOptions& options) {
    if (g.status == Status::Converged) return orbit_branch_from_guess(system, g.guess, options);
    OrbitBranch b;
    b.parameter = options.parameter;
    b.degree = options.degree;
    b.intervals = options.intervals;
    b.status = g.status;
    b.stop = "first_orbit_failed";
    b.message = "no orbit from the simulation: " + g.message;
    return b;
}

double default_simulation_step(const NonlinearDDE& system) {
    double h = 0.01;
    for (double t : system.delays())
        if (t > 0.0) h = std::min(h, 0.1 * t);
    return h;
}

SimulatedOrbitGuess orbit_guess_from_simulation(const NonlinearDDE& system, const std::string& parameter, const PeriodicMesh& mesh,
                                                const Eigen::VectorXd& history, double t_end, double step) {
    const int n = system.dimension(), m = system.delay_count();
    if (history.size() != n) throw std::invalid_argument("orbit from a simulation: expected a history of one value per variable");
    if (!history.allFinite()) throw std::invalid_argument("orbit from a simulation: expected finite history values");
    if (!(t_end > 0.0) || !std::isfinite(t_end)) throw std::invalid_argument("orbit from a simulation: expected a run time > 0");
    if (!(step > 0.0) || !(step < t_end)) throw std::invalid_argument("orbit from a simulation: expected a step > 0 below the run time");
    const int j = system.parameter_index(parameter);  // throws for an unknown name
    const std::vector<double> tau = system.delays();
    SimulatedOrbitGuess r;
    bool finite = true;
    DdeSolver sol(n, 0.0, [&history](double, double* y) { Eigen::Map<Eigen::VectorXd>(y, history.size()) = history; },
                  [&](double t, const double* y, const DdeSolver& sv, double* dy) {
                      Eigen::VectorXd u(static_cast<Eigen::Index>(n) * (m + 1));
                      for (int i = 0; i < n; ++i) u(i) = y[i];
                      for (int k = 0; k < m; ++k)
                          for (int i = 0; i < n; ++i) u((k + 1) * n + i) = sv.value(i, t - tau[static_cast<std::size_t>(k)]);
                      const Eigen::VectorXd f = system.f(u);
                      for (int i = 0; i < n; ++i) dy[i] = f(i);
                  });
    sol.integrate(t_end, step, {}, [&finite](const DdeSolver& sv) {
        for (int i = 0; i < sv.dimension(); ++i)
            if (!std::isfinite(sv.state()[i]) || std::abs(sv.state()[i]) > 1e100) return finite = false;
        return true;
    });
    if (!finite) {
        r.message = "the simulation left the finite numbers at t = " + detail::format_number(sol.time()) + " (a smaller step, or another history)";
        return r;
    }
    // the last third: the mean level of the first variable and its upward crossings
    const double t0 = t_end * 2.0 / 3.0, dt = step;
    double lo = 1e300, hi = -1e300, sum = 0.0;
    long count = 0;
    for (double t = t0; t <= t_end; t += dt) {
        const double x = sol.value(0, t);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        sum += x;
        ++count;
    }
    r.amplitude = hi - lo;
    const double level = sum / static_cast<double>(count);
    if (!(r.amplitude > 1e-6 * std::max(1.0, std::abs(level)))) {
        r.message = "the simulation settled on an equilibrium (the first variable varies by " + detail::significant(r.amplitude, 2) +
                    " over the last third of the run): another history or parameter value";
        return r;
    }
    std::vector<double> up;
    for (double t = t0; t + dt <= t_end; t += dt) {
        double a = t, b = t + dt;
        if (!(sol.value(0, a) < level && sol.value(0, b) >= level)) continue;
        for (int it = 0; it < 60; ++it) {
            const double mid = 0.5 * (a + b);
            (sol.value(0, mid) < level ? a : b) = mid;
        }
        up.push_back(0.5 * (a + b));
    }
    for (int k = 1; k <= 8 && r.crossings_per_period == 0; ++k) {
        if (static_cast<int>(up.size()) < 2 * k + 1) break;
        double mean = 0.0;
        const std::size_t uk = static_cast<std::size_t>(k);
        for (std::size_t i = uk; i < up.size(); ++i) mean += up[i] - up[i - uk];
        mean /= static_cast<double>(up.size() - uk);
        double spread = 0.0;
        for (std::size_t i = uk; i < up.size(); ++i) spread = std::max(spread, std::abs(up[i] - up[i - uk] - mean) / mean);
        if (spread <= 1e-3) {
            r.crossings_per_period = k;
            r.period = mean;
            r.period_spread = spread;
        } else if (k == 1) {
            r.period_spread = spread;
        }
    }
    if (r.crossings_per_period == 0) {
        r.message = up.size() < 3 ? "the simulation crossed its mean level " + std::to_string(up.size()) +
                                        " times over the last third of the run: a longer run time"
                                  : "the simulation did not settle on a periodic orbit (the times between crossings of the mean level vary by " +
                                        detail::significant(r.period_spread * 100.0, 2) + " %, more than 0.1 %): a longer run time, or another history";
        return r;
    }
    // one period ending at the last crossing, sampled at 16 points per mesh point
    const double t1 = up.back(), ts = t1 - r.period;
    const int samples = 16 * mesh.points();
    std::vector<double> times;
    Eigen::MatrixXd states(samples + 1, n);
    for (int i = 0; i <= samples; ++i) {
        const double t = ts + r.period * i / samples;
        times.push_back(t);
        for (int v = 0; v < n; ++v) states(i, v) = sol.value(v, t);
    }
    r.guess = orbit_guess_from_samples(mesh, times, states, r.period, system.parameter_values()[static_cast<std::size_t>(j)]);
    r.status = Status::Converged;
    std::ostringstream msg;
    msg << "settled on an orbit of period " << detail::significant(r.period, 8) << " (repeats to " << detail::significant(r.period_spread, 2) << ")";
    r.message = msg.str();
    return r;
}

std::vector<cplx> orbit_multipliers(const NonlinearDDE& system, const std::string& parameter, const PeriodicMesh& mesh,
                                    const Eigen::MatrixXd& profile, double period, double par) {
    if (profile.rows() != mesh.points() || profile.cols() != system.dimension())
        throw std::invalid_argument("orbit multipliers: expected a profile of (degree x intervals) rows and one column per variable");
    if (!(period > 0.0) || !std::isfinite(period)) throw std::invalid_argument("orbit multipliers: expected a period > 0");
    Setup c(system, mesh);
    c.n = system.dimension();
    c.m = system.delay_count();
    c.j = system.parameter_index(parameter);
    c.d = mesh.degree();
    c.L = mesh.intervals();
    c.P = mesh.points();
    c.base = system.parameter_values();
    Eigen::VectorXd u(c.N() + 2);
    for (int i = 0; i < c.P; ++i) u.segment(static_cast<Eigen::Index>(i) * c.n, c.n) = profile.row(i).transpose();
    u(c.N()) = period;
    u(c.N() + 1) = par;
    std::vector<cplx> out;
    if (!multipliers(c, u, out)) out.clear();
    return out;
}

OrbitBranch orbit_branch_from_hopf(const NonlinearDDE& system, const HopfPoint& hopf, const PeriodicOrbitOptions& options) {
    const SingleThreadedEigen single;
    if (!(hopf.omega > 0.0) || !std::isfinite(hopf.omega)) throw std::invalid_argument("orbits from a Hopf point: expected omega > 0");
    if (hopf.q.size() != system.dimension() || hopf.x.size() != system.dimension())
        throw std::invalid_argument("orbits from a Hopf point: x and q must have the system's dimension");
    const PeriodicMesh mesh(options.degree, options.intervals);
    const double T0 = 2.0 * kPi / hopf.omega;
    const Setup c = make_setup(system, mesh, options, T0);
    const int N = c.N();
    OrbitBranch b;
    b.parameter = options.parameter;
    b.degree = options.degree;
    b.intervals = options.intervals;
    b.method = method_text(mesh);
    const VectorXc q = hopf.q / hopf.q.norm();
    Eigen::VectorXd uh(N + 2), t0(N + 2);
    for (int i = 0; i < c.P; ++i) {
        const cplx e = std::exp(cplx(0.0, 2.0 * kPi * mesh.point(i)));
        uh.segment(static_cast<Eigen::Index>(i) * c.n, c.n) = hopf.x;
        t0.segment(static_cast<Eigen::Index>(i) * c.n, c.n) = (q * e).real();
    }
    uh(N) = T0;
    uh(N + 1) = hopf.par;
    t0(N) = t0(N + 1) = 0.0;
    branch_off(c, uh, t0, options, "the first orbit from the Hopf point did not converge (try a smaller initial step or a finer mesh)", hopf_end(), b);
    return b;
}

OrbitBranch orbit_branch_from_guess(const NonlinearDDE& system, const OrbitGuess& guess, const PeriodicOrbitOptions& options) {
    const SingleThreadedEigen single;
    const PeriodicMesh mesh(options.degree, options.intervals);
    if (guess.profile.rows() != mesh.points() || guess.profile.cols() != system.dimension())
        throw std::invalid_argument("orbit guess: expected a profile of (degree x intervals) rows and one column per variable");
    if (!(guess.period > 0.0)) throw std::invalid_argument("orbit guess: expected a period > 0");
    const Setup c = make_setup(system, mesh, options, guess.period);
    const int N = c.N();
    OrbitBranch b;
    b.parameter = options.parameter;
    b.degree = options.degree;
    b.intervals = options.intervals;
    b.method = method_text(mesh);
    Eigen::VectorXd u(N + 2);
    for (int i = 0; i < c.P; ++i) u.segment(static_cast<Eigen::Index>(i) * c.n, c.n) = guess.profile.row(i).transpose();
    u(N) = guess.period;
    u(N + 1) = guess.par;
    const Eigen::MatrixXd ref = derivative_at_collocation(c, u);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 2);
    e(N + 1) = 1.0;
    const Correction r = correct(c, u, ref, e, guess.par, options, nullptr);
    if (!r.ok) {
        b.status = Status::MaxIterations;
        b.stop = "first_orbit_failed";
        b.message = "the orbit did not converge from the guess";
        b.newton_iterations = r.iterations;
        return b;
    }
    {
        const PeriodicOrbit first = make_orbit(c, u, r, false);
        if (!(amplitude(first) > 1e-6 * std::max(1.0, first.max.cwiseAbs().maxCoeff()))) {
            b.status = Status::NumericalIssue;
            b.stop = "first_orbit_failed";
            b.message = "the guess converged to an equilibrium, not a periodic orbit";
            b.newton_iterations = r.iterations;
            return b;
        }
    }
    Eigen::VectorXd t = r.tangent / c.norm(r.tangent);
    if ((t(N + 1) < 0.0) != (options.to < options.from)) t = -t;
    follow(c, u, t, r, options, b);
    finish(b);
    return b;
}

OrbitBranch orbit_branch_from_period_doubling(const NonlinearDDE& system, const OrbitCrossing& pd, const PeriodicOrbitOptions& options) {
    const SingleThreadedEigen single;
    const PeriodicOrbit& o = pd.orbit;
    if (!pd.located || o.profile.rows() == 0 || o.breakpoints.size() < 3)
        throw std::invalid_argument("orbits from a period doubling: expected a located period doubling with its orbit");
    if (!(std::abs(pd.multiplier.imag()) <= 1e-6) || !(std::abs(pd.multiplier.real() + 1.0) <= 1e-3))
        throw std::invalid_argument("orbits from a period doubling: expected its crossing multiplier real and near -1");
    if (o.profile.cols() != system.dimension() || !(o.period > 0.0))
        throw std::invalid_argument("orbits from a period doubling: the orbit must have the system's dimension and a period > 0");
    const int L = static_cast<int>(o.breakpoints.size()) - 1;
    if (o.profile.rows() % L != 0) throw std::invalid_argument("orbits from a period doubling: the orbit's profile does not fit its mesh");
    const int d = static_cast<int>(o.profile.rows() / L);
    const PeriodicMesh mesh(d, o.breakpoints);
    const Setup c1 = make_setup(system, mesh, options, o.period);
    const int N1 = c1.N(), n = c1.n, P = c1.P;
    Eigen::VectorXd u1(N1 + 2);
    for (int i = 0; i < P; ++i) u1.segment(static_cast<Eigen::Index>(i) * n, n) = o.profile.row(i).transpose();
    u1(N1) = o.period;
    u1(N1 + 1) = o.par;
    // the doubled mesh: the orbit's mesh on [0, 1/2] and again on [1/2, 1]
    std::vector<double> bp;
    for (int i = 0; i <= L; ++i) bp.push_back(0.5 * o.breakpoints[static_cast<std::size_t>(i)]);
    for (int i = 1; i <= L; ++i) bp.push_back(0.5 + 0.5 * o.breakpoints[static_cast<std::size_t>(i)]);
    bp.back() = 1.0;
    const PeriodicMesh mesh2(d, bp);
    const Setup c = make_setup(system, mesh2, options, 2.0 * o.period);
    const int N = c.N();
    OrbitBranch b;
    b.parameter = options.parameter;
    b.degree = d;
    b.intervals = 2 * L;
    b.method = method_text(mesh2) + "; started from the period doubling at " + options.parameter + " = " + detail::format_number(o.par) +
               " along the Floquet eigenfunction of its multiplier -1 (the orbit traversed twice)";
    // the eigenfunction: the eigenvector v of the monodromy matrix for mu (inverse iteration on
    // M - mu I), continued over the period by the collocated variational equation, y = Y v
    Linearization lz;
    if (linearize(c1, u1, lz) != LinStatus::ok) {
        b.status = Status::NumericalIssue;
        b.stop = "first_orbit_failed";
        b.message = "the Floquet eigenfunction of the period doubling was not computed (its history window is above 4000 values or the collocation matrix is singular)";
        return b;
    }
    const int H = lz.H;
    Eigen::MatrixXd mono = Eigen::MatrixXd::Zero(H, H);
    for (long h = 0; h < lz.nh; ++h) {
        const long g = lz.gmin + h + P;
        if (g <= 0) mono.block(h * n, (g - lz.gmin) * n, n, n).setIdentity();
        else mono.middleRows(h * n, n) = lz.Y.block((g - 1) * n, 0, n, H);
    }
    const double mu = pd.multiplier.real();
    Eigen::MatrixXd shifted = mono;
    shifted.diagonal().array() -= mu;
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(shifted);
    Eigen::VectorXd v = Eigen::VectorXd::Ones(H);
    for (int it = 0; it < 4; ++it) {
        v = lu.solve(v);
        v /= v.norm();
    }
    const double eig_residual = (mono * v - mu * v).norm();
    if (!v.allFinite() || !(eig_residual <= 1e-6 * std::max(1.0, mono.lpNorm<Eigen::Infinity>()))) {
        b.status = Status::NumericalIssue;
        b.stop = "first_orbit_failed";
        b.message = "the Floquet eigenvector of the multiplier " + detail::format_number(mu) + " did not converge (residual " + detail::significant(eig_residual, 3) + ")";
        return b;
    }
    const Eigen::VectorXd y = lz.Y.leftCols(H) * v;  // the values at the points 1..P of the period (M1 order)
    Eigen::MatrixXd yp(P, n);
    yp.row(0) = v.segment(-lz.gmin * n, n).transpose();  // point 0 is the window's last point
    for (int q = 1; q < P; ++q) yp.row(q) = y.segment(static_cast<Eigen::Index>(q - 1) * n, n).transpose();
    Eigen::VectorXd u0(N + 2), t0(N + 2);
    for (int q = 0; q < 2 * P; ++q) {
        u0.segment(static_cast<Eigen::Index>(q) * n, n) = o.profile.row(q % P).transpose();
        // y(s + 1) = mu y(s) on the second period: the direction is 2-periodic
        t0.segment(static_cast<Eigen::Index>(q) * n, n) = (q < P ? 1.0 : mu) * yp.row(q % P).transpose();
    }
    u0(N) = 2.0 * o.period;
    u0(N + 1) = o.par;
    t0(N) = t0(N + 1) = 0.0;
    branch_off(c, u0, t0, options, "the first orbit of twice the period did not converge from the period doubling (try a smaller initial step)",
               BranchEnd{half_period_distance, "period_doubling"}, b);
    return b;
}

// ---------------------------------------------------------------------------------------------
// Curves of folds of periodic orbits in two parameters (the header's orbit_fold_curve)

namespace {

/// The problem in two parameters on one mesh: c1 continues in p1 (its column of df/dp), c2 in
/// p2; each base holds the other parameter's current value. z = (X, T, p1, p2).
struct FoldSystem {
    FoldSystem(const Setup& a, const Setup& b) : c1(a), c2(b) {}
    Setup c1, c2;
    int N = 0;
    Eigen::VectorXd w;  // weights of the norm (N + 3)
    double norm(const Eigen::VectorXd& v) const { return std::sqrt((w.array() * v.array().square()).sum()); }
    /// (X, T, p1) of z, for the functions of one parameter; c1's base set to z's p2
    Eigen::VectorXd orbit_part(const Eigen::VectorXd& z) {
        c1.base[static_cast<std::size_t>(c2.j)] = z(N + 2);
        return z.head(N + 2);
    }
};

/// F(z) (N + 1: collocation and phase) and with J its Jacobian in (X, T, p1, p2), (N + 1) x (N + 3).
bool fold_assemble(FoldSystem& fs, const Eigen::VectorXd& z, const Eigen::MatrixXd& ref, Eigen::VectorXd& F, SpD* J) {
    const int N = fs.N;
    const Eigen::VectorXd u1 = fs.orbit_part(z);
    if (!J) return assemble(fs.c1, u1, ref, nullptr, 0.0, F, nullptr);
    SpD J1, J2;
    if (!assemble(fs.c1, u1, ref, nullptr, 0.0, F, &J1)) return false;
    fs.c2.base[static_cast<std::size_t>(fs.c1.j)] = z(N + 1);
    Eigen::VectorXd u2(N + 2), F2;
    u2.head(N + 1) = z.head(N + 1);
    u2(N + 1) = z(N + 2);
    if (!assemble(fs.c2, u2, ref, nullptr, 0.0, F2, &J2)) return false;
    std::vector<Triplet> t;
    t.reserve(static_cast<std::size_t>(J1.nonZeros()) + static_cast<std::size_t>(N) + 1);
    for (int k = 0; k < J1.outerSize(); ++k)
        for (SpD::InnerIterator it(J1, k); it; ++it)
            if (it.row() <= N) t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
    for (SpD::InnerIterator it(J2, N + 1); it; ++it)
        if (it.row() <= N) t.emplace_back(static_cast<int>(it.row()), N + 2, it.value());
    J->resize(N + 1, N + 3);
    J->setFromTriplets(t.begin(), t.end());
    return true;
}

/// The fold test of the bordered system (see the header): v, g from [A b; c^T 0] [v; g] = [0; 1]
/// and w from the transposed system, A = D_(X,T) [F; phase] (J's first N + 1 columns).
struct FoldTest {
    Eigen::VectorXd v, w;
    double g = std::numeric_limits<double>::quiet_NaN();
};
bool fold_test(const SpD& J, const Eigen::VectorXd& b, const Eigen::VectorXd& c, FoldTest& out) {
    const int M = static_cast<int>(J.rows());  // N + 1
    std::vector<Triplet> t;
    t.reserve(static_cast<std::size_t>(J.nonZeros()) + 2 * static_cast<std::size_t>(M));
    for (int k = 0; k < M; ++k)
        for (SpD::InnerIterator it(J, k); it; ++it) t.emplace_back(static_cast<int>(it.row()), k, it.value());
    for (int i = 0; i < M; ++i) {
        if (b(i) != 0.0) t.emplace_back(i, M, b(i));
        if (c(i) != 0.0) t.emplace_back(M, i, c(i));
    }
    SpD B(M + 1, M + 1);
    B.setFromTriplets(t.begin(), t.end());
    B.makeCompressed();
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(B);
    if (lu.info() != Eigen::Success) return false;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(M + 1);
    e(M) = 1.0;
    const Eigen::VectorXd x = lu.solve(e);
    const Eigen::VectorXd y = lu.transpose().solve(e);
    if (!x.allFinite() || !y.allFinite()) return false;
    out.v = x.head(M);
    out.g = x(M);
    out.w = y.head(M);
    return true;
}

/// The period-doubling test. `fd` is the problem on the mesh traversed twice (2 L intervals, the
/// unknowns (X, X, 2T, p1, p2) of the orbit traversed twice, z2 below). A -1 multiplier of the
/// orbit is a 1 of the doubled orbit with an antiperiodic eigenfunction (v, -v); the Jacobian A2
/// of the doubled collocation equations in its profile maps (v, -v) to (A_pd v, -A_pd v), with
///     A_pd = A2[first half rows, first half columns] - A2[first half rows, second half columns],
/// the collocated variational operator with the antiperiodic wrap y(s + 1) = -y(s). The bordered
/// [A_pd b; c^T 0] [v; g] = [0; 1] gives g (0 exactly at a multiplier -1). Its gradient
/// g_z = -w^T A_pd,z v is half the gradient of (w, -w)^T A2 (v, -v) summed over the two copies
/// of X (and twice the 2T component), and that one is the central difference of A2's transpose
/// times (w, -w) along (v, -v), a direction in which the doubled orbit stays 2T-periodic.
Eigen::VectorXd doubled_point(const Eigen::VectorXd& z, int N) {
    Eigen::VectorXd z2(2 * N + 3);
    z2.head(N) = z.head(N);
    z2.segment(N, N) = z.head(N);
    z2(2 * N) = 2.0 * z(N);
    z2(2 * N + 1) = z(N + 1);
    z2(2 * N + 2) = z(N + 2);
    return z2;
}

/// A_pd (N x N) from the doubled Jacobian J2 ((2N + 1) x (2N + 3)).
SpD antiperiodic_block(const SpD& J2, int N) {
    std::vector<Triplet> t;
    for (int k = 0; k < 2 * N; ++k)
        for (SpD::InnerIterator it(J2, k); it; ++it)
            if (it.row() < N) t.emplace_back(static_cast<int>(it.row()), k < N ? k : k - N, k < N ? it.value() : -it.value());
    SpD A(N, N);
    A.setFromTriplets(t.begin(), t.end());
    return A;
}

struct FoldCorrection {
    bool ok = false;
    int iterations = 0;
    double residual = std::numeric_limits<double>::infinity();  // max |F|
    double test = std::numeric_limits<double>::infinity();      // |g|
    Eigen::VectorXd tangent;  // the extended Jacobian's inverse times e_last (not normalised)
    FoldTest fold;            // at the result
};

/// Newton on [F; g; a . z - beta] = 0 in z = (X, T, p1, p2), a sparse LU of the extended
/// Jacobian every step; g's row by the central difference of the header.
/// With `doubled` (the problem on the mesh traversed twice, see antiperiodic_block) the condition
/// is the period doubling's instead of the fold's.
FoldCorrection correct_fold(FoldSystem& fs, Eigen::VectorXd& z, const Eigen::MatrixXd& ref, const Eigen::VectorXd& b, const Eigen::VectorXd& c,
                            const Eigen::VectorXd& a, double beta, const PeriodicOrbitOptions& o, FoldSystem* doubled = nullptr) {
    const int N = fs.N;
    FoldCorrection r;
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    bool factored = false;
    double last_step = std::numeric_limits<double>::infinity();
    Eigen::VectorXd F, Fp, Fm;
    SpD J, Jp, Jm;
    const Eigen::MatrixXd ref2 = doubled ? Eigen::MatrixXd::Zero(doubled->c1.P, doubled->c1.n) : Eigen::MatrixXd();  // (its phase row is not used)
    for (int it = 0; it <= o.max_iterations; ++it) {
        if (!fold_assemble(fs, z, ref, F, &J)) return r;
        FoldTest ft;
        SpD J2;
        if (doubled) {
            Eigen::VectorXd F2;
            if (!fold_assemble(*doubled, doubled_point(z, N), ref2, F2, &J2) || !fold_test(antiperiodic_block(J2, N), b, c, ft)) return r;
        } else if (!fold_test(J, b, c, ft)) {
            return r;
        }
        r.residual = F.lpNorm<Eigen::Infinity>();
        r.test = std::abs(ft.g);
        r.fold = ft;
        if (it > 0 && last_step <= o.tolerance * std::max(1.0, z.lpNorm<Eigen::Infinity>())) {
            r.ok = r.residual <= o.residual_tolerance && factored;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 3);
            e(N + 2) = 1.0;
            r.tangent = lu.solve(e);  // one step earlier: an O(|dz|) difference in a normalised direction
            if (!r.tangent.allFinite()) r.ok = false;
            return r;
        }
        if (it == o.max_iterations) break;
        // g_z = -w^T A_z v, A_z v by the central difference of J^T w along v (the (X, T) part)
        const double vmax = ft.v.lpNorm<Eigen::Infinity>();
        if (!(vmax > 0.0)) return r;
        const double eps = 1e-5 * std::max(1.0, z.head(N + 1).lpNorm<Eigen::Infinity>()) / vmax;
        Eigen::VectorXd grad;
        if (doubled) {
            Eigen::VectorXd z2 = doubled_point(z, N), v2 = Eigen::VectorXd::Zero(2 * N + 3), w2 = Eigen::VectorXd::Zero(2 * N + 1);
            v2.head(N) = ft.v;
            v2.segment(N, N) = -ft.v;
            w2.head(N) = ft.w;
            w2.segment(N, N) = -ft.w;
            const Eigen::VectorXd zp = z2 + eps * v2, zm = z2 - eps * v2;
            if (!fold_assemble(*doubled, zp, ref2, Fp, &Jp) || !fold_assemble(*doubled, zm, ref2, Fm, &Jm)) return r;
            const Eigen::VectorXd d = ((Jp.transpose() * w2) - (Jm.transpose() * w2)) / (2.0 * eps);
            grad.resize(N + 3);
            grad.head(N) = -0.5 * (d.head(N) + d.segment(N, N));
            grad(N) = -0.5 * 2.0 * d(2 * N);
            grad(N + 1) = -0.5 * d(2 * N + 1);
            grad(N + 2) = -0.5 * d(2 * N + 2);
        } else {
            Eigen::VectorXd zp = z, zm = z;
            zp.head(N + 1) += eps * ft.v;
            zm.head(N + 1) -= eps * ft.v;
            if (!fold_assemble(fs, zp, ref, Fp, &Jp) || !fold_assemble(fs, zm, ref, Fm, &Jm)) return r;
            grad = -((Jp.transpose() * ft.w) - (Jm.transpose() * ft.w)) / (2.0 * eps);
        }
        std::vector<Triplet> t;
        t.reserve(static_cast<std::size_t>(J.nonZeros()) + 2 * static_cast<std::size_t>(N + 3));
        for (int k = 0; k < J.outerSize(); ++k)
            for (SpD::InnerIterator q(J, k); q; ++q) t.emplace_back(static_cast<int>(q.row()), k, q.value());
        for (int k = 0; k < N + 3; ++k) {
            if (grad(k) != 0.0) t.emplace_back(N + 1, k, grad(k));
            if (a(k) != 0.0) t.emplace_back(N + 2, k, a(k));
        }
        SpD E(N + 3, N + 3);
        E.setFromTriplets(t.begin(), t.end());
        E.makeCompressed();
        lu.compute(E);
        if (lu.info() != Eigen::Success) return r;
        factored = true;
        Eigen::VectorXd rhs(N + 3);
        rhs.head(N + 1) = F;
        rhs(N + 1) = ft.g;
        rhs(N + 2) = a.dot(z) - beta;
        const Eigen::VectorXd dz = lu.solve(rhs);
        if (!dz.allFinite()) return r;
        z -= dz;
        ++r.iterations;
        last_step = dz.lpNorm<Eigen::Infinity>();
    }
    return r;
}

using VectorXcd = Eigen::VectorXcd;
using SpC = Eigen::SparseMatrix<std::complex<double>>;

/// The torus condition. A multiplier mu = e^{i phi} of the orbit is one whose Floquet
/// eigenfunction wraps as y(s + 1) = mu y(s): the collocated variational operator with that wrap,
///     A_mu = sum_q mu^q A^(q),
/// A^(q) the part of the Jacobian of the collocation equations (in the profile) whose values lie q
/// periods after the collocation point's (q = 1: the end point of the last interval; q < 0: the
/// delayed values, q >= -ceil(tau_max / T)). On the mesh traversed M = ceil(tau_max / T) + 2 times
/// these parts are separate column blocks of the first copy's rows: copy 0 (q = 0), copy 1
/// (q = 1), copy j >= 2 (q = j - M). The bordered [A_mu b; c^H 0] [v; g] = [0; 1] gives the
/// complex g, zero exactly where mu is a multiplier; with w from the adjoint system
/// g_z = -w^H A_mu,z v and g_phi = -w^H (sum_q i q mu^q A^(q)) v. A_mu,z v is the derivative of the
/// M-fold Jacobian's first-copy rows along the M-fold direction V = (mu^q(j) v)_j, and by the
/// symmetry of second derivatives w^H (d_e J) V = w^H (d_V J) E for the M-fold lift E of e: the
/// central difference of J^T conj(w) along Re V and Im V, summed back over the copies.
struct TorusCondition {
    TorusCondition(const NonlinearDDE& s, const PeriodicOrbitOptions& a, const PeriodicOrbitOptions& b, int n) : sys(s), o1(a), o2(b), N(n) {}
    const NonlinearDDE& sys;
    PeriodicOrbitOptions o1, o2;
    int N;
    struct Copies {
        std::unique_ptr<PeriodicMesh> mesh;
        std::unique_ptr<FoldSystem> fs;
    };
    std::map<int, Copies> cache;
    /// M for the point z = (X, T, p1, p2, phi); 0 when the delays are not defined there
    int copies(const FoldSystem& fs, const Eigen::VectorXd& z) const {
        std::vector<double> pv = fs.c1.base;
        pv[static_cast<std::size_t>(fs.c1.j)] = z(N + 1);
        pv[static_cast<std::size_t>(fs.c2.j)] = z(N + 2);
        double tmax = 0.0;
        try {
            for (const double t : sys.delays(pv)) tmax = std::max(tmax, t);
        } catch (const std::exception&) {
            return 0;
        }
        if (!(z(N) > 0.0) || !std::isfinite(tmax)) return 0;
        return static_cast<int>(std::ceil(tmax / z(N))) + 2;
    }
    FoldSystem* get(int M, const FoldSystem& one) {
        Copies& c = cache[M];
        if (!c.fs) {
            c.mesh = std::make_unique<PeriodicMesh>(one.c1.d, M * one.c1.L);
            c.fs = std::make_unique<FoldSystem>(make_setup(sys, *c.mesh, o1, M), make_setup(sys, *c.mesh, o2, M));
            c.fs->N = M * N;
            c.fs->w = Eigen::VectorXd::Ones(M * N + 3);
        }
        return c.fs.get();
    }
};

/// (X, ..., X, M T, p1, p2): the orbit z traversed M times.
Eigen::VectorXd repeated_point(const Eigen::VectorXd& z, int N, int M) {
    Eigen::VectorXd zm(M * N + 3);
    for (int j = 0; j < M; ++j) zm.segment(static_cast<Eigen::Index>(j) * N, N) = z.head(N);
    zm(M * N) = M * z(N);
    zm(M * N + 1) = z(N + 1);
    zm(M * N + 2) = z(N + 2);
    return zm;
}

/// mu^q of copy j of M (see TorusCondition), and its derivative in phi (mu = e^{i phi}).
std::complex<double> copy_factor(int j, int M, std::complex<double> mu, bool d_phi = false) {
    const int q = j == 0 ? 0 : (j == 1 ? 1 : j - M);
    const std::complex<double> f = std::pow(mu, q);
    return d_phi ? std::complex<double>(0.0, q) * f : f;
}

/// A_mu (or its phi derivative) from the M-fold Jacobian JM.
SpC floquet_operator(const SpD& JM, int N, int M, std::complex<double> mu, bool d_phi) {
    std::vector<Eigen::Triplet<std::complex<double>>> t;
    t.reserve(static_cast<std::size_t>(JM.nonZeros()) / static_cast<std::size_t>(M) + 16);
    for (int k = 0; k < M * N; ++k) {
        const int j = k / N;
        const std::complex<double> f = copy_factor(j, M, mu, d_phi);
        if (f == 0.0) continue;
        for (SpD::InnerIterator it(JM, k); it; ++it)
            if (it.row() < N) t.emplace_back(static_cast<int>(it.row()), k - j * N, f * it.value());
    }
    SpC A(N, N);
    A.setFromTriplets(t.begin(), t.end());
    return A;
}

struct TorusTest {
    VectorXcd v, w;
    std::complex<double> g{std::numeric_limits<double>::quiet_NaN(), 0.0};
};

/// v, g from [A b; c^H 0] [v; g] = [0; 1] and w from the adjoint system.
bool torus_test(const SpC& A, const VectorXcd& b, const VectorXcd& c, TorusTest& out) {
    const int M = static_cast<int>(A.rows());
    std::vector<Eigen::Triplet<std::complex<double>>> t;
    t.reserve(static_cast<std::size_t>(A.nonZeros()) + 2 * static_cast<std::size_t>(M));
    for (int k = 0; k < M; ++k)
        for (SpC::InnerIterator it(A, k); it; ++it) t.emplace_back(static_cast<int>(it.row()), k, it.value());
    for (int i = 0; i < M; ++i) {
        if (b(i) != 0.0) t.emplace_back(i, M, b(i));
        if (c(i) != 0.0) t.emplace_back(M, i, std::conj(c(i)));
    }
    SpC K(M + 1, M + 1);
    K.setFromTriplets(t.begin(), t.end());
    K.makeCompressed();
    Eigen::SparseLU<SpC, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(K);
    if (lu.info() != Eigen::Success) return false;
    VectorXcd e = VectorXcd::Zero(M + 1);
    e(M) = 1.0;
    const VectorXcd x = lu.solve(e);
    const VectorXcd y = lu.adjoint().solve(e);
    if (!x.allFinite() || !y.allFinite()) return false;
    out.v = x.head(M);
    out.g = x(M);
    out.w = y.head(M);
    return true;
}

/// The torus test at y = (X, T, p1, p2, phi) and, with `grad`, its gradient (2 rows: Re g, Im g).
bool torus_at(TorusCondition& tc, FoldSystem& fs, const Eigen::VectorXd& y, const VectorXcd& b, const VectorXcd& c, TorusTest& out,
              Eigen::MatrixXd* grad) {
    const int N = fs.N;
    const int M = tc.copies(fs, y);
    if (M < 2) return false;
    FoldSystem& fm = *tc.get(M, fs);
    const std::complex<double> mu = std::polar(1.0, y(N + 3));
    const Eigen::MatrixXd ref = Eigen::MatrixXd::Zero(fm.c1.P, fm.c1.n);  // (its phase row is not used)
    const Eigen::VectorXd Z = repeated_point(y, N, M);
    Eigen::VectorXd F;
    SpD JM;
    if (!fold_assemble(fm, Z, ref, F, &JM) || !torus_test(floquet_operator(JM, N, M, mu, false), b, c, out)) return false;
    if (!grad) return true;
    // g_phi
    const std::complex<double> gphi = -out.w.dot(floquet_operator(JM, N, M, mu, true) * out.v);  // dot: w^H (.)
    // g_z by the central differences of J^T conj(w) along Re V and Im V
    VectorXcd V = VectorXcd::Zero(M * N + 3);
    for (int j = 0; j < M; ++j) V.segment(static_cast<Eigen::Index>(j) * N, N) = copy_factor(j, M, mu) * out.v;
    Eigen::VectorXd Wr = Eigen::VectorXd::Zero(M * N + 1), Wi = Eigen::VectorXd::Zero(M * N + 1);
    Wr.head(N) = out.w.real();
    Wi.head(N) = -out.w.imag();  // conj(w)
    const double vmax = V.cwiseAbs().maxCoeff();
    if (!(vmax > 0.0)) return false;
    const double eps = 1e-5 * std::max(1.0, y.head(N + 1).lpNorm<Eigen::Infinity>()) / vmax;
    VectorXcd gz = VectorXcd::Zero(M * N + 3);
    for (int part = 0; part < 2; ++part) {
        const Eigen::VectorXd dir = part == 0 ? Eigen::VectorXd(V.real()) : Eigen::VectorXd(V.imag());
        if (dir.isZero(0.0)) continue;
        Eigen::VectorXd Fp, Fm;
        SpD Jp, Jm;
        if (!fold_assemble(fm, Z + eps * dir, ref, Fp, &Jp) || !fold_assemble(fm, Z - eps * dir, ref, Fm, &Jm)) return false;
        const Eigen::VectorXd dr = (Jp.transpose() * Wr - Jm.transpose() * Wr) / (2.0 * eps);
        const Eigen::VectorXd di = (Jp.transpose() * Wi - Jm.transpose() * Wi) / (2.0 * eps);
        const std::complex<double> unit = part == 0 ? std::complex<double>(1.0, 0.0) : std::complex<double>(0.0, 1.0);
        gz -= unit * (dr.cast<std::complex<double>>() + std::complex<double>(0.0, 1.0) * di.cast<std::complex<double>>());
    }
    VectorXcd g(N + 4);
    g.head(N).setZero();
    for (int j = 0; j < M; ++j) g.head(N) += gz.segment(static_cast<Eigen::Index>(j) * N, N);
    g(N) = static_cast<double>(M) * gz(M * N);
    g(N + 1) = gz(M * N + 1);
    g(N + 2) = gz(M * N + 2);
    g(N + 3) = gphi;
    grad->resize(2, N + 4);
    grad->row(0) = g.real().transpose();
    grad->row(1) = g.imag().transpose();
    return true;
}

/// Newton on [F; Re g; Im g; a . y - beta] = 0 in y = (X, T, p1, p2, phi) (the torus condition
/// appended), as correct_fold.
FoldCorrection correct_torus(FoldSystem& fs, TorusCondition& tc, Eigen::VectorXd& y, const Eigen::MatrixXd& ref, const VectorXcd& b,
                             const VectorXcd& c, const Eigen::VectorXd& a, double beta, const PeriodicOrbitOptions& o, TorusTest& last) {
    const int N = fs.N;
    FoldCorrection r;
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    bool factored = false;
    double last_step = std::numeric_limits<double>::infinity();
    Eigen::VectorXd F;
    SpD J;
    Eigen::MatrixXd grad;
    for (int it = 0; it <= o.max_iterations; ++it) {
        TorusTest tt;
        const bool want = !(it > 0 && last_step <= o.tolerance * std::max(1.0, y.lpNorm<Eigen::Infinity>()));
        if (!fold_assemble(fs, y, ref, F, &J) || !torus_at(tc, fs, y, b, c, tt, want && it < o.max_iterations ? &grad : nullptr)) return r;
        r.residual = F.lpNorm<Eigen::Infinity>();
        r.test = std::abs(tt.g);
        last = tt;
        if (!want) {
            r.ok = r.residual <= o.residual_tolerance && factored;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 4);
            e(N + 3) = 1.0;
            r.tangent = lu.solve(e);
            if (!r.tangent.allFinite()) r.ok = false;
            return r;
        }
        if (it == o.max_iterations) break;
        std::vector<Triplet> t;
        t.reserve(static_cast<std::size_t>(J.nonZeros()) + 3 * static_cast<std::size_t>(N + 4));
        for (int k = 0; k < J.outerSize(); ++k)
            for (SpD::InnerIterator q(J, k); q; ++q) t.emplace_back(static_cast<int>(q.row()), k, q.value());
        for (int k = 0; k < N + 4; ++k) {
            if (grad(0, k) != 0.0) t.emplace_back(N + 1, k, grad(0, k));
            if (grad(1, k) != 0.0) t.emplace_back(N + 2, k, grad(1, k));
            if (a(k) != 0.0) t.emplace_back(N + 3, k, a(k));
        }
        SpD E(N + 4, N + 4);
        E.setFromTriplets(t.begin(), t.end());
        E.makeCompressed();
        lu.compute(E);
        if (lu.info() != Eigen::Success) return r;
        factored = true;
        Eigen::VectorXd rhs(N + 4);
        rhs.head(N + 1) = F;
        rhs(N + 1) = tt.g.real();
        rhs(N + 2) = tt.g.imag();
        rhs(N + 3) = a.dot(y) - beta;
        const Eigen::VectorXd dy = lu.solve(rhs);
        if (!dy.allFinite()) return r;
        y -= dy;
        ++r.iterations;
        last_step = dy.lpNorm<Eigen::Infinity>();
    }
    return r;
}

}  // namespace

bool OrbitFoldCurveOptions::is_valid(std::string* why) const {
    if (!orbit.is_valid(why)) return false;
    const char* w = nullptr;
    if (parameter2.empty()) w = "parameter2: expected a name";
    else if (parameter2 == orbit.parameter) w = "parameter2: expected a parameter other than the first";
    else if (!std::isfinite(from2) || !std::isfinite(to2) || from2 == to2) w = "from2, to2: expected two different finite values";
    if (w && why) *why = w;
    return w == nullptr;
}

namespace {

enum class CurveKind { Fold, PeriodDoubling, Torus };

/// The curve of folds, period doublings or tori through the orbit `orbit` at p1 = par
/// (orbit_fold_curve, orbit_period_doubling_curve, orbit_torus_curve); `multiplier` the torus's
/// e^{i phi} (Im > 0).
OrbitFoldCurve orbit_bifurcation_curve(const NonlinearDDE& system, const PeriodicOrbit& orbit, double par, CurveKind curve_kind,
                                       const OrbitFoldCurveOptions& options, std::complex<double> multiplier = 1.0) {
    const SingleThreadedEigen single;
    const bool doubling = curve_kind == CurveKind::PeriodDoubling, torus = curve_kind == CurveKind::Torus;
    const std::string what = doubling ? "period doubling curve" : (torus ? "torus curve" : "fold curve");
    const std::string kind = doubling ? "period doubling" : (torus ? "torus bifurcation" : "fold");
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument(what + " options: " + why);
    const PeriodicOrbitOptions& o = options.orbit;
    const PeriodicMesh mesh(o.degree, o.intervals);
    if (orbit.profile.rows() != mesh.points() || orbit.profile.cols() != system.dimension())
        throw std::invalid_argument(what + ": the " + kind + "'s orbit must lie on the uniform mesh of the options' degree and intervals");
    if (!(orbit.period > 0.0)) throw std::invalid_argument(what + ": expected a " + kind + " with a period > 0");
    const Setup s1 = make_setup(system, mesh, o, orbit.period);
    PeriodicOrbitOptions o2 = o;
    o2.parameter = options.parameter2;
    o2.from = options.from2;
    o2.to = options.to2;
    const Setup s2 = make_setup(system, mesh, o2, orbit.period);
    FoldSystem fs(s1, s2);
    const int N = s1.N();
    fs.N = N;
    fs.w.resize(N + 3);
    fs.w.head(N + 2) = s1.w;
    fs.w(N + 2) = s2.w(N + 1);
    const double lo1 = std::min(o.from, o.to), hi1 = std::max(o.from, o.to);
    const double lo2 = std::min(options.from2, options.to2), hi2 = std::max(options.from2, options.to2);
    const double p20 = system.parameter_values()[static_cast<std::size_t>(s2.j)];
    if (!(p20 >= lo2 && p20 <= hi2))
        throw std::invalid_argument(what + ": " + options.parameter2 + " = " + detail::format_number(p20) + " lies outside its range [" +
                                    detail::format_number(lo2) + ", " + detail::format_number(hi2) + "]");
    // the period doubling's condition lives on the mesh traversed twice (antiperiodic_block)
    const PeriodicMesh mesh2(o.degree, 2 * o.intervals);
    std::unique_ptr<FoldSystem> fd;
    if (doubling) {
        fd = std::make_unique<FoldSystem>(make_setup(system, mesh2, o, 2.0 * orbit.period), make_setup(system, mesh2, o2, 2.0 * orbit.period));
        fd->N = 2 * N;
        fd->w = Eigen::VectorXd::Ones(2 * N + 3);
    }
    const Eigen::MatrixXd ref2 = doubling ? Eigen::MatrixXd::Zero(mesh2.points(), system.dimension()) : Eigen::MatrixXd();
    TorusCondition tc(system, o, o2, N);
    // the unknowns: (X, T, p1, p2), and for a torus phi (weighted as (phi / pi)^2 in the norm)
    const int K = N + 3 + (torus ? 1 : 0);
    Eigen::VectorXd wk(K);
    wk.head(N + 3) = fs.w;
    if (torus) wk(N + 3) = 1.0 / (M_PI * M_PI);
    auto knorm = [&](const Eigen::VectorXd& v) { return std::sqrt((wk.array() * v.array().square()).sum()); };

    OrbitFoldCurve curve;
    curve.parameter = o.parameter;
    curve.parameter2 = options.parameter2;
    curve.degree = o.degree;
    curve.intervals = o.intervals;
    curve.method = torus ? "the minimally augmented torus system (the complex test g of the bordered collocated variational operator with "
                           "the Floquet wrap y(s + 1) = e^{i phi} y(s) appended, phi free) on " + method_text(mesh) +
                               "; both parameters free, pseudo-arclength; sparse LU of the extended Jacobian"
                   : doubling ? "the minimally augmented period doubling system (the test g of the bordered collocated variational operator "
                              "with the antiperiodic wrap appended) on " + method_text(mesh) + "; both parameters free, pseudo-arclength; "
                              "sparse LU of the extended Jacobian"
                            : "the minimally augmented fold system (the fold test g of the bordered Jacobian of the collocation and phase "
                              "conditions appended) on " + method_text(mesh) + "; both parameters free, pseudo-arclength; sparse LU of the extended Jacobian";

    Eigen::VectorXd z(K);
    for (int i = 0; i < s1.P; ++i) z.segment(static_cast<Eigen::Index>(i) * s1.n, s1.n) = orbit.profile.row(i).transpose();
    z(N) = orbit.period;
    z(N + 1) = par;
    z(N + 2) = p20;
    if (torus) z(N + 3) = std::arg(multiplier);
    // the bordering vectors: from fixed pseudo-random ones, two rounds of the bordered solves
    const int M = doubling ? N : N + 1;  // the size of the test's matrix
    Eigen::VectorXd bv(M), cv(M);
    for (int i = 0; i < M; ++i) {
        bv(i) = std::sin(1.0 + 0.7 * i);
        cv(i) = std::cos(0.3 + 1.3 * i);
    }
    VectorXcd bt(N), ct(N);  // the torus's (complex)
    for (int i = 0; i < N; ++i) {
        bt(i) = std::complex<double>(std::sin(1.0 + 0.7 * i), std::cos(2.0 + 0.4 * i));
        ct(i) = std::complex<double>(std::cos(0.3 + 1.3 * i), std::sin(0.5 + 0.9 * i));
    }
    Eigen::MatrixXd ref = derivative_at_collocation(fs.c1, fs.orbit_part(z));
    auto failed = [&](const std::string& m) {
        curve.status = Status::MaxIterations;
        curve.message = m;
        curve.stop_backward = curve.stop_forward = "first_point_failed";
        return curve;
    };
    for (int round = 0; round < 2; ++round) {
        Eigen::VectorXd F;
        SpD J;
        FoldTest ft;
        bool ok = fold_assemble(fs, z, ref, F, &J);
        if (ok && torus) {
            TorusTest tt;
            if (!torus_at(tc, fs, z, bt, ct, tt, nullptr)) return failed("the " + kind + "'s orbit gives no finite Jacobian");
            ct = tt.v / tt.v.norm();
            bt = tt.w / tt.w.norm();
            continue;
        }
        if (ok && doubling) {
            SpD J2;
            Eigen::VectorXd F2;
            ok = fold_assemble(*fd, doubled_point(z, N), ref2, F2, &J2) && fold_test(antiperiodic_block(J2, N), bv, cv, ft);
        } else if (ok) {
            ok = fold_test(J, bv, cv, ft);
        }
        if (!ok) return failed("the " + kind + "'s orbit gives no finite Jacobian");
        cv = ft.v / ft.v.norm();
        bv = ft.w / ft.w.norm();
    }
    // one corrector for the three kinds; a torus's borders (complex) are renewed from its last test
    auto correct = [&](Eigen::VectorXd& y, const Eigen::MatrixXd& rf, const Eigen::VectorXd& b, const Eigen::VectorXd& c, const VectorXcd& tb,
                       const VectorXcd& tcv, const Eigen::VectorXd& a, double beta, TorusTest& tt) {
        if (torus) return correct_torus(fs, tc, y, rf, tb, tcv, a, beta, o, tt);
        return correct_fold(fs, y, rf, b, c, a, beta, o, fd.get());
    };
    Eigen::VectorXd e2 = Eigen::VectorXd::Zero(K);
    e2(N + 2) = 1.0;
    TorusTest tt0;
    FoldCorrection r0 = correct(z, ref, bv, cv, bt, ct, e2, p20, tt0);
    curve.newton_iterations += r0.iterations;
    if (!r0.ok)
        return failed("the " + kind + " did not converge as a point of the " + kind + " system at " + options.parameter2 + " = " + detail::format_number(p20));
    Eigen::VectorXd t0 = r0.tangent / knorm(r0.tangent);

    auto make_point = [&](const Eigen::VectorXd& zz, const FoldCorrection& r) {
        OrbitFoldCurvePoint q;
        Correction c;
        c.residual = r.residual;
        c.iterations = r.iterations;
        c.ok = true;
        q.orbit = make_orbit(fs.c1, fs.orbit_part(zz), c, o.floquet);
        q.par = zz(N + 1);
        q.par2 = zz(N + 2);
        q.test = r.test;
        if (torus) {
            q.rotation = std::abs(std::remainder(zz(N + 3), 2.0 * M_PI));  // in [0, pi]
            if (!q.orbit.multipliers.empty()) {
                q.second_distance = std::numeric_limits<double>::infinity();
                for (cplx m : q.orbit.multipliers) q.second_distance = std::min(q.second_distance, std::abs(m - std::polar(1.0, q.rotation)));
            }
        } else if (doubling && !q.orbit.multipliers.empty()) {
            q.second_distance = std::numeric_limits<double>::infinity();
            for (cplx m : q.orbit.multipliers) q.second_distance = std::min(q.second_distance, std::abs(m + 1.0));
        } else if (q.orbit.multipliers.size() >= 2) {
            std::vector<double> dist;
            for (cplx m : q.orbit.multipliers) dist.push_back(std::abs(m - 1.0));
            std::sort(dist.begin(), dist.end());
            q.second_distance = dist[1];
        }
        return q;
    };
    const OrbitFoldCurvePoint first = make_point(z, r0);
    const double T0 = z(N);
    const long total = 2L * o.max_points;
    long done = 1;
    if (o.progress) o.progress(done, total, first.par);

    // one direction from the start: the points after it, and why it ended
    auto follow_fold = [&](double sign, std::string& stop) {
        std::vector<OrbitFoldCurvePoint> out;
        Eigen::VectorXd u = z, t = sign * t0, b = bv, c = cv;
        VectorXcd tb = bt, tcv = ct;
        StepControl step(orbit_continuation::step_control_options(o));
        double amp_max = amplitude(first.orbit);
        stop = "max_points";
        while (static_cast<int>(out.size()) + 1 < o.max_points) {
            const double h = step.h();
            const Eigen::MatrixXd rf = derivative_at_collocation(fs.c1, fs.orbit_part(u));
            Eigen::VectorXd v = u + h * t;
            const Eigen::VectorXd a = wk.cwiseProduct(t);
            TorusTest tt;
            FoldCorrection r = correct(v, rf, b, c, tb, tcv, a, a.dot(u + h * t), tt);
            curve.newton_iterations += r.iterations;
            const bool jump = r.ok && step.jumped(knorm(v - u));
            if (!r.ok || jump) {
                if (!step.reject()) {
                    // a fold curve coming to a generalised Hopf point: the fold system degenerates
                    // as the amplitude a -> 0 (the fold's position is fixed only to ~1e-8 where
                    // a is a few % of the curve's largest, and Newton stalls there); a corrector
                    // that fails after the amplitude fell over the last 3 points to below a
                    // quarter of the largest ends the curve there, as a regular end
                    if (!r.ok && !torus && !doubling && out.size() >= 3) {
                        const std::size_t k = out.size();
                        const double a0 = amplitude(out[k - 3].orbit), a1 = amplitude(out[k - 2].orbit), a2 = amplitude(out[k - 1].orbit);
                        if (a2 < a1 && a1 < a0 && a2 < 0.25 * amp_max) {
                            stop = "hopf";
                            return out;
                        }
                    }
                    stop = "step_below_minimum";
                    if (curve.status == Status::Converged) {
                        curve.status = jump ? Status::NumericalIssue : Status::MaxIterations;
                        curve.message = "the " + what + "'s corrector failed at (" + o.parameter + ", " + options.parameter2 + ") = (" +
                                        detail::format_number(u(N + 1)) + ", " + detail::format_number(u(N + 2)) + ") with the step below " +
                                        detail::format_number(o.min_step);
                    }
                    return out;
                }
                continue;
            }
            Eigen::VectorXd tn = r.tangent / knorm(r.tangent);
            if (tn.dot(wk.cwiseProduct(t)) < 0.0) tn = -tn;
            const double p1 = v(N + 1), p2 = v(N + 2);
            if (p1 < lo1 || p1 > hi1 || p2 < lo2 || p2 > hi2) {
                // the point on the face it crossed (the first parameter's, else the second's)
                Eigen::VectorXd e = Eigen::VectorXd::Zero(K);
                double bound = 0.0;
                if (p1 < lo1 || p1 > hi1) {
                    e(N + 1) = 1.0;
                    bound = p1 < lo1 ? lo1 : hi1;
                } else {
                    e(N + 2) = 1.0;
                    bound = p2 < lo2 ? lo2 : hi2;
                }
                Eigen::VectorXd wz = v;
                TorusTest tb2;
                const FoldCorrection rb = correct(wz, rf, b, c, tb, tcv, e, bound, tb2);
                curve.newton_iterations += rb.iterations;
                if (rb.ok) out.push_back(make_point(wz, rb));
                else if (curve.status == Status::Converged) {
                    curve.status = Status::MaxIterations;
                    curve.message = "the " + what + "'s point on the face of the box did not converge";
                }
                stop = "bound";
                return out;
            }
            // the curve reached a generalised Hopf point (where it meets the Hopf curve, the
            // orbits' amplitude a -> 0 and (p1, p2) moves like a^2) and went through it onto the
            // same folds phase-shifted: the direction in (p1, p2) turns back within the step at a
            // small amplitude. Such a step ends the curve (once it ran back along itself); a cusp
            // of the fold curve turns too, but at the amplitude of its orbits
            // a torus curve whose phi crossed 0 or pi within the step passed a 1:1 or 1:2 resonance
            // (the pair met at 1 or -1 and turned real): beyond it the equations hold for the
            // conjugate pair, the same curve traced back; the curve ends before the crossing
            if (torus && std::sin(u(N + 3)) * std::sin(v(N + 3)) <= 0.0) {
                stop = "resonance";
                return out;
            }
            OrbitFoldCurvePoint next = make_point(v, r);
            const double amp = amplitude(next.orbit), amp_prev = out.empty() ? amplitude(first.orbit) : amplitude(out.back().orbit);
            const double turn = fs.w(N + 1) * t(N + 1) * tn(N + 1) + fs.w(N + 2) * t(N + 2) * tn(N + 2);
            // (the step is halved to come closer first, down to 2 % of the largest amplitude)
            if (turn < 0.0 && std::max(amp, amp_prev) < 0.25 * amp_max) {
                if (amp_prev > 0.02 * amp_max && step.reject()) continue;
                stop = "hopf";
                return out;
            }
            amp_max = std::max(amp_max, amp);
            // a torus curve ends where its multipliers e^{+-i phi} meet at 1 or -1 (a 1:1 or 1:2
            // resonance, on a fold or period doubling curve): the pair turns real there
            const bool resonant = torus && std::abs(std::sin(v(N + 3))) < 1e-2;
            out.push_back(std::move(next));
            if (o.progress) o.progress(++done, total, out.back().par);
            if (amp < 0.02 * amp_max) {
                stop = "hopf";
                return out;
            }
            if (v(N) > o.max_period_factor * T0) {
                stop = "period";
                return out;
            }
            if (resonant) {
                stop = "resonance";
                return out;
            }
            u = v;
            t = tn;
            if (torus) {
                tcv = tt.v / tt.v.norm();
                tb = tt.w / tt.w.norm();
            } else {
                c = r.fold.v / r.fold.v.norm();
                b = r.fold.w / r.fold.w.norm();
            }
            step.accept(r.iterations <= 3);
        }
        return out;
    };
    std::vector<OrbitFoldCurvePoint> backward = follow_fold(-1.0, curve.stop_backward);
    std::vector<OrbitFoldCurvePoint> forward = follow_fold(1.0, curve.stop_forward);
    curve.points.assign(backward.rbegin(), backward.rend());
    curve.start = static_cast<int>(curve.points.size());
    curve.points.push_back(first);
    curve.points.insert(curve.points.end(), forward.begin(), forward.end());
    for (const OrbitFoldCurvePoint& q : curve.points) {
        curve.max_residual = std::max(curve.max_residual, q.orbit.residual);
        curve.max_test = std::max(curve.max_test, q.test);
        if (std::isfinite(q.orbit.trivial_distance)) curve.max_trivial_distance = std::max(curve.max_trivial_distance, q.orbit.trivial_distance);
    }
    if (curve.message.empty())
        curve.message = std::to_string(curve.points.size()) + (doubling ? " period doublings" : (torus ? " torus bifurcations" : " folds of orbits")) + ", ended: " + curve.stop_backward +
                        " and " + curve.stop_forward;
    return curve;
}

}  // namespace

OrbitFoldCurve orbit_fold_curve(const NonlinearDDE& system, const OrbitFold& fold, const OrbitFoldCurveOptions& options) {
    return orbit_bifurcation_curve(system, fold.orbit, fold.par, CurveKind::Fold, options);
}

OrbitBranchCurves orbit_curves_of_branch(const NonlinearDDE& system, const OrbitBranch& branch, const OrbitFoldCurveOptions& options) {
    const double held = system.parameter_values()[static_cast<std::size_t>(system.parameter_index(options.parameter2))];
    const double range = std::abs(options.orbit.to - options.orbit.from);
    // on a curve already traced: a segment of it crosses parameter2 = held at p
    auto on_curve = [&](const std::vector<OrbitFoldCurve>& traced, double p) {
        for (const OrbitFoldCurve& c : traced)
            for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
                const OrbitFoldCurvePoint &a = c.points[i], &z = c.points[i + 1];
                if ((a.par2 - held) * (z.par2 - held) > 0.0 || a.par2 == z.par2) continue;
                if (std::abs(a.par + (z.par - a.par) * (held - a.par2) / (z.par2 - a.par2) - p) <= 1e-6 * range) return true;
            }
        return false;
    };
    OrbitBranchCurves r;
    auto note = [&](const OrbitFoldCurve& c, const std::string& what, double p) {
        if (c.status == Status::Converged || r.status != Status::Converged) return;
        r.status = c.status;
        r.message = "the " + what + " curve from the " + what + " at " + options.orbit.parameter + " = " + detail::format_number(p) + ": " + c.message;
    };
    for (std::size_t k = 0; k < branch.folds.size(); ++k) {
        const OrbitFold& f = branch.folds[k];
        if (!f.located || on_curve(r.folds, f.par)) continue;
        r.folds.push_back(orbit_fold_curve(system, f, options));
        r.fold_index.push_back(static_cast<int>(k));
        note(r.folds.back(), "fold", f.par);
    }
    for (std::size_t k = 0; k < branch.period_doublings.size(); ++k) {
        const OrbitCrossing& d = branch.period_doublings[k];
        if (!d.located || on_curve(r.period_doublings, d.par)) continue;
        r.period_doublings.push_back(orbit_period_doubling_curve(system, d, options));
        r.period_doubling_index.push_back(static_cast<int>(k));
        note(r.period_doublings.back(), "period doubling", d.par);
    }
    for (std::size_t k = 0; k < branch.tori.size(); ++k) {
        const OrbitCrossing& d = branch.tori[k];
        if (!d.located || on_curve(r.tori, d.par)) continue;
        try {
            r.tori.push_back(orbit_torus_curve(system, d, options));
        } catch (const std::invalid_argument& e) {
            // a torus whose pair is (nearly) real (|sin phi| < 0.01: at a resonance) starts no
            // curve; the other curves stand, this one is undecided with the reason
            OrbitFoldCurve c;
            c.parameter = options.orbit.parameter;
            c.parameter2 = options.parameter2;
            c.degree = options.orbit.degree;
            c.intervals = options.orbit.intervals;
            c.status = Status::NumericalIssue;
            c.message = e.what();
            c.stop_backward = c.stop_forward = "first_point_failed";
            r.tori.push_back(std::move(c));
        }
        r.torus_index.push_back(static_cast<int>(k));
        note(r.tori.back(), "torus", d.par);
    }
    return r;
}

OrbitFoldCurve orbit_period_doubling_curve(const NonlinearDDE& system, const OrbitCrossing& pd, const OrbitFoldCurveOptions& options) {
    if (!pd.located || pd.orbit.profile.size() == 0)
        throw std::invalid_argument("period doubling curve: expected a located period doubling with its orbit");
    return orbit_bifurcation_curve(system, pd.orbit, pd.par, CurveKind::PeriodDoubling, options);
}

OrbitFoldCurve orbit_torus_curve(const NonlinearDDE& system, const OrbitCrossing& torus, const OrbitFoldCurveOptions& options) {
    if (!torus.located || torus.orbit.profile.size() == 0) throw std::invalid_argument("torus curve: expected a located torus bifurcation with its orbit");
    const std::complex<double> mu = torus.multiplier.imag() < 0.0 ? std::conj(torus.multiplier) : torus.multiplier;
    if (!(std::abs(std::sin(std::arg(mu))) >= 1e-2))
        throw std::invalid_argument("torus curve: the multiplier " + detail::format_number(mu.real()) + " + " + detail::format_number(mu.imag()) +
                                    " i is (nearly) real: expected a complex pair on the unit circle");
    return orbit_bifurcation_curve(system, torus.orbit, torus.par, CurveKind::Torus, options, mu);
}

std::string orbit_curve_end_point(const OrbitFoldCurvePoint& end) {
    return std::abs(std::sin(end.rotation)) < std::sin(0.1) ? "ZH" : "DH";
}

}  // namespace ddemap
