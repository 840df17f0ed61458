#include "ddemap/analysis/bifurcation/wave_stability.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

// GCC 12 reports a false -Wuse-after-free inside Spectra's Hessenberg eigenvector code (as in
// periodic_orbit.cpp)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#endif
#include <Spectra/GenEigsSolver.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include "core/internal/text.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"
#include "ddemap/traffic/ring_car.hpp"

#include "analysis/bifurcation/internal/wave_stability_pass.hpp"

namespace ddemap {

namespace {

using Triplet = Eigen::Triplet<double>;
using SpD = Eigen::SparseMatrix<double>;
using SpR = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// The collocated variational problem of the ring along the wave, condensed to the window (see
/// the header): per interval i the entries on the known values (window and earlier points,
/// global storage (g - gmin) n + variable) and the factorised diagonal block (the d new points).
struct RingMonodromy {
    int n = 0, d = 0, L = 0, P = 0, cars = 0;
    long gmin = 0, nh = 0;
    std::vector<SpR> known;
    std::vector<std::unique_ptr<Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>>>> diag;
    Eigen::VectorXd u;  // the length direction: 1 / N on the headways at s = 0
    mutable Eigen::VectorXd all;
    mutable long applications = 0;
    double scale = 1.0;  // an estimate of |M| (max over the columns tried of |M e| / |e|)

    int window() const { return static_cast<int>(nh * n); }
    /// e(y) = sum of the headways at s = 0
    double length(const double* y) const {
        double s = 0.0;
        const long base = -gmin * n;
        for (int i = 0; i < cars; ++i) s += y[base + 2 * i];
        return s;
    }
    /// y_out = Q M Q y_in
    void apply(const double* in, double* out) const {
        const long H = window();
        all.setZero((nh + P) * static_cast<long>(n));
        Eigen::Map<const Eigen::VectorXd> x(in, H);
        all.head(H) = x - u * length(in);
        for (int i = 0; i < L; ++i) {
            const Eigen::VectorXd rhs = -(known[static_cast<std::size_t>(i)] * all);
            const Eigen::VectorXd sol = diag[static_cast<std::size_t>(i)]->solve(rhs);
            all.segment((static_cast<long>(i) * d + 1 - gmin) * n, static_cast<long>(d) * n) = sol;
        }
        Eigen::Map<Eigen::VectorXd> y(out, H);
        y = all.segment(static_cast<long>(P) * n, H);
        y -= u * length(out);
        ++applications;
    }
};

/// Spectra's operator interface for RingMonodromy.
struct MonodromyOp {
    using Scalar = double;
    const RingMonodromy* m = nullptr;
    Eigen::Index rows() const { return m->window(); }
    Eigen::Index cols() const { return m->window(); }
    void perform_op(const double* in, double* out) const { m->apply(in, out); }
};

double cpu_seconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

/// Builds the monodromy of the ring along the spread wave; false (with why) on a singular block
/// or a non-finite coefficient.
bool build(const RingCar& car, const std::vector<double>& pv, int cars, int wave, const PeriodicMesh& mesh, const PeriodicOrbit& orbit,
           RingMonodromy& m, Eigen::VectorXd& xdot, std::string& why) {
    const int N = cars, n = 2 * N, d = mesh.degree(), L = mesh.intervals(), P = mesh.points();
    m.n = n;
    m.d = d;
    m.L = L;
    m.P = P;
    m.cars = N;
    const double T = orbit.period;
    const std::vector<double> tau = car.delays(pv);
    const double headway = pv[static_cast<std::size_t>(car.length_parameter())];
    // the wave spread to the cars on the mesh points, the last headway by the length (as the
    // dense path's elimination)
    Eigen::MatrixXd Y(P, n);
    for (int g = 0; g < P; ++g) {
        double sum = 0.0;
        for (int i = 0; i < N; ++i) {
            const Eigen::VectorXd x = wave_car_state(mesh, orbit, N, wave, i, mesh.point(g));
            Y(g, 2 * i) = x(0);
            Y(g, 2 * i + 1) = x(1);
            if (i + 1 < N) sum += x(0);
        }
        Y(g, 2 * (N - 1)) = N * headway - sum;
    }
    // the window, as periodic_orbit's multipliers()
    double rmax = 0.0;
    for (double t : tau) rmax = std::max(rmax, t / T);
    long gmin = 0;
    if (rmax > 0.0) {
        const double fl = std::floor(-rmax);
        double w = -rmax - fl;
        if (w >= 1.0) w = 0.0;
        gmin = static_cast<long>(fl) * P + static_cast<long>(mesh.interval_of(w)) * d;
    }
    m.gmin = gmin;
    m.nh = 1 - gmin;
    const long total = (m.nh + P) * static_cast<long>(n);
    if (total > static_cast<long>(std::numeric_limits<int>::max()) / 2) {
        why = "the collocated ring is too large for sparse indices";
        return false;
    }
    m.u = Eigen::VectorXd::Zero(m.window());
    for (int i = 0; i < N; ++i) m.u(-gmin * n + 2 * i) = 1.0 / N;
    // x' on the window (the eigenvector of the trivial multiplier): the derivative of the
    // interpolant of Y at each window point (the interval to its left; s = 0 that of s = 1)
    xdot = Eigen::VectorXd::Zero(m.window());
    std::vector<double> l(static_cast<std::size_t>(d) + 1), dl(l), lk(l), dlk(l);
    auto rowcombo = [&](int interval, const std::vector<double>& coef) {
        Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
        for (int jj = 0; jj <= d; ++jj) v += coef[static_cast<std::size_t>(jj)] * Y.row((interval * d + jj) % P).transpose();
        return v;
    };
    for (long h = 0; h < m.nh; ++h) {
        const long g = gmin + h;
        const long gm = ((g % P) + P) % P;  // the point mod P
        const int interval = gm == 0 ? L - 1 : static_cast<int>((gm - 1) / d);
        const double s = gm == 0 ? 1.0 : mesh.point(static_cast<int>(gm));
        mesh.basis(interval, s, l.data(), dl.data());
        xdot.segment(h * n, n) = rowcombo(interval, dl) / T;
    }
    // the collocation equations, interval by interval
    m.known.resize(static_cast<std::size_t>(L));
    m.diag.resize(static_cast<std::size_t>(L));
    const int m3 = 3;
    std::vector<std::vector<double>> lkv(m3, l);
    std::vector<int> lki(m3);
    std::vector<long> per(m3);
    Eigen::VectorXd stacked(8);
    const Eigen::Matrix2d eye = Eigen::Matrix2d::Identity();
    for (int i = 0; i < L; ++i) {
        std::vector<Triplet> tk, td;
        tk.reserve(static_cast<std::size_t>(d) * n * 16 * (d + 1));
        td.reserve(static_cast<std::size_t>(d) * n * 8 * (d + 1));
        const long first = static_cast<long>(i) * d + 1, last = static_cast<long>(i) * d + d;  // the new points
        auto put = [&](int row, long gl, int var0, const Eigen::Matrix2d& blk, double factor) {
            for (int q = 0; q < 2; ++q)
                for (int r = 0; r < 2; ++r) {
                    const double v = factor * blk(r, q);
                    if (v == 0.0) continue;
                    if (gl >= first && gl <= last)
                        td.emplace_back(row + r, static_cast<int>((gl - first) * n + var0 + q), v);
                    else
                        tk.emplace_back(row + r, static_cast<int>((gl - gmin) * n + var0 + q), v);
                }
        };
        for (int g = 0; g < d; ++g) {
            const double s = mesh.collocation_point(i, g);
            mesh.basis(i, s, l.data(), dl.data());
            const Eigen::VectorXd cur = rowcombo(i, l);
            std::vector<Eigen::VectorXd> del(m3);
            for (int k = 0; k < m3; ++k) {
                const auto uk = static_cast<std::size_t>(k);
                const double sk = s - tau[uk] / T;
                double wrapped = sk - std::floor(sk);
                if (wrapped >= 1.0) wrapped = 0.0;
                per[uk] = static_cast<long>(std::floor(sk));
                lki[uk] = mesh.interval_of(wrapped);
                mesh.basis(lki[uk], wrapped, lkv[uk].data(), dlk.data());
                del[uk] = rowcombo(lki[uk], lkv[uk]);
            }
            for (int c = 0; c < N; ++c) {
                const int lead = (c + 1) % N;
                stacked.segment<2>(0) = cur.segment<2>(2 * c);
                stacked.segment<2>(2) = del[0].segment<2>(2 * c);
                stacked.segment<2>(4) = del[1].segment<2>(2 * lead);
                stacked.segment<2>(6) = del[2].segment<2>(2 * lead);
                const std::vector<Eigen::MatrixXd> A = car.jacobians(stacked, pv);
                for (const auto& a : A)
                    if (!a.allFinite()) {
                        why = "a non-finite Jacobian of the ring along the wave";
                        return false;
                    }
                const int row = g * n + 2 * c;
                for (int jj = 0; jj <= d; ++jj) {
                    const long gl = static_cast<long>(i) * d + jj;
                    const Eigen::Matrix2d own = dl[static_cast<std::size_t>(jj)] * eye - T * l[static_cast<std::size_t>(jj)] * Eigen::Matrix2d(A[0]);
                    put(row, gl, 2 * c, own, 1.0);
                }
                for (int k = 0; k < m3; ++k) {
                    const auto uk = static_cast<std::size_t>(k);
                    const int var0 = RingCar::is_lead(k + 1) ? 2 * lead : 2 * c;
                    const Eigen::Matrix2d blk = A[uk + 1];
                    for (int jj = 0; jj <= d; ++jj) {
                        const long gl = per[uk] * P + static_cast<long>(lki[uk]) * d + jj;
                        put(row, gl, var0, blk, -T * lkv[uk][static_cast<std::size_t>(jj)]);
                    }
                }
            }
        }
        SpR K(d * n, total);
        K.setFromTriplets(tk.begin(), tk.end());
        K.makeCompressed();
        m.known[static_cast<std::size_t>(i)] = std::move(K);
        SpD D(d * n, d * n);
        D.setFromTriplets(td.begin(), td.end());
        D.makeCompressed();
        auto lu = std::make_unique<Eigen::SparseLU<SpD, Eigen::COLAMDOrdering<int>>>();
        lu->compute(D);
        if (lu->info() != Eigen::Success) {
            why = "a singular collocation block of the ring (interval " + std::to_string(i) + ")";
            return false;
        }
        m.diag[static_cast<std::size_t>(i)] = std::move(lu);
    }
    return true;
}

std::string fmt(double x) { return detail::significant(x, 3); }

}  // namespace

bool WaveStabilityOptions::is_valid(std::string* why) const {
    std::string w;
    if (min_multipliers < 1) w = "min_multipliers: expected an integer >= 1";
    else if (max_multipliers < min_multipliers) w = "max_multipliers: expected an integer >= min_multipliers";
    else if (!(arnoldi_tolerance > 0.0) || !std::isfinite(arnoldi_tolerance)) w = "arnoldi_tolerance: expected a number > 0";
    else if (max_restarts < 1) w = "max_restarts: expected an integer >= 1";
    else if (dense_limit < 0) w = "dense_limit: expected an integer >= 0";
    else if (uniform_intervals < 2) w = "uniform_intervals: expected an integer >= 2";
    else if (!(resolution_tolerance > 0.0) || !std::isfinite(resolution_tolerance)) w = "resolution_tolerance: expected a number > 0";
    if (why) *why = w;
    return w.empty();
}

WaveStability wave_ring_stability(const std::string& model, const ParameterMap& parameters, const std::string& parameter, int cars, int wave,
                                  int degree, const PeriodicOrbit& orbit, const WaveStabilityOptions& options) {
    std::string bad;
    if (!options.is_valid(&bad)) throw std::invalid_argument("wave stability: " + bad);
    if (cars < 2 || cars > 2000) throw std::invalid_argument("wave stability: cars = " + std::to_string(cars) + ": expected 2 to 2000");
    if (wave < 1 || wave >= cars) throw std::invalid_argument("wave stability: wave = " + std::to_string(wave) + ": expected 1 to N - 1");
    if (orbit.profile.cols() != 2 || orbit.profile.rows() < 1 || !(orbit.period > 0.0) || !std::isfinite(orbit.period))
        throw std::invalid_argument("wave stability: expected a travelling wave (a profile of car 0's 2 variables and a period > 0)");
    const PeriodicMesh given(degree, orbit.breakpoints);
    if (given.points() != orbit.profile.rows()) throw std::invalid_argument("wave stability: the profile does not match the mesh of the given degree");
    ParameterMap at = parameters;
    at[parameter] = orbit.par;
    const RingCar car(model, at);
    (void)car.parameter_index(parameter);  // throws for an unknown parameter
    const std::vector<double> pv = car.parameter_values();

    const double t0 = cpu_seconds();
    WaveStability res;
    // a non-uniform mesh (equidistributed on car 0) does not resolve the other cars: uniform
    bool uniform = true;
    for (int i = 0; i < given.intervals(); ++i)
        if (std::abs(given.width(i) * given.intervals() - 1.0) > 1e-9) uniform = false;
    PeriodicOrbit wave_on_mesh;
    const PeriodicOrbit* wo = &orbit;
    std::unique_ptr<PeriodicMesh> mesh_ptr;
    if (uniform) {
        mesh_ptr = std::make_unique<PeriodicMesh>(given);
    } else {
        mesh_ptr = std::make_unique<PeriodicMesh>(degree, std::max(given.intervals(), options.uniform_intervals));
        wave_on_mesh = orbit;
        wave_on_mesh.breakpoints = mesh_ptr->breakpoints();
        wave_on_mesh.profile.resize(mesh_ptr->points(), 2);
        for (int g = 0; g < mesh_ptr->points(); ++g) wave_on_mesh.profile.row(g) = orbit_value(given, orbit.profile, mesh_ptr->point(g)).transpose();
        wo = &wave_on_mesh;
    }
    const PeriodicMesh& mesh = *mesh_ptr;
    {
        std::ostringstream s;
        s << "Floquet multipliers of the full ring of " << cars << " cars along the wave, matrix-free: collocated variational equation (degree " << degree
          << " on " << mesh.intervals() << (uniform ? "" : " uniform") << " intervals), monodromy applied by a forward sweep with sparse LU per interval, ring length projected out; ";
        res.method = s.str();
    }
    RingMonodromy m;
    Eigen::VectorXd xdot;
    std::string why;
    if (!build(car, pv, cars, wave, mesh, *wo, m, xdot, why)) {
        res.status = Status::NumericalIssue;
        res.message = why;
        res.method += "not computed";
        res.seconds = cpu_seconds() - t0;
        return res;
    }
    const int H = m.window();
    res.window = H;
    // |M| estimated from one application (it scales the Ritz residuals)
    {
        Eigen::VectorXd e = Eigen::VectorXd::Ones(H), y(H);
        m.apply(e.data(), y.data());
        m.scale = std::max(1.0, y.norm() / e.norm());
    }
    // the resolution check: x' must be (nearly) the eigenvector of 1
    {
        Eigen::VectorXd mx(H);
        m.apply(xdot.data(), mx.data());
        res.xdot_residual = (mx - xdot).norm() / xdot.norm();
    }
    if (!(res.xdot_residual <= options.resolution_tolerance)) {
        res.status = Status::MaxDegreeReached;
        std::ostringstream msg;
        msg << "the wave spread to the " << cars << " cars is not resolved on the ring's mesh (" << mesh.intervals()
            << " intervals): |M x' - x'| / |x'| = " << fmt(res.xdot_residual) << " > " << fmt(options.resolution_tolerance) << " (more intervals needed)";
        res.message = msg.str();
        res.method += "not computed";
        res.applications = static_cast<int>(m.applications);
        res.seconds = cpu_seconds() - t0;
        return res;
    }
    std::vector<cplx> vals;
    Eigen::MatrixXcd vecs;
    bool all_found = false;
    bool converged_run = false;
    int nev_used = 0;
    auto residual = [&](const Eigen::VectorXcd& v, cplx mu) {
        Eigen::VectorXd re = v.real(), im = v.imag(), mre(H), mim(H);
        m.apply(re.data(), mre.data());
        m.apply(im.data(), mim.data());
        const Eigen::VectorXcd mv = mre.cast<cplx>() + cplx(0.0, 1.0) * mim.cast<cplx>();
        return (mv - mu * v).norm() / (v.norm() * m.scale);
    };
    // the trivial multiplier: largest |cos| with x'
    auto alignment = [&](const Eigen::VectorXcd& v) { return std::abs(v.dot(xdot.cast<cplx>())) / (v.norm() * xdot.norm()); };
    std::size_t k1 = 0;
    auto analyse = [&]() {
        k1 = 0;
        double best = -1.0;
        for (std::size_t k = 0; k < vals.size(); ++k) {
            const double a = alignment(vecs.col(static_cast<Eigen::Index>(k)));
            if (a > best) {
                best = a;
                k1 = k;
            }
        }
        res.trivial_alignment = best;
        res.trivial_distance = std::abs(vals[k1] - 1.0);
        res.max_nontrivial = 0.0;
        for (std::size_t k = 0; k < vals.size(); ++k)
            if (k != k1) res.max_nontrivial = std::max(res.max_nontrivial, std::abs(vals[k]));
    };
    if (H <= options.dense_limit) {
        Eigen::MatrixXd mono(H, H);
        Eigen::VectorXd e = Eigen::VectorXd::Zero(H), y(H);
        for (int j = 0; j < H; ++j) {
            e.setZero();
            e(j) = 1.0;
            m.apply(e.data(), y.data());
            mono.col(j) = y;
        }
        Eigen::EigenSolver<Eigen::MatrixXd> es(mono, true);
        if (es.info() == Eigen::Success) {
            std::vector<Eigen::Index> order(static_cast<std::size_t>(H));
            for (int j = 0; j < H; ++j) order[static_cast<std::size_t>(j)] = j;
            std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) { return std::abs(es.eigenvalues()(a)) > std::abs(es.eigenvalues()(b)); });
            vecs.resize(H, H);
            for (int j = 0; j < H; ++j) {
                vals.push_back(es.eigenvalues()(order[static_cast<std::size_t>(j)]));
                vecs.col(j) = es.eigenvectors().col(order[static_cast<std::size_t>(j)]);
            }
            all_found = true;
            converged_run = true;
            nev_used = H;
        }
        res.method += "all multipliers (dense QR of the " + std::to_string(H) + " x " + std::to_string(H) + " monodromy matrix built by columns)";
    } else {
        MonodromyOp op;
        op.m = &m;
        int nev = std::min(options.min_multipliers, H - 3);
        for (;;) {
            const int ncv = std::min(H, 2 * nev + 20);
            Spectra::GenEigsSolver<MonodromyOp> es(op, nev, ncv);
            es.init();
            es.compute(Spectra::SortRule::LargestMagn, options.max_restarts, options.arnoldi_tolerance);
            nev_used = nev;
            converged_run = es.info() == Spectra::CompInfo::Successful;
            // the converged Ritz pairs (all of them, or those that did when Arnoldi stopped)
            const Eigen::VectorXcd ev = es.eigenvalues();
            vecs = es.eigenvectors();
            vals.assign(ev.data(), ev.data() + ev.size());
            if (vals.empty() || !converged_run) break;
            analyse();
            const double error = res.trivial_distance + residual(vecs.col(static_cast<Eigen::Index>(k1)), vals[k1]);
            const double smallest = std::abs(vals.back());
            if (smallest < 1.0 - error || nev >= options.max_multipliers || 2 * (2 * nev) + 20 > H) break;
            // one nontrivial multiplier clearly outside: unstable, no need for more
            bool outside = false;
            for (std::size_t k = 0; k < vals.size(); ++k)
                if (k != k1 && std::abs(vals[k]) > 1.0 + 10.0 * error) outside = true;
            if (outside) break;
            nev = std::min(2 * nev, options.max_multipliers);
        }
        res.method += "the largest multipliers by Arnoldi (Spectra GenEigsSolver, nev = " + std::to_string(nev_used) + ", window " + std::to_string(H) + ")";
    }
    res.applications = static_cast<int>(m.applications);
    if (vals.empty()) {
        res.status = converged_run ? Status::NumericalIssue : Status::MaxIterations;
        res.message = converged_run ? "the eigenvalue problem of the monodromy matrix failed"
                                    : "Arnoldi did not converge for any of the " + std::to_string(nev_used) + " largest multipliers within " +
                                          std::to_string(options.max_restarts) + " restarts (clustered multipliers)";
        res.seconds = cpu_seconds() - t0;
        return res;
    }
    analyse();
    res.multipliers = vals;
    // residuals of the trivial pair and of every nontrivial one near or outside the circle
    res.max_residual = residual(vecs.col(static_cast<Eigen::Index>(k1)), vals[k1]);
    const double band = std::max(0.01, 10.0 * (res.trivial_distance + res.max_residual));
    for (std::size_t k = 0; k < vals.size(); ++k)
        if (k != k1 && std::abs(vals[k]) > 1.0 - band) res.max_residual = std::max(res.max_residual, residual(vecs.col(static_cast<Eigen::Index>(k)), vals[k]));
    res.applications = static_cast<int>(m.applications);
    const bool recognised = res.trivial_alignment >= 0.99;
    // the discretisation's accuracy: the trivial multiplier's distance from 1 and the resolution
    // check (the only one when the trivial pair is not among those found), plus the residuals
    res.error = std::max(recognised ? res.trivial_distance : 0.0, res.xdot_residual) + res.max_residual;
    res.complete = converged_run && (all_found || std::abs(vals.back()) < 1.0 - res.error);
    int outside = 0, near = 0;
    for (std::size_t k = 0; k < vals.size(); ++k) {
        if (recognised && k == k1) continue;
        const double a = std::abs(vals[k]);
        if (a > 1.0 + res.error) ++outside;
        else if (a >= 1.0 - res.error) ++near;
    }
    if (!recognised) {
        res.trivial_distance = std::numeric_limits<double>::quiet_NaN();
        res.max_nontrivial = std::abs(vals.front());
    }
    std::ostringstream msg;
    if (res.max_residual > 1e-6) {
        res.status = Status::NumericalIssue;
        msg << "a Ritz pair's residual is " << fmt(res.max_residual) << " of |M| (above 1e-6): the multipliers are not trusted";
    } else if (outside > 0) {
        // an eigenvalue outside the circle (converged and checked) is enough, whatever else
        res.status = Status::Converged;
        res.verdict = Verdict::Unstable;
        msg << outside << " nontrivial multiplier" << (outside > 1 ? "s" : "") << " outside the unit circle (max |mu| = " << fmt(res.max_nontrivial)
            << ", error estimate " << fmt(res.error) << ")";
    } else if (!converged_run) {
        res.status = Status::MaxIterations;
        msg << "Arnoldi did not converge for the " << nev_used << " largest multipliers within " << options.max_restarts << " restarts (" << vals.size()
            << " converged, none outside the unit circle)";
    } else if (!recognised) {
        res.status = Status::NumericalIssue;
        msg << "the trivial multiplier is not among those found (the best eigenvector's |cos| with x' is " << fmt(res.trivial_alignment) << " < 0.99)";
    } else if (near > 0) {
        res.status = Status::NumericalIssue;
        msg << near << " nontrivial multiplier" << (near > 1 ? "s" : "") << " within the error estimate " << fmt(res.error)
            << " of the unit circle (max |mu| = " << fmt(res.max_nontrivial) << "): stability not decided";
    } else if (!res.complete) {
        res.status = Status::BudgetExhausted;
        msg << "the " << vals.size() << " largest multipliers found are all within the radius 1 - " << fmt(res.error)
            << ": more may lie outside it (raise max_multipliers)";
    } else {
        res.status = Status::Converged;
        res.verdict = Verdict::Stable;
        msg << "every nontrivial multiplier inside the unit circle (max |mu| = " << fmt(res.max_nontrivial) << ", error estimate " << fmt(res.error) << ")";
    }
    res.message = msg.str();
    res.seconds = cpu_seconds() - t0;
    return res;
}

}  // namespace ddemap

namespace ddemap::wave_stability {

void matrix_free_pass(const ParameterMap& parameters, const TravellingWaveOptions& options, TravellingWaveBranch& res) {
    OrbitBranch& b = res.branch;
    res.stability_method = "matrix_free";
    res.full_ring_stability = true;
    res.stability.clear();
    res.stability_status = Status::Converged;
    res.stability_message.clear();
    const long total = static_cast<long>(b.points.size());
    for (std::size_t i = 0; i < b.points.size(); ++i) {
        PeriodicOrbit& o = b.points[i];
        WaveStability s = wave_ring_stability(options.model, parameters, b.parameter, options.cars, options.wave, b.degree, o, options.stability);
        o.multipliers = s.multipliers;
        o.trivial_distance = s.trivial_distance;
        o.max_nontrivial = s.max_nontrivial;
        o.stable = s.verdict == Verdict::Stable;
        if (std::isfinite(o.trivial_distance)) b.max_trivial_distance = std::max(b.max_trivial_distance, o.trivial_distance);
        if (s.status != Status::Converged && res.stability_status == Status::Converged) {
            res.stability_status = s.status;
            std::ostringstream m;
            m << "the stability of wave " << i + 1 << " (" << b.parameter << " = " << o.par << ") is undecided: " << s.message;
            res.stability_message = m.str();
        }
        res.stability.push_back(std::move(s));
        if (options.stability_progress) options.stability_progress(static_cast<long>(i) + 1, total, o.par);
    }
}

}  // namespace ddemap::wave_stability
