// The dense backend of rightmost_roots: all eigenvalues of the Chebyshev collocation matrix
// (Eigen's QR algorithm, real arithmetic for real problems), each refined by Newton on det Delta,
// with the degree raised until the rightmost roots settle (docs/mathematics.md section 5).

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "ddemap/discretize/collocation.hpp"
#include "internal/backends.hpp"

namespace ddemap {

namespace {

/// A matrix of at least this many rows has its complex eigenvalues computed in stages with
/// `check` between them (smaller ones take well under a tenth of a second in one piece).
constexpr Eigen::Index kStagedRows = 200;
/// Hessenberg columns reduced, and QR steps of the Schur iteration done, between two checks.
constexpr Eigen::Index kColumnsPerCheck = 16;
constexpr Eigen::Index kStepsPerCheck = 32;

/// The eigenvalues of a complex matrix as Eigen::ComplexEigenSolver computes them (Householder
/// reduction to Hessenberg form H = Q^* A Q, then single-shift QR steps until H is triangular,
/// the diagonal sorted by modulus), with `check` called after every kColumnsPerCheck columns of
/// the reduction and every kStepsPerCheck QR steps. The reduction is Eigen's, step for step;
/// the QR iteration is Eigen's ComplexSchur resumed from its own partial result, with the same
/// total budget of 30 steps per row (only its count of steps on the current eigenvalue, which
/// triggers an exceptional shift after 10 and 30, restarts at a check). false: no convergence.
bool staged_complex_eigenvalues(MatrixXc a, const std::function<void()>& check, std::vector<cplx>& out) {
    const Eigen::Index n = a.rows();
    Eigen::VectorXcd h_coeffs(n - 1), temp(n);
    for (Eigen::Index i = 0; i < n - 1; ++i) {  // HessenbergDecomposition::_compute
        const Eigen::Index rest = n - i - 1;
        double beta;
        cplx h;
        a.col(i).tail(rest).makeHouseholderInPlace(h, beta);
        a.col(i).coeffRef(i + 1) = beta;
        h_coeffs.coeffRef(i) = h;
        a.bottomRightCorner(rest, rest).applyHouseholderOnTheLeft(a.col(i).tail(rest - 1), h, &temp.coeffRef(0));
        a.rightCols(rest).applyHouseholderOnTheRight(a.col(i).tail(rest - 1), std::conj(h), &temp.coeffRef(0));
        if (check && (i + 1) % kColumnsPerCheck == 0) check();
    }
    if (n > 2) a.bottomLeftCorner(n - 2, n - 2).triangularView<Eigen::Lower>().setZero();  // matrixH()
    Eigen::ComplexSchur<MatrixXc> schur(n);
    const Eigen::Index budget = Eigen::ComplexSchur<MatrixXc>::m_maxIterationsPerRow * n;
    for (Eigen::Index used = 0;; used += kStepsPerCheck) {
        const Eigen::Index steps = std::min(kStepsPerCheck, budget - used);
        schur.setMaxIterations(steps);
        schur.computeFromHessenberg(a, a, /*computeU=*/false);
        if (schur.info() == Eigen::Success) break;
        if (used + steps >= budget) return false;
        a = schur.matrixT();  // still Hessenberg, similar to the input: resume from it
        if (check) check();
    }
    Eigen::VectorXcd values = schur.matrixT().diagonal();
    for (Eigen::Index i = 0; i < n; ++i) {  // ComplexEigenSolver::sortEigenvalues
        Eigen::Index k;
        values.cwiseAbs().tail(n - i).minCoeff(&k);
        if (k != 0) std::swap(values[k + i], values[i]);
    }
    out.assign(values.data(), values.data() + n);
    return true;
}

}  // namespace

bool collocation_eigenvalues(const LinearDDE& dde, int degree, std::vector<cplx>& out, const std::function<void()>& check) {
    const MatrixXc a = collocation_matrix(dde.is_sparse() ? dde.to_dense() : dde, degree);
    if (dde.is_real()) {
        Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(a.real()), /*computeEigenvectors=*/false);
        if (es.info() != Eigen::Success) return false;
        out.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
    } else if (a.rows() >= kStagedRows) {
        return staged_complex_eigenvalues(a, check, out);
    } else {
        Eigen::ComplexEigenSolver<MatrixXc> es(a, /*computeEigenvectors=*/false);
        if (es.info() != Eigen::Success) return false;
        out.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
    }
    return true;
}

}  // namespace ddemap

namespace ddemap::detail {


namespace {

/// R(-1/tau) tau below which the roots come from the ODE limit (see dense_roots).
constexpr double kShortDelay = 1e-3;

/// The short-delay certificate in the eigenbasis of the tau -> 0 limit L = A0 + sum_k A_k.
/// With L V = V diag(mu) + F (F the rounding residual of the computed decomposition) and
/// E(lambda) = sum_k A_k (e^{-lambda tau_k} - 1), Delta(lambda) = V [lambda I - diag(mu) -
/// V^{-1} (F + E(lambda)) V] V^{-1}. For Re(lambda) >= -1/tau, |e^{-lambda tau_k} - 1| <=
/// e tau_k |lambda|, so ||V^{-1} (F + E) V|| <= q |lambda| + f with
///     q = e sum_k tau_k ||V^{-1} A_k V||,   f = ||V^{-1} F||.
/// A root there has min_i |lambda - mu_i| <= q |lambda| + f, hence (q < 1) lies in a disc
///     |lambda - mu_i| <= rho_i = 2 (q |mu_i| + f) / (1 - q) + tiny.
/// When q <= kCertifiedShortDelay, the discs are pairwise disjoint and all lie in Re > -1/tau,
/// the homotopy t (F + E), t in [0, 1], keeps Delta nonsingular on every circle, so each disc
/// holds exactly one root (with multiplicity) and every root with Re >= -1/tau is in a disc:
/// the n roots right of -1/tau are one per disc, and all others have Re < -1/tau. Norms are
/// 2-norms computed in floating point (V^{-1} from an LU solve), not interval bounds.
/// Returns the radii, or an empty vector when a condition fails.
constexpr double kCertifiedShortDelay = 0.1;

std::vector<double> short_delay_discs(const LinearDDE& dde, const Eigen::VectorXcd& mu, const MatrixXc& v, double& q_out) {
    const Eigen::Index n = mu.size();
    if (n != dde.dimension() || v.rows() != n || v.cols() != n) return {};
    Eigen::PartialPivLU<MatrixXc> lu(v);
    const MatrixXc w = lu.inverse();
    if (!w.allFinite()) return {};
    auto norm2 = [](const MatrixXc& m) { return Eigen::JacobiSVD<MatrixXc>(m).singularValues()(0); };
    double q = 0.0;
    for (const auto& t : dde.delayed()) q += t.delay * norm2(w * t.matrix * v);
    q *= std::exp(1.0);
    const MatrixXc residual = dde.ode_limit() * v - v * mu.asDiagonal();
    const double f = norm2(w * residual) + norm2(w * v - MatrixXc::Identity(n, n)) * mu.cwiseAbs().maxCoeff();
    q_out = q;
    if (!std::isfinite(q) || !std::isfinite(f) || q > kCertifiedShortDelay) return {};
    const double floor = -1.0 / dde.max_delay();
    std::vector<double> rho(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) {
        rho[static_cast<std::size_t>(i)] = 2.0 * (q * std::abs(mu[i]) + f) / (1.0 - q) + 1e-300;
        if (!(mu[i].real() - rho[static_cast<std::size_t>(i)] > floor)) return {};
    }
    for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = i + 1; j < n; ++j)
            if (!(std::abs(mu[i] - mu[j]) > rho[static_cast<std::size_t>(i)] + rho[static_cast<std::size_t>(j)])) return {};
    return rho;
}

/// Newton on det Delta from `guess` (the one Newton loop); true when converged (or stalled
/// near a multiple root) with a residual below the tolerance.
bool refine_root(const LinearDDE& dde, cplx guess, const RootOptions& options, Root& out, int& iterations) {
    cplx lambda = guess;
    const NewtonSummary s = newton(
        lambda,
        [&](const cplx& z, cplx& dz) {
            Eigen::PartialPivLU<MatrixXc> lu(dde.characteristic_matrix(z));
            const cplx t = lu.solve(dde.characteristic_derivative(z)).trace();
            // Delta(lambda) exactly singular: lambda is a root to machine precision
            if (!std::isfinite(t.real()) || !std::isfinite(t.imag()) || t == cplx(0.0)) return NewtonStep::Exact;
            dz = 1.0 / t;
            return NewtonStep::Ok;
        },
        options.dense.newton);
    iterations += s.iterations;
    if (s.status == Status::NumericalIssue) return false;
    out.value = lambda;
    out.eigenvalue = guess;
    out.newton_step = s.last_step;
    out.residual = relative_residual(dde, lambda);
    out.collocation_error = std::abs(lambda - guess);
    // A multiple root converges only linearly and stalls near sqrt(eps): accept it on the residual.
    return (s.status == Status::Converged || s.last_step <= 1e-6 * scale_of(lambda)) && out.residual <= options.residual_tolerance;
}

/// Schroeder's iteration (Newton on u = g / g') for g(lambda) = det Delta(lambda) / prod_k
/// (lambda - r_k), the roots r_k already found deflated (Maehly), from `start`: quadratic at a
/// root of any multiplicity, where Newton on det Delta is only linear and stalls near
/// eps^(1/m). With X = Delta^-1 Delta', Y = Delta^-1 Delta'' and T = g'/g = tr X - sum 1/(lambda -
/// r_k), T' = tr Y - tr X^2 + sum 1/(lambda - r_k)^2 and the step is -T / T'. True when it
/// converged (a step below 1e-14 of the root's scale, or Delta singular to machine precision)
/// with a residual below the tolerance; `out` then holds the root.
bool refine_deflated(const LinearDDE& dde, cplx start, const std::vector<cplx>& deflate, const RootOptions& options, Root& out,
                     int& iterations) {
    cplx lambda = start;
    double last = std::numeric_limits<double>::infinity();
    bool converged = false;
    for (int it = 0; it < 60; ++it) {
        MatrixXc d2 = MatrixXc::Zero(dde.dimension(), dde.dimension());
        for (const auto& t : dde.delayed()) d2 -= (t.delay * t.delay * std::exp(-lambda * t.delay)) * t.matrix;
        const Eigen::PartialPivLU<MatrixXc> lu(dde.characteristic_matrix(lambda));
        const MatrixXc X = lu.solve(dde.characteristic_derivative(lambda));
        cplx T = X.trace(), dT = lu.solve(d2).trace() - (X * X).trace();
        for (const cplx r : deflate) {
            const cplx q = 1.0 / (lambda - r);
            T -= q;
            dT += q * q;
        }
        ++iterations;
        if (!std::isfinite(std::abs(T)) || !std::isfinite(std::abs(dT))) {
            converged = true;  // Delta singular to machine precision: lambda is the root
            break;
        }
        if (dT == cplx(0.0)) break;
        const cplx step = -T / dT;
        if (!std::isfinite(std::abs(step))) break;
        lambda -= step;
        last = std::abs(step);
        if (last <= 1e-14 * scale_of(lambda)) {
            converged = true;
            break;
        }
    }
    if (!converged) return false;
    out.value = lambda;
    out.eigenvalue = start;
    out.newton_step = std::isfinite(last) ? last : 0.0;
    out.residual = relative_residual(dde, lambda);
    return out.residual <= options.residual_tolerance;
}

/// Refine candidates, merge duplicates, return sorted rightmost first.
/// Candidates whose Newton iteration failed go to `failed` (when given): a root there may be
/// missing from the list. A real candidate is also tried off the axis: rounding splits a nearly
/// double complex pair (separation ~sqrt(eps)) into two real eigenvalues, and Newton from a real
/// start stays real (real arithmetic on a real DDE), so it cannot reach the pair.
///
/// Several candidates whose Newton iterations end within 1e-5 of each other (relative) meet a
/// multiple root, where Newton stalls up to eps^(1/m) away, or a cluster of distinct roots, of
/// which Newton may find one from every start (a missed root): on a real DDE a value within that
/// of the real axis counts with its conjugate. Such a group of k members is refined again: k
/// deflated Schroeder iterations (refine_deflated), the i-th from the i-th member's eigenvalue
/// with the i - 1 roots before it deflated, find every distinct root of the cluster to full
/// accuracy (a multiple root comes back, and is listed once); if one fails, the group's Newton
/// values stand.
std::vector<Root> refine_all(const LinearDDE& dde, const std::vector<cplx>& candidates, const RootOptions& options, int& dropped,
                             int& iterations, std::vector<cplx>* failed = nullptr) {
    const bool real = dde.is_real();
    std::vector<Root> refined;
    for (cplx c : candidates) {
        if (real && c.imag() < 0.0) continue;  // the conjugate partner is (or will be) refined instead
        Root r;
        if (!refine_root(dde, c, options, r, iterations) &&
            !(c.imag() == 0.0 && refine_root(dde, c + cplx(0.0, 1e-4 * scale_of(c)), options, r, iterations))) {
            ++dropped;
            if (failed) failed->push_back(c);
            continue;
        }
        r.eigenvalue = c;
        r.collocation_error = std::abs(r.value - c);
        if (real) {
            if (r.value.imag() < 0.0) r.value = std::conj(r.value);
            if (std::abs(r.value.imag()) <= 1e-12 * scale_of(r.value) && r.value.imag() != 0.0) {
                Root rr;
                if (refine_root(dde, cplx(r.value.real(), 0.0), options, rr, iterations) && rr.value.imag() == 0.0) {
                    rr.collocation_error = std::abs(rr.value - c);
                    rr.eigenvalue = c;
                    r = rr;
                }
            }
        }
        refined.push_back(r);
    }
    // groups of refined values within `cluster` of each other (single linkage)
    const double cluster = 1e-5;
    auto close = [&](cplx a, cplx b) { return std::abs(a - b) <= cluster * std::max(scale_of(a), scale_of(b)); };
    std::vector<int> group(refined.size(), -1);
    int groups = 0;
    for (std::size_t i = 0; i < refined.size(); ++i) {
        if (group[i] >= 0) continue;
        group[i] = groups;
        for (std::size_t k = i; k < refined.size(); ++k) {  // grow the group from its members
            if (group[k] != groups) continue;
            for (std::size_t j = i + 1; j < refined.size(); ++j)
                if (group[j] < 0 && close(refined[k].value, refined[j].value)) group[j] = groups;
        }
        ++groups;
    }
    std::vector<Root> found;
    auto add = [&](const Root& r) {  // merge exact duplicates (1e-9)
        for (auto& f : found) {
            if (std::abs(f.value - r.value) <= 1e-9 * scale_of(r.value)) {
                ++dropped;
                f.collocation_error = std::min(f.collocation_error, r.collocation_error);
                const int mult = std::max(f.multiplicity, r.multiplicity);
                if (r.residual < f.residual) {
                    const double ce = f.collocation_error;
                    f = r;
                    f.collocation_error = ce;
                }
                f.multiplicity = mult;
                return;
            }
        }
        found.push_back(r);
    };
    for (int g = 0; g < groups; ++g) {
        std::vector<const Root*> members;
        std::vector<cplx> starts;
        for (std::size_t i = 0; i < refined.size(); ++i)
            if (group[i] == g) {
                members.push_back(&refined[i]);
                starts.push_back(refined[i].eigenvalue);
                // on a real DDE a value next to the real axis, from a value or a start off it: its
                // conjugate (the skipped partner of the eigenvalue) is a member too
                const bool near_axis = std::abs(refined[i].value.imag()) <= cluster * scale_of(refined[i].value);
                if (real && near_axis && (refined[i].value.imag() != 0.0 || refined[i].eigenvalue.imag() > 0.0))
                    starts.push_back(std::conj(refined[i].eigenvalue) + cplx(0.0, refined[i].eigenvalue.imag() == 0.0 ? -1e-6 * scale_of(refined[i].value) : 0.0));
            }
        if (starts.size() == 1) {
            add(*members.front());
            continue;
        }
        double ce = std::numeric_limits<double>::infinity();
        for (const Root* m : members) ce = std::min(ce, m->collocation_error);
        // the deflated sequence from `from`; false when one iteration fails
        auto sequence = [&](const std::vector<cplx>& from, std::vector<Root>& out) {
            std::vector<cplx> roots;
            for (const cplx s0 : from) {
                Root r;
                // (a start exactly on a root already found would divide by zero: moved off it)
                cplx s = s0;
                for (const cplx x : roots)
                    if (s == x) s += cplx(1e-8 * scale_of(x), 0.0);
                if (!refine_deflated(dde, s, roots, options, r, iterations)) return false;
                roots.push_back(r.value);
                r.collocation_error = ce;
                out.push_back(r);
            }
            return true;
        };
        std::vector<Root> out;
        bool ok = false;
        if (real && starts.size() > members.size()) {
            // a group at the real axis of a real DDE (a double real root, or real roots closer than
            // Newton resolves): from real starts the iterations stay real and list them real; a
            // complex pair this close to the axis (they fail then) is looked for from the complex starts
            std::vector<cplx> on_axis;
            for (const cplx z : starts) on_axis.push_back(cplx(z.real(), 0.0));
            ok = sequence(on_axis, out);
            if (!ok) out.clear();
        }
        if (!ok) ok = sequence(starts, out);
        if (!ok) {
            for (const Root* m : members) add(*m);
            continue;
        }
        // roots of the sequence within 1e-7 (relative) of each other are one multiple root (the
        // deflated iteration found it again): listed once, with its multiplicity
        std::vector<Root> distinct;
        for (Root& r : out) {
            if (real) {
                if (std::abs(r.value.imag()) <= 1e-12 * scale_of(r.value)) r.value = cplx(r.value.real(), 0.0);
                if (r.value.imag() < 0.0) r.value = std::conj(r.value), r.eigenvalue = std::conj(r.eigenvalue);  // listed by its partner
            }
            bool same = false;
            for (Root& d : distinct)
                if (std::abs(d.value - r.value) <= 1e-7 * scale_of(r.value)) {
                    ++d.multiplicity;
                    same = true;
                    break;
                }
            if (!same) distinct.push_back(r);
        }
        for (const Root& r : distinct) add(r);
    }
    if (real) {
        const std::size_t n = found.size();
        for (std::size_t i = 0; i < n; ++i) {
            if (found[i].value.imag() > 0.0) {
                Root c = found[i];
                c.value = std::conj(c.value);
                c.eigenvalue = std::conj(c.eigenvalue);
                found.push_back(c);
            }
        }
    }
    std::sort(found.begin(), found.end(), rightmost_first);
    return found;
}

/// The first collocation degree and the largest one tried: the largest degree whose
/// collocation matrix has at most max_rows rows caps them; the first degree is computed whatever
/// its size (a given degree as asked, an automatic one not above the cap unless M = 8 is), later
/// ones not beyond the larger of the two.
std::pair<int, int> dense_degrees(const LinearDDE& dde, const RootOptions& options) {
    const DenseRootOptions& o = options.dense;
    const int max_degree = std::max(o.max_degree, options.degree);
    const int row_degree = o.max_rows / std::max(1, dde.dimension()) - 1;
    int m = options.degree > 0 ? options.degree : std::clamp(degree_for_radius(dde.root_bound(0.0), dde.max_delay()), 8, max_degree);
    if (options.degree == 0) m = std::min(m, std::max(row_degree, 8));
    return {m, std::max(row_degree, m)};
}

}  // namespace

RootWorkEstimate dense_estimate(const RootProblem& problem, const RootOptions& options) {
    const LinearDDE& dde = problem.dde;
    RootWorkEstimate e;
    const double n = dde.dimension();
    // Eigen's eigenvalues on one core (measured: 2 s at 1,000 real rows, 19 s at 2,000)
    const double c = dde.is_real() ? 2e-9 : 8e-9, scalar = dde.is_real() ? 8.0 : 16.0;
    std::ostringstream os;
    os.precision(3);
    if (dde.is_ode()) {
        e.units = 1;
        e.seconds = c * n * n * n;
        e.bytes = 3.0 * scalar * n * n;
        os << "the eigenvalues of one " << n << "-row matrix";
    } else {
        const auto [first, cap] = dense_degrees(dde, options);
        const double r1 = (first + 1.0) * n, r2 = std::min((cap + 1.0) * n, 1.5 * r1);
        e.units = 2;
        e.seconds = c * (r1 * r1 * r1 + r2 * r2 * r2);
        e.bytes = 3.0 * scalar * std::max(r1, r2) * std::max(r1, r2);
        os << "the eigenvalues of two collocation degrees, " << r1 << " and " << r2 << " rows";
    }
    e.basis = os.str();
    return e;
}

std::string dense_why_not(const RootProblem& problem, const RootOptions& /*options*/) {
    if (problem.dde.dimension() > 4000)
        return "method 'dense': " + std::to_string(problem.dde.dimension()) +
               " states are too many for dense collocation (at most 4000): expected auto or shift_invert (the sparse path)";
    return {};
}

RootResult dense_roots(const RootProblem& problem, const RootOptions& options) {
    const LinearDDE dde = problem.dde.to_dense();
    const DenseRootOptions& o = options.dense;
    RootResult result;

    if (dde.is_ode()) {
        const MatrixXc a = dde.a0();
        std::vector<cplx> ev;
        if (dde.is_real()) {
            // real arithmetic: exact conjugate pairs and real eigenvalues with zero imaginary part
            // (refine_all skips Im < 0, so a real eigenvalue computed as x - 1e-18 i would be lost)
            Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(a.real()), false);
            ev.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
        } else {
            Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
            ev.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
        }
        result.roots = cut_rightmost(refine_all(dde, ev, options, result.dropped, result.newton_iterations), options.count);
        result.degree = 0;
        result.status = Status::Converged;
        result.covered_radius = std::numeric_limits<double>::infinity();
        result.message = "no delay: the eigenvalues of the ODE matrix A0 + sum A_k, refined by Newton";
        return result;
    }

    const double tau = dde.max_delay();
    // A short delay (R tau small, R = R(-1/tau) the bound on |lambda| for every root with
    // Re >= -1/tau): there |lambda tau_k| <= R tau, so Delta(lambda) differs from the ODE limit
    // lambda I - (A0 + sum A_k) by at most about R tau sum ||A_k||, and the n roots with
    // Re >= -1/tau are the ODE eigenvalues moved by O(R tau) (every other root has
    // Re < -1/tau). They are found by Newton on Delta from those eigenvalues; the collocation on
    // [-tau, 0] would need entries of size 1/tau (overflow for tau -> 0) for the same roots.
    const double short_floor = -1.0 / tau;
    const double short_radius = dde.root_bound(short_floor);
    // Beyond R tau <= kShortDelay the same path is taken when the certificate of
    // short_delay_discs holds (large gains with a short delay: R tau up to 0.1, where the
    // collocation's eigenvalues near the axis are spoiled by rounding in entries of size M^2/tau).
    const bool short_by_radius = std::isfinite(short_radius) && short_radius * tau <= kShortDelay;
    const bool try_discs = !short_by_radius && std::isfinite(short_radius) && short_radius * tau <= 0.1 && dde.dimension() <= 64;
    if (options.degree == 0 && (short_by_radius || try_discs)) {
        const MatrixXc limit = dde.ode_limit();
        std::vector<cplx> ev;
        Eigen::VectorXcd mu;
        MatrixXc vectors;
        bool ok = true;
        if (dde.is_real()) {
            Eigen::EigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(limit.real()), try_discs);
            ok = es.info() == Eigen::Success;
            if (ok) {
                mu = es.eigenvalues();
                if (try_discs) vectors = es.eigenvectors();
            }
        } else {
            Eigen::ComplexEigenSolver<MatrixXc> es(limit, try_discs);
            ok = es.info() == Eigen::Success;
            if (ok) {
                mu = es.eigenvalues();
                if (try_discs) vectors = es.eigenvectors();
            }
        }
        if (ok) ev.assign(mu.data(), mu.data() + mu.size());
        double q = 0.0;
        std::vector<double> rho;
        if (ok && try_discs) {
            rho = short_delay_discs(dde, mu, vectors, q);
            ok = !rho.empty();
        }
        int dropped = 0;
        std::vector<Root> all = ok ? refine_all(dde, ev, options, dropped, result.newton_iterations) : std::vector<Root>{};
        // every eigenvalue must give its own root (n of them): else the collocation path decides
        bool complete = ok && static_cast<int>(all.size()) == dde.dimension();
        if (complete && try_discs) {  // and, certified, exactly one root in each disc
            for (std::size_t i = 0; i < rho.size(); ++i) {
                int inside = 0;
                for (const auto& x : all) inside += std::abs(x.value - mu[static_cast<Eigen::Index>(i)]) <= rho[i] ? 1 : 0;
                if (inside != 1) complete = false;
            }
        }
        if (complete) {
            double worst = 0.0;
            for (const auto& x : all) worst = std::max(worst, x.collocation_error / scale_of(x.value));
            result.roots = cut_rightmost(all, options.count);
            result.degree = 0;
            result.dropped = dropped;
            result.collocation_error = worst;
            result.covered_radius = short_radius;
            result.strip_floor = static_cast<int>(result.roots.size()) < dde.dimension() ? result.roots.back().value.real() : short_floor;
            result.status = Status::Converged;
            std::ostringstream os;
            os.precision(3);
            if (try_discs) {
                os << "short delay (certified: q = e sum tau_k ||V^-1 A_k V|| = " << q << " <= " << kCertifiedShortDelay
                   << "): exactly one root in a disc about each of the " << dde.dimension()
                   << " eigenvalues of the tau -> 0 limit, none elsewhere with Re >= -1/tau = " << short_floor
                   << ", refined by Newton (moved by at most " << worst << " relative)";
            } else {
                os << "short delay (R tau = " << short_radius * tau << " <= " << kShortDelay << "): the " << dde.dimension()
                   << " roots with Re >= -1/tau = " << short_floor << " refined by Newton from the eigenvalues of the tau -> 0 limit"
                   << " (moved by at most " << worst << " relative)";
            }
            result.message = os.str();
            return result;
        }
    }
    const int max_degree = std::max(o.max_degree, options.degree);
    const std::pair<int, int> degrees = dense_degrees(dde, options);
    int m = degrees.first;
    const int cap_degree = degrees.second;
    std::vector<Root> previous;
    std::size_t previous_in_strip = 0;
    int previous_degree = 0;
    double previous_sigma = std::numeric_limits<double>::quiet_NaN();
    // within one degree (a complex eigenvalue problem of (M+1) n >= 200 states): the last report
    // repeated between stages of the eigenvalues (the degree done before, 0 and NaN before the
    // first), so that a callback throwing Cancelled stops a long degree too
    std::function<void()> within;
    if (options.progress) within = [&] { options.progress(previous_degree, max_degree, previous_sigma); };
    for (;;) {
        if (m > cap_degree) {
            // (never the first degree) the roots of the last one did not settle: they are
            // returned, undecided
            result.status = Status::BudgetExhausted;
            result.degree = previous_degree;
            result.roots = previous;
            result.covered_radius = radius_for_degree(previous_degree, tau);
            result.strip_floor = previous_sigma;
            std::ostringstream os;
            os << "the roots of M=" << previous_degree << " did not settle, and M=" << m << " needs a dense eigenproblem of (M+1) n = "
               << (static_cast<long>(m) + 1) * dde.dimension() << " rows, more than dense.max_rows = " << o.max_rows
               << " (ask for fewer roots, or " << (dde.is_real() ? "use the sparse path" : "raise dense.max_rows") << ")";
            result.message = os.str();
            return result;
        }
        std::vector<cplx> values;
        if (!collocation_eigenvalues(dde, m, values, within)) {
            result.status = Status::NumericalIssue;
            result.degree = m;
            result.roots = previous;
            result.message = "the dense eigen-solver failed at degree " + std::to_string(m);
            return result;
        }
        const double covered = radius_for_degree(m, tau);
        // eigenvalues beyond the resolved radius are discretisation artefacts, not roots
        std::vector<cplx> ev;
        for (cplx z : values)
            if (std::abs(z) <= 1.5 * covered + 1.0) ev.push_back(z);
        std::sort(ev.begin(), ev.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
        const std::size_t k = std::min<std::size_t>(ev.size(), 2 * options.count + 8);
        ev.resize(k);
        int dropped = 0;
        std::vector<cplx> failed;
        std::vector<Root> current = cut_rightmost(refine_all(dde, ev, options, dropped, result.newton_iterations, &failed), options.count);

        // Completeness is certified right of sigma: the last of the `count` roots, or, when fewer
        // were found, the floor of the strip Re >= alpha - depth (all roots there are listed).
        const double depth = o.depth > 0.0 ? o.depth : 2.0 / tau;
        const bool full = current.size() >= std::size_t(options.count);
        const double floor = current.empty() ? -depth : current.front().value.real() - depth;
        const double sigma = full ? current.back().value.real() : floor;
        std::size_t in_strip = 0;
        while (in_strip < current.size() && current[in_strip].value.real() >= sigma) ++in_strip;
        // every root right of sigma is within the bound; M must resolve that disc
        const double needed = dde.root_bound(sigma);
        double change = std::numeric_limits<double>::infinity();
        bool collocated = true;
        // a root within d (relative) of another is determined only to about eps / d (a cluster or
        // a multiple root, d ~ sqrt(eps) for a double one): its change between degrees is measured
        // against 1e3 eps / d where that exceeds the agreement tolerance
        bool conditioned = false;  // every change within its own allowance
        double close_roots = std::numeric_limits<double>::infinity();  // the least such d
        if (previous_degree > 0 && previous_in_strip == in_strip) {
            change = 0.0;
            conditioned = true;
            for (std::size_t i = 0; i < in_strip; ++i) {
                double d = std::numeric_limits<double>::infinity();
                for (std::size_t j = 0; j < current.size(); ++j)
                    if (j != i) d = std::min(d, std::abs(current[i].value - current[j].value) / scale_of(current[i].value));
                // (a root of multiplicity m: to about eps^(1/m))
                const int mult = std::max(current[i].multiplicity, previous[i].multiplicity);
                const double allowed = std::max({o.agreement_tolerance, 1e3 * std::numeric_limits<double>::epsilon() / d,
                                                 mult > 1 ? 1e2 * std::pow(std::numeric_limits<double>::epsilon(), 1.0 / mult) : 0.0});
                const double c = std::abs(current[i].value - previous[i].value) / scale_of(current[i].value);
                if (c > allowed) conditioned = false;
                if (allowed > o.agreement_tolerance) close_roots = std::min(close_roots, mult > 1 ? 0.0 : d);
                change = std::max(change, c);
            }
        }
        double worst_collocation = 0.0;
        for (std::size_t i = 0; i < in_strip; ++i) {
            const double e = current[i].collocation_error / scale_of(current[i].value);
            worst_collocation = std::max(worst_collocation, e);
            if (e > o.collocation_tolerance) collocated = false;
        }
        // Two certificates: the eigenvalues themselves already equal the Newton-refined roots
        // (spectral accuracy reached at this M), or the refined roots agree between two degrees.
        const bool covers = covered >= needed;
        // a collocation eigenvalue right of sigma that Newton could not refine may be a root the
        // list misses: no certificate at this degree (a larger M or its neighbour may refine it)
        cplx lost(std::numeric_limits<double>::quiet_NaN(), 0.0);
        for (cplx z : failed)
            if (z.real() >= sigma - 1e-8 * scale_of(z) && !(z.real() <= lost.real())) lost = z;
        const bool complete = std::isnan(lost.real());
        // (With fewer than `count` roots found only the second certificate applies: a larger M
        // may reveal more roots, so the same set must come out of two degrees.)
        const bool spectral = full && worst_collocation <= o.spectral_tolerance && covers && complete;
        const bool agreed = conditioned && collocated && covers && complete;
        const bool settled = spectral || agreed;
        // the degree M done (of at most max_degree); may throw Cancelled (caught by rightmost_roots)
        if (options.progress) options.progress(m, max_degree, sigma);
        if (settled || m >= max_degree) {
            result.roots = current;
            result.degree = m;
            result.previous_degree = previous_degree;
            result.degree_change = change;
            result.collocation_error = worst_collocation;
            result.covered_radius = covered;
            result.strip_floor = sigma;
            result.dropped = dropped;
            std::ostringstream os;
            os.precision(3);
            if (settled) {
                result.status = Status::Converged;
                os << "the " << in_strip << " rightmost roots" << (full ? "" : " (all with Re >= " + std::to_string(floor) + ")");
                if (spectral) {
                    os << " equal collocation eigenvalues at M=" << m << " to " << worst_collocation
                       << " (relative; spectral accuracy reached)";
                } else {
                    os << " agree between M=" << previous_degree << " and M=" << m << " (max relative change " << change;
                    if (close_roots == 0.0)
                        os << ", within 100 eps^(1/m) for a root of multiplicity m, determined to about that";
                    else if (std::isfinite(close_roots))
                        os << ", within 1e3 eps / d for roots a relative d >= " << close_roots << " apart (a cluster, determined to about eps / d)";
                    os << "; eigenvalues within " << worst_collocation << ")";
                }
                os << ", and M resolves |lambda| <= " << covered << ", beyond the bound " << needed
                   << " on any root with Re >= " << sigma;
            } else {
                result.status = Status::MaxDegreeReached;
                // (no earlier degree with the same roots in the strip to compare with: no change to name)
                os << "max degree M=" << m << " reached before the roots settled (";
                if (std::isfinite(change)) os << "change " << change << " from M=" << previous_degree;
                else os << "no earlier degree to compare with";
                os << ", resolved radius " << covered << " of needed ";
                if (std::isfinite(needed)) os << needed;
                else os << "an unbounded radius (the root bound is not finite)";
                if (!complete) os << "; the collocation eigenvalue " << lost.real() << (lost.imag() < 0 ? " - " : " + ") << std::abs(lost.imag()) << "i right of sigma = " << sigma << " could not be refined to a root";
                os << ")";
            }
            result.message = os.str();
            return result;
        }
        previous = current;
        previous_in_strip = in_strip;
        previous_degree = m;
        previous_sigma = sigma;
        int next = static_cast<int>(std::ceil(1.5 * m));
        if (covered < needed) next = std::max(next, degree_for_radius(needed, tau));
        m = std::min(next, max_degree);
        // the largest degree within the cap is tried before giving up
        if (m > cap_degree && cap_degree > previous_degree) m = cap_degree;
    }
}

}  // namespace ddemap::detail
