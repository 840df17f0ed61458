#include "ddemap/analysis/bifurcation/travelling_wave.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include "ddemap/solve/roots.hpp"
#include "ddemap/solve/step_control.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"
#include "ddemap/traffic/ring_car.hpp"

#include "analysis/bifurcation/internal/orbit_continuation.hpp"
#include "analysis/bifurcation/internal/orbit_mesh.hpp"
#include "analysis/bifurcation/internal/wave_stability_pass.hpp"

namespace ddemap {

namespace {

constexpr double kPi = 3.14159265358979323846;
using Triplet = Eigen::Triplet<double>;
using SpD = Eigen::SparseMatrix<double>;

/// The reduced problem on a mesh. Unknowns u = (X (P x 2), T, p, mu): N + 3 values, N = 2 P.
struct Wave {
    Wave(const RingCar& c, const PeriodicMesh& me) : car(c), mesh(me) {}
    const RingCar& car;
    PeriodicMesh mesh;  // replaced when the mesh is adapted (remesh)
    double kappa = 0.0;  // k / N
    int j = 0, d = 0, L = 0, P = 0;
    std::vector<double> base;
    Eigen::VectorXd w;  // weights of the continuation norm (size N + 3; mu not weighted)
    static constexpr int n = 2;
    static constexpr int m = 3;
    int N() const { return P * n; }
    std::vector<double> params(double p) const {
        std::vector<double> v = base;
        v[static_cast<std::size_t>(j)] = p;
        return v;
    }
    double norm(const Eigen::VectorXd& v) const { return std::sqrt((w.array() * v.array().square()).sum()); }
};

Eigen::Vector2d combine(const Wave& c, const Eigen::VectorXd& u, int interval, const double* coef) {
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    for (int jj = 0; jj <= c.d; ++jj) v += coef[jj] * u.segment<2>(static_cast<Eigen::Index>(((interval * c.d + jj) % c.P) * 2));
    return v;
}

/// The residual (N + 3: collocation, phase, length, arclength a . u - b) and with J its Jacobian.
bool assemble(const Wave& c, const Eigen::VectorXd& u, const Eigen::MatrixXd& ref, const Eigen::VectorXd& a, double b, Eigen::VectorXd& F,
              SpD* J) {
    const int N = c.N();
    const double T = u(N), p = u(N + 1), mu = u(N + 2);
    if (!(T > 0.0) || !std::isfinite(p) || !std::isfinite(mu)) return false;
    const std::vector<double> pv = c.params(p);
    const std::vector<double> tau = c.car.delays(pv), dtau = c.car.delay_derivatives(pv, c.j);
    for (double t : tau)
        if (!(t >= 0.0) || !std::isfinite(t)) return false;
    F.setZero(N + 3);
    std::vector<Triplet> trip;
    if (J) trip.reserve(static_cast<std::size_t>(N) * static_cast<std::size_t>(4 * (c.d + 1) * 4 + 8));
    const int d = c.d;
    std::vector<double> l(static_cast<std::size_t>(d) + 1), dl(l), lk(l), dlk(l);
    Eigen::VectorXd stacked(2 * (c.m + 1));
    std::vector<int> intervals(static_cast<std::size_t>(c.m));
    std::vector<std::vector<double>> bases(static_cast<std::size_t>(c.m), l);
    std::vector<Eigen::Vector2d> dxk(static_cast<std::size_t>(c.m));
    const double length_target = c.j == c.car.length_parameter() ? p : c.base[static_cast<std::size_t>(c.car.length_parameter())];
    for (int i = 0; i < c.L; ++i) {
        const double h = c.mesh.width(i);
        for (int g = 0; g < d; ++g) {
            const double s = c.mesh.collocation_point(i, g);
            c.mesh.basis(i, s, l.data(), dl.data());
            const Eigen::Vector2d x = combine(c, u, i, l.data()), dx = combine(c, u, i, dl.data());
            stacked.head<2>() = x;
            for (int k = 0; k < c.m; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                const double sk = s - tau[uk] / T + (RingCar::is_lead(k + 1) ? c.kappa : 0.0);
                double wrapped = sk - std::floor(sk);
                if (wrapped >= 1.0) wrapped = 0.0;
                intervals[uk] = c.mesh.interval_of(wrapped);
                c.mesh.basis(intervals[uk], wrapped, bases[uk].data(), dlk.data());
                stacked.segment<2>(2 * (k + 1)) = combine(c, u, intervals[uk], bases[uk].data());
                dxk[uk] = combine(c, u, intervals[uk], dlk.data());
            }
            Eigen::VectorXd f = c.car.f(stacked, pv);
            if (!f.allFinite()) return false;
            f(0) += mu;
            const int row = (i * d + g) * 2;
            F.segment<2>(row) = dx - T * f;
            const double wg = c.mesh.gauss_weights()[static_cast<std::size_t>(g)] * h;
            const Eigen::Vector2d r = ref.row(i * d + g).transpose();
            F(N) += wg * x.dot(r);
            F(N + 1) += wg * x(0);
            if (!J) continue;
            const std::vector<Eigen::MatrixXd> A = c.car.jacobians(stacked, pv);
            const Eigen::VectorXd fp = c.car.parameter_derivative(stacked, c.j, pv);
            for (const auto& blk : A)
                if (!blk.allFinite()) return false;
            if (!fp.allFinite()) return false;
            for (int jj = 0; jj <= d; ++jj) {
                const int col = ((i * d + jj) % c.P) * 2;
                const double lj = l[static_cast<std::size_t>(jj)], dlj = dl[static_cast<std::size_t>(jj)];
                for (int q = 0; q < 2; ++q) {
                    trip.emplace_back(row + q, col + q, dlj);
                    for (int rr = 0; rr < 2; ++rr)
                        if (A[0](rr, q) != 0.0) trip.emplace_back(row + rr, col + q, -T * lj * A[0](rr, q));
                    if (r(q) != 0.0) trip.emplace_back(N, col + q, wg * lj * r(q));
                }
                trip.emplace_back(N + 1, col, wg * lj);
            }
            Eigen::Vector2d dT = -f, dp = -T * fp;
            for (int k = 0; k < c.m; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                const Eigen::MatrixXd& Ak = A[uk + 1];
                for (int jj = 0; jj <= d; ++jj) {
                    const int col = ((intervals[uk] * d + jj) % c.P) * 2;
                    const double lj = bases[uk][static_cast<std::size_t>(jj)];
                    for (int q = 0; q < 2; ++q)
                        for (int rr = 0; rr < 2; ++rr)
                            if (Ak(rr, q) != 0.0) trip.emplace_back(row + rr, col + q, -T * lj * Ak(rr, q));
                }
                const Eigen::Vector2d ad = Ak * dxk[uk];
                dT -= ad * (tau[uk] / T);  // the leader's shift kappa is constant in s: no T term
                dp += ad * dtau[uk];
            }
            for (int q = 0; q < 2; ++q) {
                trip.emplace_back(row + q, N, dT(q));
                trip.emplace_back(row + q, N + 1, dp(q));
            }
            trip.emplace_back(row, N + 2, -T);
        }
    }
    F(N + 1) -= length_target;
    F(N + 2) = a.dot(u) - b;
    if (J) {
        if (c.j == c.car.length_parameter()) trip.emplace_back(N + 1, N + 1, -1.0);
        for (int q = 0; q < N + 3; ++q)
            if (a(q) != 0.0) trip.emplace_back(N + 2, q, a(q));
        J->resize(N + 3, N + 3);
        J->setFromTriplets(trip.begin(), trip.end());
    }
    return F.allFinite();
}

/// x' at the collocation points (row l d + g): the phase reference.
Eigen::MatrixXd derivative_at_collocation(const Wave& c, const Eigen::VectorXd& u) {
    Eigen::MatrixXd r(c.P, 2);
    std::vector<double> l(static_cast<std::size_t>(c.d) + 1), dl(l);
    for (int i = 0; i < c.L; ++i)
        for (int g = 0; g < c.d; ++g) {
            c.mesh.basis(i, c.mesh.collocation_point(i, g), l.data(), dl.data());
            r.row(i * c.d + g) = combine(c, u, i, dl.data()).transpose();
        }
    return r;
}

/// The relative defect of the wave u between the collocation points: at the d + 1 representation
/// points of every interval (the ends and the points between the Gauss nodes, where the
/// collocation does not hold the equations), r(s) = x'(s) - T [g(x(s), x(s - tau/T), x(s + kappa),
/// x(s + kappa - tau/T); p) + mu e_h]; returns max over components c of max_s |r_c| / max_s |x_c'|
/// (the interval's own polynomial at its ends). For a collocation solution it is
/// O(h^d |x^(d+1)| / |x'|): the indicator of an unresolved profile. NaN when not finite.
double reduced_defect(const Wave& c, const Eigen::VectorXd& u) {
    const int N = c.N();
    const double T = u(N), p = u(N + 1), mu = u(N + 2);
    const std::vector<double> pv = c.params(p);
    const std::vector<double> tau = c.car.delays(pv);
    std::vector<double> l(static_cast<std::size_t>(c.d) + 1), dl(l), lk(l), dlk(l);
    Eigen::VectorXd stacked(2 * (c.m + 1));
    Eigen::Array2d rmax = Eigen::Array2d::Zero(), dmax = Eigen::Array2d::Zero();
    for (int i = 0; i < c.L; ++i)
        for (int jj = 0; jj <= c.d; ++jj) {
            const double s = c.mesh.breakpoints()[static_cast<std::size_t>(i)] + c.mesh.width(i) * jj / c.d;
            c.mesh.basis(i, s, l.data(), dl.data());
            const Eigen::Vector2d dx = combine(c, u, i, dl.data());
            stacked.head<2>() = combine(c, u, i, l.data());
            for (int k = 0; k < c.m; ++k) {
                const double sk = s - tau[static_cast<std::size_t>(k)] / T + (RingCar::is_lead(k + 1) ? c.kappa : 0.0);
                double wrapped = sk - std::floor(sk);
                if (wrapped >= 1.0) wrapped = 0.0;
                const int ik = c.mesh.interval_of(wrapped);
                c.mesh.basis(ik, wrapped, lk.data(), dlk.data());
                stacked.segment<2>(2 * (k + 1)) = combine(c, u, ik, lk.data());
            }
            Eigen::VectorXd f = c.car.f(stacked, pv);
            f(0) += mu;
            rmax = rmax.max((dx - T * f).array().abs());
            dmax = dmax.max(dx.array().abs());
        }
    const double r = (rmax / dmax).maxCoeff();
    return std::isfinite(r) ? r : std::numeric_limits<double>::quiet_NaN();
}

struct Correction {
    bool ok = false;
    int iterations = 0;
    double residual = std::numeric_limits<double>::infinity();
    Eigen::VectorXd tangent;
};

/// Newton on the bordered system (the last row a . u = b), as periodic_orbit's corrector.
Correction correct(const Wave& c, Eigen::VectorXd& u, const Eigen::MatrixXd& ref, const Eigen::VectorXd& a, double b, const PeriodicOrbitOptions& o) {
    Correction r;
    Eigen::VectorXd F;
    SpD J;
    Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>> lu;
    const int N = c.N();
    double last_step = std::numeric_limits<double>::infinity();
    for (int it = 0; it <= o.max_iterations; ++it) {
        if (it > 0 && last_step <= o.tolerance * std::max(1.0, u.head(N + 2).lpNorm<Eigen::Infinity>())) {
            if (!assemble(c, u, ref, a, b, F, nullptr)) return r;
            r.residual = F.head(N + 2).lpNorm<Eigen::Infinity>();
            r.ok = r.residual <= o.residual_tolerance;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 3);
            e(N + 2) = 1.0;
            r.tangent = lu.solve(e);
            if (!r.tangent.allFinite()) r.ok = false;
            return r;
        }
        if (it == o.max_iterations) break;
        if (!assemble(c, u, ref, a, b, F, &J)) return r;
        J.makeCompressed();
        lu.compute(J);
        if (lu.info() != Eigen::Success) return r;
        r.residual = F.head(N + 2).lpNorm<Eigen::Infinity>();
        const Eigen::VectorXd du = lu.solve(F);
        if (!du.allFinite()) return r;
        u -= du;
        ++r.iterations;
        last_step = du.head(N + 2).lpNorm<Eigen::Infinity>();
    }
    return r;
}

/// The full ring (one headway eliminated) for the multipliers, or null when N is above the limit.
struct FullRing {
    std::unique_ptr<NonlinearDDE> system;
    int cars = 0, wave = 0;
};

PeriodicOrbit make_orbit(const Wave& c, const Eigen::VectorXd& u, const Correction& r, const FullRing& full, const std::string& parameter,
                         bool floquet) {
    const int N = c.N();
    PeriodicOrbit o;
    o.period = u(N);
    o.par = u(N + 1);
    o.profile.resize(c.P, 2);
    for (int i = 0; i < c.P; ++i) o.profile.row(i) = u.segment<2>(2 * i).transpose();
    o.breakpoints = c.mesh.breakpoints();
    o.min = o.profile.colwise().minCoeff().transpose();
    o.max = o.profile.colwise().maxCoeff().transpose();
    const int per = 8 * c.d;  // as periodic_orbit: 8 d samples per interval
    for (int i = 0; i < c.L; ++i)
        for (int k = 1; k < per; ++k) {
            const Eigen::VectorXd x = orbit_value(c.mesh, o.profile, c.mesh.breakpoints()[static_cast<std::size_t>(i)] + c.mesh.width(i) * k / per);
            o.min = o.min.cwiseMin(x);
            o.max = o.max.cwiseMax(x);
        }
    o.residual = r.residual;
    o.iterations = r.iterations;
    if (floquet && full.system) {
        // the wave spread to the N cars: (h_0..h_{N-2}, v_0..v_{N-1}) at every mesh point
        const int cars = full.cars;
        Eigen::MatrixXd profile(c.P, 2 * cars - 1);
        for (int i = 0; i < c.P; ++i)
            for (int car = 0; car < cars; ++car) {
                const Eigen::VectorXd x = wave_car_state(c.mesh, o, cars, full.wave, car, c.mesh.point(i));
                if (car + 1 < cars) profile(i, car) = x(0);
                profile(i, cars - 1 + car) = x(1);
            }
        o.multipliers = orbit_multipliers(*full.system, parameter, c.mesh, profile, o.period, o.par);
        if (!o.multipliers.empty()) {
            std::size_t k1 = 0;
            for (std::size_t k = 1; k < o.multipliers.size(); ++k)
                if (std::abs(o.multipliers[k] - 1.0) < std::abs(o.multipliers[k1] - 1.0)) k1 = k;
            o.trivial_distance = std::abs(o.multipliers[k1] - 1.0);
            o.max_nontrivial = 0.0;
            for (std::size_t k = 0; k < o.multipliers.size(); ++k)
                if (k != k1) o.max_nontrivial = std::max(o.max_nontrivial, std::abs(o.multipliers[k]));
            o.stable = o.max_nontrivial < 1.0;
            orbit_continuation::check_accuracy(o);
        }
    }
    return o;
}

double amplitude(const PeriodicOrbit& o) { return (o.max - o.min).maxCoeff(); }

/// The mode-k characteristic matrix Delta_k(lambda) and Delta_k'(lambda) at the uniform flow of p.
struct Mode {
    Eigen::Matrix2cd M0, M1;
    double tau = 0.0;
    Eigen::Matrix2cd delta(cplx l) const { return l * Eigen::Matrix2cd::Identity() - M0 - M1 * std::exp(-l * tau); }
    Eigen::Matrix2cd ddelta(cplx l) const { return Eigen::Matrix2cd::Identity() + tau * M1 * std::exp(-l * tau); }
};

Mode mode_at(const RingCar& car, const std::vector<double>& pv, cplx z, Eigen::VectorXd& x) {
    x = car.uniform_flow(pv);
    const std::vector<Eigen::MatrixXd> A = car.jacobians(car.stack_constant(x), pv);
    Mode md;
    md.tau = car.delays(pv)[0];
    md.M0 = A[0].cast<cplx>() + z * A[2].cast<cplx>();
    md.M1 = A[1].cast<cplx>() + z * A[3].cast<cplx>();
    return md;
}

/// Newton on det Delta_k from lambda (lambda <- lambda - 1 / trace(Delta^{-1} Delta')); false when
/// it does not converge.
bool newton_root(const Mode& md, cplx& lambda) {
    for (int it = 0; it < 60; ++it) {
        const Eigen::Matrix2cd D = md.delta(lambda);
        const cplx det = D.determinant();
        if (det == 0.0) return true;
        const cplx tr = (D.inverse() * md.ddelta(lambda)).trace();
        if (!std::isfinite(std::abs(tr)) || tr == 0.0) return false;
        const cplx step = 1.0 / tr;
        lambda -= step;
        if (std::abs(step) <= 1e-14 * std::max(1.0, std::abs(lambda))) return std::isfinite(std::abs(lambda));
    }
    return false;
}

/// The rightmost roots with Im > 0 of mode k at p (rightmost_roots of the complex 2 x 2 DDE).
std::vector<cplx> upper_roots(const RingCar& car, const std::vector<double>& pv, cplx z) {
    Eigen::VectorXd x;
    const Mode md = mode_at(car, pv, z, x);
    std::vector<DelayTerm> delayed;
    MatrixXc a0 = md.M0;
    if (md.tau > 0.0) delayed.push_back({md.M1, md.tau});
    else a0 += md.M1;
    RootOptions ro;
    ro.count = 8;
    const RootResult rr = rightmost_roots(LinearDDE(a0, delayed), ro);
    std::vector<cplx> out;
    for (const Root& r : rr.roots)
        if (r.value.imag() > 1e-9 * std::max(1.0, std::abs(r.value))) out.push_back(r.value);
    return out;
}

/// The first Hopf point of mode k from `from` towards `to` (see the header).
HopfPoint wave_hopf(const RingCar& car, int j, double from, double to, cplx z) {
    HopfPoint h;
    h.status = Status::NumericalIssue;
    std::vector<double> pv = car.parameter_values();
    auto at = [&](double p) {
        pv[static_cast<std::size_t>(j)] = p;
        return pv;
    };
    // the rightmost roots with Im > 0 at `from` (rightmost_roots), each followed by Newton on
    // det Delta_k over a grid of 200 steps in p; the first sign change of Re of one of them is
    // located (a root that would enter from the left of these 8 is not seen)
    const int grid = 200;
    std::vector<cplx> tracked;
    try {
        tracked = upper_roots(car, at(from), z);
    } catch (const std::invalid_argument&) {
        return h;  // no uniform flow at from
    }
    if (tracked.empty()) return h;
    double p0 = from, g0 = 0.0;
    cplx l0;
    std::vector<double> previous(tracked.size());
    for (std::size_t r = 0; r < tracked.size(); ++r) previous[r] = tracked[r].real();
    for (int i = 1; i <= grid; ++i) {
        const double p = from + (to - from) * i / grid;
        Eigen::VectorXd xs;
        Mode md;
        try {
            md = mode_at(car, at(p), z, xs);
        } catch (const std::invalid_argument&) {
            return h;  // the uniform flow ends (idm: gap <= eta)
        }
        int crossing = -1;
        cplx l;
        for (std::size_t r = 0; r < tracked.size(); ++r) {
            cplx lr = tracked[r];
            if (!newton_root(md, lr) || !(lr.imag() > 0.0)) continue;
            if (crossing < 0 && (previous[r] < 0.0) != (lr.real() < 0.0)) {
                crossing = static_cast<int>(r);
                l0 = tracked[r];
                g0 = previous[r];
                l = lr;
            }
            tracked[r] = lr;
            previous[r] = lr.real();
        }
        if (crossing < 0) {
            p0 = p;
            continue;
        }
        {
            const double g = l.real();
            // Illinois regula falsi in p on Re lambda, lambda followed by Newton
            double a = p0, ga = g0, b = p, gb = g;
            cplx la = l0, lb = l;
            int side = 0;
            for (int it = 0; it < 100; ++it) {
                const double pm = a - ga * (b - a) / (gb - ga);
                cplx lm = la + (lb - la) * ((pm - a) / (b - a));
                Eigen::VectorXd x;
                const Mode md = mode_at(car, at(pm), z, x);
                if (!newton_root(md, lm)) break;
                const double gm = lm.real();
                h.par = pm;
                h.x = x;
                h.omega = lm.imag();
                h.iterations = it + 1;
                if (std::abs(gm) <= 1e-12 * std::max(1.0, std::abs(lm)) || std::abs(b - a) <= 1e-14 * std::max(1.0, std::abs(pm))) {
                    const Eigen::Matrix2cd D = md.delta(cplx(0.0, h.omega));
                    // the null vector from the row of larger norm
                    const int r = D.row(0).norm() >= D.row(1).norm() ? 0 : 1;
                    h.q.resize(2);
                    h.q << D(r, 1), -D(r, 0);
                    h.q /= h.q.norm();
                    h.residual = std::abs(gm);
                    h.status = h.omega > 0.0 ? Status::Converged : Status::NumericalIssue;
                    return h;
                }
                if ((gm < 0.0) == (ga < 0.0)) {
                    a = pm;
                    ga = gm;
                    la = lm;
                    if (side == -1) gb *= 0.5;
                    side = -1;
                } else {
                    b = pm;
                    gb = gm;
                    lb = lm;
                    if (side == 1) ga *= 0.5;
                    side = 1;
                }
            }
            h.status = Status::MaxIterations;
            return h;
        }
    }
    return h;
}

/// u (or a tangent) on the mesh of c re-represented on `to` (the same degree and number of
/// intervals): the profile interpolated at the new points, T, p and mu kept.
Eigen::VectorXd resample(const Wave& c, const PeriodicMesh& to, const Eigen::VectorXd& u) {
    Eigen::MatrixXd profile(c.P, 2);
    for (int i = 0; i < c.P; ++i) profile.row(i) = u.segment<2>(2 * i).transpose();
    Eigen::VectorXd v(u.size());
    for (int i = 0; i < c.P; ++i) v.segment<2>(2 * i) = orbit_value(c.mesh, profile, to.point(i));
    v.tail<3>() = u.tail<3>();
    return v;
}

/// Moves c's mesh so that it equidistributes |x^(d+1)|^(1/(d+1)) of u (orbit_mesh.hpp); u and
/// the tangent t (when given, renormalised) are re-represented on it.
void remesh(Wave& c, Eigen::VectorXd& u, Eigen::VectorXd* t) {
    const PeriodicMesh next(c.d, orbit_mesh::equidistributed_breakpoints(c.mesh, 2, u));
    u = resample(c, next, u);
    if (t) *t = resample(c, next, *t);
    c.mesh = next;
    if (t) *t /= c.norm(*t);
}

/// u (or a tangent; profile part 2 P values, then T, p, mu) on the mesh of c re-represented on
/// `to`, which may have another number of intervals (same degree).
Eigen::VectorXd resample_to(const Wave& c, const PeriodicMesh& to, const Eigen::VectorXd& u) {
    Eigen::MatrixXd profile(c.P, 2);
    for (int i = 0; i < c.P; ++i) profile.row(i) = u.segment<2>(2 * i).transpose();
    Eigen::VectorXd v(2 * to.points() + 3);
    for (int i = 0; i < to.points(); ++i) v.segment<2>(2 * i) = orbit_value(c.mesh, profile, to.point(i));
    v.tail<3>() = u.tail<3>();
    return v;
}

/// Sets c's mesh to `to` (any number of intervals of c's degree): the sizes and the profile
/// weights of the continuation norm (1 / P, as at the start) follow; u is re-represented.
void apply_mesh(Wave& c, const PeriodicMesh& to) {
    const int N = c.N();
    const Eigen::Vector3d tail = c.w.tail<3>();
    const double profile_weight = c.w(0);
    c.mesh = to;
    c.L = to.intervals();
    c.P = to.points();
    c.w.resize(c.N() + 3);
    c.w.head(c.N()).setConstant(profile_weight * static_cast<double>(N) / c.N());
    c.w.tail<3>() = tail;
}

void set_mesh(Wave& c, const PeriodicMesh& to, Eigen::VectorXd& u) {
    u = resample_to(c, to, u);
    apply_mesh(c, to);
}

/// Every interval of c's mesh split in two (2 L intervals, the equidistribution kept).
PeriodicMesh split_mesh(const PeriodicMesh& m) {
    std::vector<double> t;
    t.reserve(2 * m.breakpoints().size());
    for (std::size_t i = 0; i + 1 < m.breakpoints().size(); ++i) {
        t.push_back(m.breakpoints()[i]);
        t.push_back(0.5 * (m.breakpoints()[i] + m.breakpoints()[i + 1]));
    }
    t.push_back(1.0);
    return PeriodicMesh(m.degree(), t);
}

/// The resolution control of follow (reduced_defect): on an adapted mesh a wave whose defect is
/// above `tolerance` is corrected again on a mesh equidistributed on it, and when still above,
/// the step is halved (the branch stops as "unresolved" below the minimum step); on a fixed
/// mesh the branch stops as "unresolved" at a wave whose defect is above `refuse` (0: off).
struct DefectControl {
    double tolerance = 0.0, refuse = 0.0;
    int max_intervals = 0;
};

/// The branch from the corrected wave u with unit tangent t: pseudo-arclength with the step
/// control of periodic_orbit's branches, the range's faces located, and the special points of
/// every step by the same code (orbit_continuation.hpp: folds; with the full ring's multipliers
/// period doublings and tori), with the reduced corrector and the wave's orbits. The branch ends at
/// max_points waves, on a face of the range, when the amplitude falls below `collapse` times the
/// first wave's (back at the Hopf point), when the period exceeds max_period_factor T0, or when
/// the step falls below min_step. With `adapt` the mesh is re-equidistributed after every wave.
void follow(Wave& c, Eigen::VectorXd u, Eigen::VectorXd t, const Correction& first, const FullRing& full, const PeriodicOrbitOptions& o,
            double collapse, double T0, int max_points, bool adapt, OrbitBranch& b, double& max_drift, std::vector<double>& defects,
            const DefectControl& dc) {
    int N = c.N();
    const double lo = std::min(o.from, o.to), hi = std::max(o.from, o.to);
    // after every wave added: o.progress (waves so far, max_points, p); it may throw to stop the branch
    auto report = [&] {
        if (o.progress) o.progress(static_cast<long>(b.points.size()), max_points, b.points.back().par);
    };
    b.points.push_back(make_orbit(c, u, first, full, o.parameter, o.floquet));
    report();

    defects.push_back(reduced_defect(c, u));
    b.newton_iterations += first.iterations;
    max_drift = std::max(max_drift, std::abs(u(N + 2)));
    const double amp0 = amplitude(b.points.front());
    StepControl step(orbit_continuation::step_control_options(o));
    b.stop = "max_points";
    b.intervals = std::max(b.intervals, c.L);
    if (adapt && !(dc.tolerance > 0.0)) remesh(c, u, &t);  // with the defect control, only when needed
    Eigen::MatrixXd ref;
    Eigen::VectorXd a;
    // A corrected wave vv (defect dv above the tolerance, adaptive mesh) made resolved: corrected
    // again on the mesh equidistributed on it, then, when the step h is already small (below
    // 1e-3 of the largest), on that mesh with every interval split (up to max_intervals); the
    // condition row is the arclength step h from u along t (and the result no jump) or, with
    // fixed_par, p = par. On success c, N, u, t, ref, a, vv, rr and dv are on the new mesh.
    auto resolve = [&](Eigen::VectorXd& vv, Correction& rr, double& dv, bool fixed_par, double par) {
        const double hh = step.h();
        PeriodicMesh next(c.d, orbit_mesh::equidistributed_breakpoints(c.mesh, 2, vv));
        const bool may_split = (fixed_par || hh <= 1e-3 * o.max_step) && 2 * c.L <= dc.max_intervals;
        for (int attempt = 0; attempt < (may_split ? 2 : 1); ++attempt) {
            if (attempt == 1) next = split_mesh(next);
            Wave trial = c;
            apply_mesh(trial, next);
            const int Nn = trial.N();
            const Eigen::VectorXd un = resample_to(c, next, u);
            Eigen::VectorXd tv = resample_to(c, next, t), vn = resample_to(c, next, vv);
            tv /= trial.norm(tv);
            const Eigen::MatrixXd refn = derivative_at_collocation(trial, un);
            Eigen::VectorXd an = trial.w.cwiseProduct(tv), row = an;
            double rhs = an.dot(un + hh * tv);
            if (fixed_par) {
                row = Eigen::VectorXd::Zero(Nn + 3);
                row(Nn + 1) = 1.0;
                rhs = par;
            }
            const Correction rn = correct(trial, vn, refn, row, rhs, o);
            b.newton_iterations += rn.iterations;
            const double dn = rn.ok ? reduced_defect(trial, vn) : std::numeric_limits<double>::quiet_NaN();
            if (rn.ok && dn <= dc.tolerance && (fixed_par || trial.norm(vn - un) <= step.jump_limit())) {
                apply_mesh(c, next);
                N = c.N();
                b.intervals = std::max(b.intervals, c.L);
                u = un;
                t = tv;
                vv = vn;
                rr = rn;
                ref = refn;
                a = an;
                dv = dn;
                return true;
            }
        }
        return false;
    };
    while (static_cast<int>(b.points.size()) < max_points) {
        const PeriodicMesh mesh_before = c.mesh;  // resolve() may move u and t to another mesh
        const Eigen::VectorXd u_before = u, t_before = t;
        const double h = step.h();
        ref = derivative_at_collocation(c, u);
        Eigen::VectorXd v = u + h * t;
        a = c.w.cwiseProduct(t);
        Correction rc = correct(c, v, ref, a, a.dot(u + h * t), o);
        b.newton_iterations += rc.iterations;
        const bool jump = rc.ok && step.jumped(c.norm(v - u));
        double dv = rc.ok && !jump ? reduced_defect(c, v) : std::numeric_limits<double>::quiet_NaN();
        bool unresolved = false;
        if (rc.ok && !jump && adapt && dc.tolerance > 0.0 && !(dv <= dc.tolerance)) unresolved = !resolve(v, rc, dv, false, 0.0);
        if (unresolved) {
            // a smaller step first; the mesh is refined only when the step is already small
            if (!step.reject()) {
                b.stop = "unresolved";
                b.status = Status::NumericalIssue;
                std::ostringstream s;
                s << "the wave at " << b.parameter << " = " << v(N + 1) << " is not resolved on " << c.L << " adapted intervals (relative defect "
                  << dv << " between the collocation points, above " << dc.tolerance << ", with the step below " << o.min_step
                  << "): use more intervals";
                b.message = s.str();
                break;
            }
            continue;
        } else if (rc.ok && !jump && !adapt && dc.refuse > 0.0 && !(dv <= dc.refuse)) {
            b.stop = "unresolved";
            b.status = Status::NumericalIssue;
            std::ostringstream s;
            s << "the wave at " << b.parameter << " = " << v(N + 1) << " is not resolved on " << c.L << " intervals (relative defect " << dv
              << " between the collocation points, above " << dc.refuse << "): the branch stops there; use more intervals";
            b.message = s.str();
            break;
        }
        if (!rc.ok || jump) {
            if (!step.reject()) {
                b.stop = "step_below_minimum";
                b.status = jump ? Status::NumericalIssue : Status::MaxIterations;
                std::ostringstream s;
                s << "the corrector failed at " << b.parameter << " = " << v(N + 1) << " with the step below " << o.min_step;
                b.message = s.str();
                break;
            }
            continue;
        }
        Eigen::VectorXd tn = rc.tangent / c.norm(rc.tangent);
        if (tn.dot(c.w.cwiseProduct(t)) < 0.0) tn = -tn;
        const double p = v(N + 1);
        if (p < lo || p > hi) {  // the orbit on the face of the range
            const double bound = p < lo ? lo : hi;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 3);
            e(N + 1) = 1.0;
            Eigen::VectorXd wv = v;
            Correction rb = correct(c, wv, ref, e, bound, o);
            b.newton_iterations += rb.iterations;
            double db = rb.ok ? reduced_defect(c, wv) : std::numeric_limits<double>::quiet_NaN();
            if (rb.ok && adapt && dc.tolerance > 0.0 && !(db <= dc.tolerance) && !resolve(wv, rb, db, true, bound)) {
                // the step overshot the face onto a wave that is not resolved: a shorter step
                // from u on its own mesh
                if (step.reject()) {
                    apply_mesh(c, mesh_before);
                    N = c.N();
                    u = u_before;
                    t = t_before;
                    continue;
                }
                b.status = Status::NumericalIssue;
                std::ostringstream s;
                s << "the wave on the end of the parameter range (" << b.parameter << " = " << bound << ") is not resolved on " << c.L
                  << " adapted intervals (relative defect " << db << " above " << dc.tolerance << ")";
                b.message = s.str();
                rb.ok = false;
            } else if (rb.ok) {
                b.points.push_back(make_orbit(c, wv, rb, full, o.parameter, o.floquet));
                report();

                defects.push_back(db);
                max_drift = std::max(max_drift, std::abs(wv(N + 2)));
            } else if (b.message.empty()) {
                b.status = Status::MaxIterations;
                b.message = "the wave on the end of the parameter range did not converge";
            }
            b.stop = "bound";
            break;
        }
        PeriodicOrbit orbit = make_orbit(c, v, rc, full, o.parameter, o.floquet);
        // folds, and with the full ring's multipliers period doublings and tori, of this step: the
        // detection and location of periodic_orbit's branches (analysis/bifurcation/internal/orbit_continuation.hpp)
        {
            const Eigen::VectorXd ak = c.w.cwiseProduct(t);
            Eigen::VectorXd best = v;
            Correction bestc = rc;
            orbit_continuation::Probe probe;
            probe.fold_trial = [&](double s, double& g) {
                Eigen::VectorXd wv = u + s * t;
                const Correction rf = correct(c, wv, ref, ak, ak.dot(u + s * t), o);
                b.newton_iterations += rf.iterations;
                if (!rf.ok) return false;
                g = (rf.tangent / c.norm(rf.tangent))(N + 1) * (rf.tangent.dot(ak) < 0.0 ? -1.0 : 1.0);
                best = wv;
                bestc = rf;
                return true;
            };
            probe.fold_orbit = [&] { return make_orbit(c, best, bestc, full, o.parameter, false); };
            probe.orbit_at = [&](double s, PeriodicOrbit& out) {
                Eigen::VectorXd wv = u + s * t;
                const Correction rx = correct(c, wv, ref, ak, ak.dot(u + s * t), o);
                b.newton_iterations += rx.iterations;
                if (!rx.ok) return false;
                out = make_orbit(c, wv, rx, full, o.parameter, true);
                return true;
            };
            orbit_continuation::Step st;
            st.after = static_cast<int>(b.points.size()) - 1;
            st.length = ak.dot(v - u);
            st.h = h;
            st.t_par = t(N + 1);
            st.tn_par = tn(N + 1);
            st.par_scale = std::abs(o.to - o.from);
            const bool crossings = o.floquet && full.system != nullptr;
            if (orbit_continuation::special_points(st, b.points.back(), orbit, crossings, "travelling waves", probe, b)) {
                const double df = reduced_defect(c, best), limit = adapt ? dc.tolerance : dc.refuse;
                if (limit > 0.0 && !(df <= limit) && b.status == Status::Converged) {
                    b.status = Status::NumericalIssue;
                    std::ostringstream s;
                    s << "the fold of travelling waves at " << b.parameter << " = " << b.folds.back().orbit.par << " is not resolved on " << c.L
                      << " intervals (relative defect " << df << " above " << limit << "): use more intervals";
                    b.message = s.str();
                }
            }
        }
        max_drift = std::max(max_drift, std::abs(v(N + 2)));
        const bool collapsed = amplitude(orbit) < collapse * amp0;
        b.points.push_back(std::move(orbit));
        report();

        defects.push_back(dv);
        if (collapsed) {
            b.stop = "hopf";
            break;
        }
        u = v;
        t = tn;
        step.accept(rc.iterations <= 3);
        if (u(N) > o.max_period_factor * T0) {
            b.stop = "period";
            break;
        }
        if (adapt && !(dc.tolerance > 0.0)) remesh(c, u, &t);
    }
}

/// The first wave from the Hopf point h (predictor along Re(q e^{2 pi i s}), corrector with the
/// arclength row along that direction); u and its unit tangent t when the correction is ok.
Correction first_wave(const Wave& c, const HopfPoint& hopf, const PeriodicOrbitOptions& o, Eigen::VectorXd& u, Eigen::VectorXd& t) {
    const int N = c.N();
    Eigen::VectorXd uh(N + 3), t0 = Eigen::VectorXd::Zero(N + 3);
    for (int i = 0; i < c.P; ++i) {
        const cplx e = std::exp(cplx(0.0, 2.0 * kPi * c.mesh.point(i)));
        uh.segment<2>(2 * i) = hopf.x;
        t0.segment<2>(2 * i) = (hopf.q * e).real();
    }
    uh(N) = 2.0 * kPi / hopf.omega;
    uh(N + 1) = hopf.par;
    uh(N + 2) = 0.0;
    t0 /= c.norm(t0);
    u = uh + o.initial_step * t0;
    const Eigen::MatrixXd ref = derivative_at_collocation(c, u);
    const Eigen::VectorXd a = c.w.cwiseProduct(t0);
    Correction r = correct(c, u, ref, a, a.dot(u), o);
    if (r.ok) {
        t = r.tangent / c.norm(r.tangent);
        if (t.dot(c.w.cwiseProduct(t0)) < 0.0) t = -t;
    }
    return r;
}

std::string format_q(double q) {
    std::ostringstream s;
    s << q;
    return s.str();
}

/// The shift fraction q = k / N from which long waves are reached by the homotopy in q.
constexpr double kHomotopyStart = 0.1;
/// The least number of waves of the K / N = 0.1 branch from which the homotopy's start is taken.
constexpr int kHomotopyBranchPoints = 1000;

/// Homotopy in q = c.kappa with the parameter held at p = u(N + 1): natural continuation in log q
/// from c.kappa down to `target` (steps of factor 0.5 at first, halved on failure, grown by 1.5
/// after easy corrections up to a factor 0.25: the StepControl of solve/step_control.hpp on
/// h = -log of the factor), the predictor keeping the profile in s and T q (the time shift from
/// car to car); after every step the mesh is re-equidistributed and the wave corrected on it.
/// false when a step in log q falls below 1e-3.
bool kappa_homotopy(Wave& c, Eigen::VectorXd& u, double target, const PeriodicOrbitOptions& o, int& iterations, int& steps, Correction& last) {
    const int N = c.N();
    Eigen::VectorXd e = Eigen::VectorXd::Zero(N + 3);
    e(N + 1) = 1.0;
    const double p = u(N + 1);
    StepControlOptions so;
    so.initial_step = -std::log(0.5);
    so.max_step = -std::log(0.25);
    so.min_step = 1e-3;
    so.shrink_factor = 0.5;
    so.grow_factor = 1.5;
    StepControl step(so);
    while (c.kappa > target) {
        const double k0 = c.kappa, k1 = std::max(target, k0 * std::exp(-step.h()));
        Eigen::VectorXd v = u;
        v(N) = u(N) * k0 / k1;
        const Eigen::MatrixXd ref = derivative_at_collocation(c, u);
        c.kappa = k1;
        const Correction r = correct(c, v, ref, e, p, o);
        iterations += r.iterations;
        if (!r.ok) {
            c.kappa = k0;
            if (!step.reject()) return false;
            continue;
        }
        u = v;
        last = r;
        ++steps;
        const PeriodicMesh old = c.mesh;
        Eigen::VectorXd w = u;
        remesh(c, w, nullptr);
        const Correction rm = correct(c, w, derivative_at_collocation(c, w), e, p, o);
        iterations += rm.iterations;
        if (rm.ok) {
            u = w;
            last = rm;
        } else {
            c.mesh = old;
        }
        step.accept(r.iterations <= 3);
    }
    return true;
}

/// Long waves (see the header): the wave of q0 = kHomotopyStart from its own Hopf point, the
/// homotopy in q down to c.kappa at the parameter of that branch's largest wave inside the range,
/// then the branch in the parameter in both directions on an adapted mesh, joined at that wave
/// (the direction that ends at the smaller amplitude, towards the Hopf point, first).
void long_wave_branch(Wave& c, const RingCar& car, int j, const FullRing& full, const TravellingWaveOptions& opt, double T0, TravellingWaveBranch& res) {
    const PeriodicOrbitOptions& o = opt.orbit;
    OrbitBranch& b = res.branch;
    const int N = c.N();
    const double q = c.kappa;
    auto fail = [&](const std::string& why) {
        b.points.clear();
        b.folds.clear();
        b.period_doublings.clear();
        b.tori.clear();
        b.status = Status::MaxIterations;
        b.stop = "first_orbit_failed";
        b.message = "the first travelling wave from the Hopf point did not converge, and the homotopy in K / N from " + format_q(kHomotopyStart) +
                    " failed: " + why;
    };
    const double phase = 2.0 * kPi * kHomotopyStart;
    const HopfPoint h0 = wave_hopf(car, j, o.from, o.to, cplx(std::cos(phase), std::sin(phase)));
    if (h0.status != Status::Converged) return fail("no Hopf point of the shorter wave in the range");
    c.kappa = kHomotopyStart;
    const double T00 = 2.0 * kPi / h0.omega;
    const double wT = c.w(N);
    c.w(N) = 1.0 / (T00 * T00);
    Eigen::VectorXd u, t;
    Correction r = first_wave(c, h0, o, u, t);
    b.newton_iterations += r.iterations;
    if (!r.ok) return fail("its first wave did not converge");
    OrbitBranch b0;
    b0.parameter = o.parameter;
    PeriodicOrbitOptions o0 = o;
    o0.floquet = false;
    double drift0 = 0.0;
    const PeriodicMesh mesh0 = c.mesh;
    std::vector<double> defects0;
    // at least kHomotopyBranchPoints waves: the branch must pass its fold when it has one (the IDM
    // ring: the homotopy at a parameter short of the fold meets a fold in K / N, see the header)
    follow(c, u, t, r, FullRing{}, o0, 0.5, T00, std::max(o.max_points, kHomotopyBranchPoints), false, b0, drift0, defects0, DefectControl{});
    b.newton_iterations += b0.newton_iterations - r.iterations;
    c.mesh = mesh0;
    const double lo = std::min(o.from, o.to), hi = std::max(o.from, o.to), margin = 0.05 * (hi - lo);
    int pick = -1;
    for (std::size_t i = 0; i < b0.points.size(); ++i) {
        const PeriodicOrbit& pt = b0.points[i];
        if (pt.par < lo + margin || pt.par > hi - margin) continue;
        if (pick < 0 || amplitude(pt) > amplitude(b0.points[static_cast<std::size_t>(pick)])) pick = static_cast<int>(i);
    }
    if (pick < 0) return fail("the shorter wave's branch has no wave inside the range");
    const PeriodicOrbit& start = b0.points[static_cast<std::size_t>(pick)];
    u.resize(N + 3);
    for (int i = 0; i < c.P; ++i) u.segment<2>(2 * i) = start.profile.row(i).transpose();
    u(N) = start.period;
    u(N + 1) = start.par;
    u(N + 2) = 0.0;
    int steps = 0, its = 0;
    Correction last;
    remesh(c, u, nullptr);
    const bool ok = kappa_homotopy(c, u, q, o, its, steps, last);
    b.newton_iterations += its;
    c.w(N) = wT;
    if (!ok) return fail("the homotopy stopped at K / N = " + format_q(c.kappa));
    res.homotopy_par = u(N + 1);
    res.homotopy_steps = steps;
    // the number of intervals: every interval split in two (then the mesh equidistributed again)
    // until the wave's defect is at most half the tolerance (room for the branch), at most
    // max_intervals
    for (double d0 = reduced_defect(c, u); opt.defect_tolerance > 0.0 && !(d0 <= 0.5 * opt.defect_tolerance); d0 = reduced_defect(c, u)) {
        if (2 * c.L > opt.max_intervals) {
            b.points.clear();
            b.folds.clear();
            b.period_doublings.clear();
            b.tori.clear();
            b.status = Status::NumericalIssue;
            b.stop = "unresolved";
            std::ostringstream s;
            s << "the long wave reached by the homotopy in K / N at " << o.parameter << " = " << res.homotopy_par << " is not resolved on " << c.L
              << " adapted intervals (relative defect " << d0 << " between the collocation points, above " << 0.5 * opt.defect_tolerance
              << "), and " << 2 * c.L << " would exceed the limit of " << opt.max_intervals << " intervals";
            b.message = s.str();
            return;
        }
        set_mesh(c, split_mesh(c.mesh), u);
        for (int pass = 0; pass < 2; ++pass) {
            Eigen::VectorXd e = Eigen::VectorXd::Zero(c.N() + 3);
            e(c.N() + 1) = 1.0;
            Eigen::VectorXd w = u;
            if (pass == 1) remesh(c, w, nullptr);
            const Correction rm = correct(c, w, derivative_at_collocation(c, w), e, res.homotopy_par, o);
            b.newton_iterations += rm.iterations;
            if (!rm.ok) return fail("the long wave did not converge on " + std::to_string(c.L) + " intervals");
            u = w;
            last = rm;
        }
    }
    b.intervals = c.L;
    t = last.tangent / c.norm(last.tangent);
    // the fronts move along s as the parameter changes: with the profile weighted as on short
    // waves the steps in the parameter are tiny; its weight is lowered 1000 times
    Wave c_start = c;
    c_start.w.head(c.N()) *= 1e-3;
    OrbitBranch side[2];
    std::vector<double> side_defects[2];
    double drift = 0.0;
    const int half = std::max(2, (o.max_points + 1) / 2);
    for (int k = 0; k < 2; ++k) {
        side[k].parameter = o.parameter;
        Wave ck = c_start;
        follow(ck, u, k == 0 ? t : Eigen::VectorXd(-t), last, full, o, 0.0, T0, k == 0 ? half : o.max_points - half + 1, true, side[k], drift, side_defects[k],
               DefectControl{opt.defect_tolerance, 0.0, opt.max_intervals});
        b.newton_iterations += side[k].newton_iterations - (k == 0 ? 0 : last.iterations);
    }
    res.max_drift = std::max(res.max_drift, drift);
    b.intervals = std::max({b.intervals, side[0].intervals, side[1].intervals});
    // the side ending at the smaller amplitude (towards the Hopf point) first, reversed
    const int first = amplitude(side[0].points.back()) <= amplitude(side[1].points.back()) ? 0 : 1;
    const OrbitBranch& A = side[first];
    const OrbitBranch& B = side[1 - first];
    const int nA = static_cast<int>(A.points.size());
    b.points.assign(A.points.rbegin(), A.points.rend());
    res.defects.assign(side_defects[first].rbegin(), side_defects[first].rend());
    res.defects.insert(res.defects.end(), side_defects[1 - first].begin() + 1, side_defects[1 - first].end());
    for (OrbitFold f : A.folds) {
        f.after = nA - 2 - f.after;
        b.folds.push_back(f);
    }
    std::reverse(b.folds.begin(), b.folds.end());
    for (std::size_t i = 1; i < B.points.size(); ++i) b.points.push_back(B.points[i]);
    for (OrbitFold f : B.folds) {
        f.after += nA - 1;
        b.folds.push_back(f);
    }
    // period doublings and tori (only with the full ring's multipliers) renumbered the same way
    for (int k = 0; k < 2; ++k) {
        std::vector<OrbitCrossing>& out = k == 0 ? b.period_doublings : b.tori;
        const std::vector<OrbitCrossing>& a_side = k == 0 ? A.period_doublings : A.tori;
        const std::vector<OrbitCrossing>& b_side = k == 0 ? B.period_doublings : B.tori;
        for (auto it = a_side.rbegin(); it != a_side.rend(); ++it) {
            out.push_back(*it);
            out.back().after = nA - 2 - it->after;
        }
        for (OrbitCrossing x : b_side) {
            x.after += nA - 1;
            out.push_back(x);
        }
    }
    b.stop = B.stop;
    b.status = B.status;
    std::ostringstream s;
    s << b.points.size() << " travelling waves, reached by a homotopy in K / N from " << kHomotopyStart << " at " << o.parameter << " = "
      << res.homotopy_par << " (" << steps << " steps) and continued both ways on an adapted mesh; towards the Hopf point it ended: " << A.stop;
    if (!A.message.empty() && A.status != Status::Converged) s << " (" << A.message << ")";
    s << "; the other way: " << B.stop;
    if (!B.message.empty() && B.status != Status::Converged) s << " (" << B.message << ")";
    b.message = s.str();
}

}  // namespace

bool TravellingWaveOptions::is_valid(std::string* why) const {
    std::string w;
    if (model != "ov" && model != "idm") w = "model " + model + ": expected ov or idm";
    else if (cars < 2) w = "cars = " + std::to_string(cars) + ": expected a ring of at least 2 cars";
    else if (wave < 1 || wave > cars - 1) w = "wave = " + std::to_string(wave) + ": expected a wave number from 1 to N - 1 = " + std::to_string(cars - 1);
    else if (full_ring_floquet_limit < 0) w = "full_ring_floquet_limit: expected an integer >= 0";
    else if (!(defect_tolerance >= 0.0) || !std::isfinite(defect_tolerance)) w = "defect_tolerance: expected a number >= 0";
    else if (!(unresolved_defect >= 0.0) || !std::isfinite(unresolved_defect)) w = "unresolved_defect: expected a number >= 0";
    else if (max_intervals < orbit.intervals) w = "max_intervals = " + std::to_string(max_intervals) + ": expected at least the intervals (" + std::to_string(orbit.intervals) + ")";
    else if (!orbit.is_valid(&w)) w = "orbit options: " + w;
    else if (!stability.is_valid(&w)) w = "stability options: " + w;
    if (!w.empty() && why) *why = w;
    return w.empty();
}

Eigen::VectorXd wave_car_state(const PeriodicMesh& mesh, const PeriodicOrbit& orbit, int cars, int wave, long car, double s) {
    // s + car k / N mod 1, the integer part of car k taken first (exact for large N)
    const long shift = static_cast<long>((static_cast<long long>(car) * wave) % cars);
    return orbit_value(mesh, orbit.profile, s + static_cast<double>(shift) / cars);
}

WaveRingCheck check_wave_on_full_ring(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars, int wave,
                                      int degree, const PeriodicOrbit& orbit, int samples) {
    if (samples < 1) throw std::invalid_argument("check_wave_on_full_ring: samples = " + std::to_string(samples) + ": expected at least 1");
    if (orbit.profile.cols() != 2 || orbit.profile.rows() < 1 || !(orbit.period > 0.0))
        throw std::invalid_argument("check_wave_on_full_ring: expected a travelling wave (a profile of car 0's 2 variables and a period > 0)");
    if (wave < 1 || wave >= cars) throw std::invalid_argument("check_wave_on_full_ring: wave = " + std::to_string(wave) + ": expected 1 to N - 1");
    const NonlinearRing ring = make_nonlinear_ring(model, cars, parameters, parameter, orbit.par);
    const NonlinearDDE& sys = *ring.system;
    const PeriodicMesh mesh(degree, orbit.breakpoints);
    if (mesh.points() != orbit.profile.rows()) throw std::invalid_argument("check_wave_on_full_ring: the profile does not match the mesh of the given degree");
    const int n = sys.dimension(), m = sys.delay_count();
    const std::vector<double> tau = sys.delays();
    const double T = orbit.period;
    const double headway = sys.parameter(model == "ov" ? "headway" : "gap");
    std::vector<double> l(static_cast<std::size_t>(degree) + 1), dl(l);
    // car i's (h, v) and d/ds at time s of the period
    auto car_at = [&](long car, double s, Eigen::Vector2d& x, Eigen::Vector2d* dx) {
        const long shift = static_cast<long>((static_cast<long long>(car) * wave) % cars);
        double q = s + static_cast<double>(shift) / cars;
        q -= std::floor(q);
        if (q >= 1.0) q = 0.0;
        const int i = mesh.interval_of(q);
        mesh.basis(i, q, l.data(), dl.data());
        x.setZero();
        if (dx) dx->setZero();
        for (int j = 0; j <= degree; ++j) {
            const Eigen::Vector2d xj = orbit.profile.row((i * degree + j) % mesh.points()).transpose();
            x += l[static_cast<std::size_t>(j)] * xj;
            if (dx) *dx += dl[static_cast<std::size_t>(j)] * xj;
        }
    };
    WaveRingCheck r;
    r.samples = samples;
    Eigen::VectorXd stacked(static_cast<Eigen::Index>(n) * (m + 1)), dX(n);
    Eigen::Vector2d x, dx;
    for (int k = 0; k < samples; ++k) {
        const double s = (k + 0.5) / samples;
        double length = 0.0;
        for (int q = 0; q <= m; ++q) {
            const double sq = q == 0 ? s : s - tau[static_cast<std::size_t>(q - 1)] / T;
            for (long car = 0; car < cars; ++car) {
                car_at(car, sq, x, q == 0 ? &dx : nullptr);
                const Eigen::Index base = static_cast<Eigen::Index>(q) * n;
                if (car + 1 < cars) stacked(base + car) = x(0);
                stacked(base + cars - 1 + car) = x(1);
                if (q == 0) {
                    length += x(0);
                    if (car + 1 < cars) dX(car) = dx(0) / T;
                    dX(cars - 1 + car) = dx(1) / T;
                }
            }
        }
        r.length_error = std::max(r.length_error, std::abs(length / (cars * headway) - 1.0));
        const Eigen::VectorXd F = sys.f(stacked);
        const Eigen::VectorXd d = (dX - F).cwiseAbs();
        r.defect_h = std::max(r.defect_h, d.head(cars - 1).maxCoeff());
        r.defect_v = std::max(r.defect_v, d.tail(cars).maxCoeff());
        r.scale_h = std::max(r.scale_h, dX.head(cars - 1).cwiseAbs().maxCoeff());
        r.scale_v = std::max(r.scale_v, dX.tail(cars).cwiseAbs().maxCoeff());
    }
    r.relative = std::max(r.defect_h / r.scale_h, r.defect_v / r.scale_v);
    return r;
}

TravellingWaveBranch travelling_wave_branch(const ParameterMap& parameters, const TravellingWaveOptions& options) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("travelling waves: " + why);
    const PeriodicOrbitOptions& o = options.orbit;
    ParameterMap start = parameters;
    const RingCar probe(options.model, parameters);
    const int j = probe.parameter_index(o.parameter);  // throws for an unknown parameter
    start[o.parameter] = o.from;
    TravellingWaveBranch res;
    res.cars = options.cars;
    res.wave = options.wave;
    OrbitBranch& b = res.branch;
    b.parameter = o.parameter;
    b.degree = o.degree;
    b.intervals = o.intervals;
    const PeriodicMesh mesh(o.degree, o.intervals);
    {
        std::ostringstream s;
        s << "travelling wave of wave number " << options.wave << " on a ring of " << options.cars
          << " cars in the reduced form (one car, the leader shifted by k T / N): piecewise polynomial collocation, degree " << o.degree << " on "
          << o.intervals << " intervals at Gauss-Legendre points; Newton with a sparse LU (Eigen SparseLU, COLAMD); pseudo-arclength; "
          << (options.cars <= options.full_ring_floquet_limit && o.floquet ? "Floquet multipliers of the full ring along the wave"
              : o.floquet && options.sparse_floquet ? "Floquet multipliers of the full ring along the wave, matrix-free (Arnoldi on the monodromy applied by sparse sweeps)"
                                                    : "no Floquet multipliers (the ring's stability is not computed)");
        b.method = s.str();
    }
    ParameterMap at_from = parameters;
    at_from[o.parameter] = o.from;
    std::unique_ptr<RingCar> car;
    try {
        car = std::make_unique<RingCar>(options.model, at_from);
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("travelling waves at ") + o.parameter + " = from: " + e.what());
    }
    const double phase = 2.0 * kPi * (static_cast<double>(options.wave) / options.cars);
    const cplx z(std::cos(phase), std::sin(phase));
    res.hopf = wave_hopf(*car, j, o.from, o.to, z);
    if (res.hopf.status != Status::Converged) {
        b.status = Status::NumericalIssue;
        b.stop = "first_orbit_failed";
        std::ostringstream s;
        s << "no Hopf point of ring mode " << options.wave << " with omega > 0 on the uniform flow for " << o.parameter << " in [" << o.from << ", "
          << o.to << "]" << (res.hopf.status == Status::MaxIterations ? " was located" : "")
          << " (a Hopf point of modes k and N - k is a wave of only one of the two wave numbers: if the ring has one in this range, try "
          << options.cars - options.wave << ")";
        b.message = s.str();
        return res;
    }
    FullRing full;
    if (o.floquet && options.cars <= options.full_ring_floquet_limit) {
        full.system = make_nonlinear_ring(options.model, options.cars, at_from).system;
        full.cars = options.cars;
        full.wave = options.wave;
    }
    Wave c(*car, mesh);
    c.kappa = static_cast<double>(options.wave) / options.cars;
    c.j = j;
    c.d = mesh.degree();
    c.L = mesh.intervals();
    c.P = mesh.points();
    c.base = car->parameter_values();
    const int N = c.N();
    const double T0 = 2.0 * kPi / res.hopf.omega;
    c.w = Eigen::VectorXd::Zero(N + 3);
    c.w.head(N).setConstant(1.0 / c.P);
    c.w(N) = 1.0 / (T0 * T0);
    c.w(N + 1) = 1.0 / ((o.to - o.from) * (o.to - o.from));

    // the first orbit from the Hopf point along Re(q e^{2 pi i s})
    Eigen::VectorXd u, t;
    Correction r;
    if (!options.force_homotopy || c.kappa >= kHomotopyStart) r = first_wave(c, res.hopf, o, u, t);
    if (r.ok) {
        // the branch (uniform mesh)
        follow(c, u, t, r, full, o, 0.5, T0, o.max_points, false, b, res.max_drift, res.defects, DefectControl{0.0, options.unresolved_defect, 0});
    } else if (c.kappa < kHomotopyStart) {
        if (!options.force_homotopy) b.newton_iterations += r.iterations;
        long_wave_branch(c, *car, j, full, options, T0, res);
        if (b.points.empty()) return res;
    } else {
        b.newton_iterations += r.iterations;
        b.status = Status::MaxIterations;
        b.stop = "first_orbit_failed";
        b.message = "the first travelling wave from the Hopf point did not converge (try a smaller initial step or a finer mesh)";
        return res;
    }
    for (double dfc : res.defects) res.max_defect = std::max(res.max_defect, dfc);
    if (o.floquet && options.sparse_floquet && !full.system) wave_stability::matrix_free_pass(parameters, options, res);
    for (const PeriodicOrbit& pt : b.points) {
        b.max_residual = std::max(b.max_residual, pt.residual);
        if (std::isfinite(pt.trivial_distance)) b.max_trivial_distance = std::max(b.max_trivial_distance, pt.trivial_distance);
    }
    if (full.system) {
        res.full_ring_stability = true;
        res.stability_method = "dense";
    }
    if (b.message.empty()) {
        std::ostringstream s;
        s << b.points.size() << " travelling waves, ended: " << b.stop;
        b.message = s.str();
    }
    return res;
}

}  // namespace ddemap
