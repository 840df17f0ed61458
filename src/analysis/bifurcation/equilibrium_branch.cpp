#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"

#include "analysis/bifurcation/internal/curve_trace.hpp"

#include <chrono>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

/// g(x, p) = f(x, ..., x; p) with p_j the last unknown.
class EquilibriumCurve final : public ContinuationProblem {
public:
    EquilibriumCurve(const NonlinearDDE& s, int j) : m_s(s), m_j(j), m_p(s.parameter_values()) {}
    int equations() const override { return m_s.dimension(); }
    std::vector<double> values(const Eigen::VectorXd& u) const {
        std::vector<double> p = m_p;
        p[m_j] = u[u.size() - 1];
        return p;
    }
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const override {
        try {
            f = m_s.f(m_s.stack_constant(u.head(m_s.dimension())), values(u));
        } catch (const std::invalid_argument&) {
            return false;
        }
        return f.allFinite();
    }
    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const override {
        const int n = m_s.dimension();
        try {
            const Eigen::VectorXd st = m_s.stack_constant(u.head(n));
            const std::vector<double> p = values(u);
            const std::vector<Eigen::MatrixXd> a = m_s.jacobians(st, p);
            j.resize(n, n + 1);
            j.leftCols(n) = a[0];
            for (std::size_t k = 1; k < a.size(); ++k) j.leftCols(n) += a[k];
            j.col(n) = m_s.parameter_derivative(st, m_j, p);
        } catch (const std::invalid_argument&) {
            return false;
        }
        return j.allFinite();
    }
    bool in_domain(const Eigen::VectorXd& u) const override { return detail::delays_valid(m_s, values(u)); }

private:
    const NonlinearDDE& m_s;
    int m_j;
    std::vector<double> m_p;
};

/// Newton on a square system F(z) = 0 with the exact Jacobian J(z) of F; |F|_max at every
/// iterate where a step was computed is appended to `history`.
NewtonSummary newton_square(Eigen::VectorXd& z, const std::function<bool(const Eigen::VectorXd&, Eigen::VectorXd&, Eigen::MatrixXd*)>& F,
                            const NewtonOptions& options, std::vector<double>& history, bool minimum_norm = false) {
    return newton(
        z,
        [&](const Eigen::VectorXd& x, Eigen::VectorXd& dx) {
            Eigen::VectorXd f;
            Eigen::MatrixXd j;
            if (!F(x, f, &j) || !f.allFinite()) return NewtonStep::Singular;
            history.push_back(f.cwiseAbs().maxCoeff());
            if (history.back() == 0.0) return NewtonStep::Exact;
            if (!j.allFinite()) return NewtonStep::Singular;
            const Eigen::FullPivLU<Eigen::MatrixXd> lu(j);
            if (lu.isInvertible()) dx = lu.solve(f);
            else if (minimum_norm) dx = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(j).solve(f);  // Gauss-Newton, minimum-norm step
            else return NewtonStep::Singular;
            if (!dx.allFinite()) return NewtonStep::Singular;
            return NewtonStep::Ok;
        },
        options);
}

using Dual1 = Dual<double>;
using Dual2 = NonlinearDDE::Dual2;

/// f and its derivatives along two directions a = (a_u, a_p), b = (b_u, b_p) of (u, p), from one
/// evaluation in Dual<Dual<double>> seeded (u + a e1 + b e2, p + a_p e1 + b_p e2):
/// {f, Df[a], Df[b], D^2 f[a, b]}.
struct TwoDirections {
    Eigen::VectorXd f, da, db, dab;
};
TwoDirections two_directions(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const Eigen::VectorXd& au,
                             const Eigen::VectorXd& bu, int bp) {
    const int n = s.dimension();
    std::vector<Dual2> U(static_cast<std::size_t>(u.size())), P(p.size()), out(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < u.size(); ++i) U[static_cast<std::size_t>(i)] = Dual2(Dual1(u[i], au[i]), Dual1(bu[i], 0.0));
    for (std::size_t i = 0; i < p.size(); ++i) P[i] = Dual2(Dual1(p[i], 0.0), Dual1(static_cast<int>(i) == bp ? 1.0 : 0.0, 0.0));
    s.evaluate(U.data(), P.data(), out.data());
    TwoDirections r{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
    for (int i = 0; i < n; ++i) {
        const Dual2& o = out[static_cast<std::size_t>(i)];
        r.f[i] = o.value.value;
        r.da[i] = o.value.deriv;
        r.db[i] = o.deriv.value;
        r.dab[i] = o.deriv.deriv;
    }
    return r;
}

/// Df[w] = sum_k A_k w_k for a stacked direction w.
Eigen::VectorXd apply_blocks(const std::vector<Eigen::MatrixXd>& a, const Eigen::VectorXd& w) {
    const Eigen::Index n = a[0].rows();
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n);
    for (std::size_t k = 0; k < a.size(); ++k) r += a[k] * w.segment(static_cast<Eigen::Index>(k) * n, n);
    return r;
}

void check_derivatives(const NonlinearDDE& s) {
    if (!s.has_higher_derivatives() || !s.has_delay_derivatives())
        throw std::invalid_argument("the system gives no second derivatives or no derivatives of its delays: expected an expression system or a built-in model (NonlinearDDEOf)");
}

std::vector<double> with(const NonlinearDDE& s, int j, double v) {
    std::vector<double> p = s.parameter_values();
    p[j] = v;
    return p;
}

void check_parameter(const NonlinearDDE& s, int j) {
    if (j < 0 || j >= static_cast<int>(s.parameter_names().size()))
        throw std::invalid_argument("parameter index " + std::to_string(j) + ": expected 0.." +
                                    std::to_string(static_cast<int>(s.parameter_names().size()) - 1));
}

}  // namespace

bool EquilibriumBranchOptions::is_valid(std::string* why) const {
    std::string m;
    if (parameter.empty()) m = "parameter: expected the name of the free parameter";
    else if (!std::isfinite(from) || !std::isfinite(to)) m = "from/to: expected finite values";
    else if (from == to) m = "to = from = " + detail::format_number(from) + ": expected a range of the parameter";
    else if (!roots.is_valid(&m)) m = "roots." + m;
    else if (!equilibrium.is_valid(&m)) m = "equilibrium." + m;
    else if (!special.is_valid(&m)) m = "special." + m;
    else if (!(std::isfinite(special_residual) && special_residual > 0.0)) m = "special_residual: expected a finite value > 0";
    else if (continuation.initial_step < 0.0 || continuation.max_step < 0.0) m = "continuation steps: expected values >= 0 (0 = automatic)";
    if (!m.empty() && why) *why = m;
    return m.empty();
}

bool fold_system(const NonlinearDDE& system, int j, const Eigen::VectorXd& v0, const Eigen::VectorXd& z, Eigen::VectorXd& out,
                 Eigen::MatrixXd* jac, const std::vector<double>& values) {
    const int n = system.dimension();
    if (z.size() != 2 * n + 1 || v0.size() != n)
        throw std::invalid_argument("fold system: z has " + std::to_string(z.size()) + " and v0 " + std::to_string(v0.size()) +
                                    " entries: expected 2n + 1 and n (n = " + std::to_string(n) + ")");
    if (!values.empty() && values.size() != system.parameter_values().size())
        throw std::invalid_argument("fold system: " + std::to_string(values.size()) + " parameter values: expected " +
                                    std::to_string(system.parameter_values().size()));
    try {
        std::vector<double> p = values.empty() ? system.parameter_values() : values;
        p[static_cast<std::size_t>(j)] = z[n];
        const Eigen::VectorXd st = system.stack_constant(z.head(n));
        const Eigen::VectorXd v = z.segment(n + 1, n);
        const std::vector<Eigen::MatrixXd> b = system.jacobians(st, p);
        Eigen::MatrixXd jj = b[0];
        for (std::size_t k = 1; k < b.size(); ++k) jj += b[k];
        out.resize(2 * n + 1);
        out.head(n) = system.f(st, p);
        out.segment(n, n) = jj * v;
        out[2 * n] = v0.dot(v) - 1.0;
        if (jac) {
            // columns x_i and p_j: (Df[b], D^2 f[(S v, 0), b]) for b = (S e_i, 0) and (0, e_j)
            Eigen::MatrixXd& J = *jac;
            J = Eigen::MatrixXd::Zero(2 * n + 1, 2 * n + 1);
            const Eigen::VectorXd sv = system.stack_constant(v);
            const Eigen::VectorXd none = Eigen::VectorXd::Zero(st.size());
            for (int c = 0; c <= n; ++c) {
                const TwoDirections d = c < n ? two_directions(system, st, p, sv, system.stack_constant(Eigen::VectorXd::Unit(n, c)), -1)
                                              : two_directions(system, st, p, sv, none, j);
                J.block(0, c, n, 1) = d.db;
                J.block(n, c, n, 1) = d.dab;
            }
            J.block(n, n + 1, n, n) = jj;
            J.block(2 * n, n + 1, 1, n) = v0.transpose();
        }
    } catch (const std::invalid_argument&) {
        return false;
    }
    return out.allFinite() && (!jac || jac->allFinite());
}

bool hopf_system(const NonlinearDDE& system, int j, const VectorXc& q0, const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac,
                 const std::vector<double>& values) {
    const int n = system.dimension();
    if (z.size() != 3 * n + 2 || q0.size() != n)
        throw std::invalid_argument("Hopf system: z has " + std::to_string(z.size()) + " and q0 " + std::to_string(q0.size()) +
                                    " entries: expected 3n + 2 and n (n = " + std::to_string(n) + ")");
    if (!values.empty() && values.size() != system.parameter_values().size())
        throw std::invalid_argument("Hopf system: " + std::to_string(values.size()) + " parameter values: expected " +
                                    std::to_string(system.parameter_values().size()));
    try {
        std::vector<double> p = values.empty() ? system.parameter_values() : values;
        p[static_cast<std::size_t>(j)] = z[n];
        const Eigen::VectorXd x = z.head(n);
        const Eigen::VectorXd qr = z.segment(n + 1, n), qi = z.segment(2 * n + 1, n);
        const VectorXc q = qr.cast<cplx>() + cplx(0.0, 1.0) * qi.cast<cplx>();
        const double w = z[3 * n + 1];
        const VectorXc dq = linearise(system, x, p).characteristic_matrix(cplx(0.0, w)) * q;
        const cplx c = q0.dot(q) - 1.0;  // q0^H q - 1
        out.resize(3 * n + 2);
        const Eigen::VectorXd st = system.stack_constant(x);
        out.head(n) = system.f(st, p);
        out.segment(n, n) = dq.real();
        out.segment(2 * n, n) = dq.imag();
        out[3 * n] = c.real();
        out[3 * n + 1] = c.imag();
        if (jac) {
            // Delta(i w) q = i w q - Df[w_q], (w_q)_k = exp(-i w tau_k) q (tau_0 = 0), so with
            // W = Re w_q, V = Im w_q: rows Re = -w qi - Df[W], Im = w qr - Df[V], and
            //  d/dx_i: -D^2 f[W, S e_i], -D^2 f[V, S e_i];  d/dp_j: -D^2 f[W, e_pj] - Df[dW/dp] (the same with V),
            //    dW_k/dp = w tau_k' V_k, dV_k/dp = -w tau_k' W_k;
            //  d/dq: Delta(i w) (real part [Re, -Im; Im, Re]);  d/dw: i (q + Df[tau w_q]).
            const std::vector<Eigen::MatrixXd> a = system.jacobians(st, p);
            std::vector<double> tau = system.delays(p), dtau = system.delay_derivatives(p, j);
            tau.insert(tau.begin(), 0.0);
            dtau.insert(dtau.begin(), 0.0);
            const Eigen::Index s = st.size();
            Eigen::VectorXd W(s), V(s), dW(s), dV(s), tW(s), tV(s);
            MatrixXc M = MatrixXc::Identity(n, n) * cplx(0.0, w);
            for (std::size_t k = 0; k < a.size(); ++k) {
                const Eigen::Index o = static_cast<Eigen::Index>(k) * n;
                const double th = w * tau[k];
                W.segment(o, n) = std::cos(th) * qr + std::sin(th) * qi;
                V.segment(o, n) = std::cos(th) * qi - std::sin(th) * qr;
                dW.segment(o, n) = w * dtau[k] * V.segment(o, n);
                dV.segment(o, n) = -w * dtau[k] * W.segment(o, n);
                tW.segment(o, n) = tau[k] * W.segment(o, n);
                tV.segment(o, n) = tau[k] * V.segment(o, n);
                M -= a[k].cast<cplx>() * std::exp(cplx(0.0, -th));
            }
            Eigen::MatrixXd& J = *jac;
            J = Eigen::MatrixXd::Zero(3 * n + 2, 3 * n + 2);
            const Eigen::VectorXd none = Eigen::VectorXd::Zero(s);
            for (int col = 0; col <= n; ++col) {
                const Eigen::VectorXd e = col < n ? system.stack_constant(Eigen::VectorXd::Unit(n, col)) : none;
                const int bp = col < n ? -1 : j;
                const TwoDirections dw = two_directions(system, st, p, W, e, bp);
                const TwoDirections dv = two_directions(system, st, p, V, e, bp);
                J.block(0, col, n, 1) = dw.db;
                J.block(n, col, n, 1) = -dw.dab;
                J.block(2 * n, col, n, 1) = -dv.dab;
            }
            J.block(n, n, n, 1) -= apply_blocks(a, dW);
            J.block(2 * n, n, n, 1) -= apply_blocks(a, dV);
            J.block(n, n + 1, n, n) = M.real();
            J.block(2 * n, n + 1, n, n) = M.imag();
            J.block(n, 2 * n + 1, n, n) = -M.imag();
            J.block(2 * n, 2 * n + 1, n, n) = M.real();
            const Eigen::RowVectorXcd r = q0.adjoint();
            J.block(3 * n, n + 1, 1, n) = r.real();
            J.block(3 * n, 2 * n + 1, 1, n) = -r.imag();
            J.block(3 * n + 1, n + 1, 1, n) = r.imag();
            J.block(3 * n + 1, 2 * n + 1, 1, n) = r.real();
            J.block(n, 3 * n + 1, n, 1) = -(qi + apply_blocks(a, tV));
            J.block(2 * n, 3 * n + 1, n, 1) = qr + apply_blocks(a, tW);
        }
    } catch (const std::invalid_argument&) {
        return false;
    }
    return out.allFinite() && (!jac || jac->allFinite());
}

namespace {
/// Newton on the fold system; minimum_norm: minimum-norm steps where its Jacobian is singular
/// (at a symmetric pitchfork the fold system is singular along the crossing branch, and it is
/// consistent there: Gauss-Newton converges to the branch point).
FoldPoint correct_steady_state(const NonlinearDDE& system, int j, const Eigen::VectorXd& x0, double par0, const NewtonOptions& options,
                               double residual_tolerance, bool minimum_norm);
}  // namespace

FoldPoint correct_fold(const NonlinearDDE& system, int j, const Eigen::VectorXd& x0, double par0, const NewtonOptions& options,
                       double residual_tolerance) {
    return correct_steady_state(system, j, x0, par0, options, residual_tolerance, false);
}

namespace {
FoldPoint correct_steady_state(const NonlinearDDE& system, int j, const Eigen::VectorXd& x0, double par0, const NewtonOptions& options,
                               double residual_tolerance, bool minimum_norm) {
    check_parameter(system, j);
    check_derivatives(system);
    const int n = system.dimension();
    FoldPoint r;
    r.x = x0;
    r.par = par0;
    // v0: the null vector of J_x at the start
    const std::vector<Eigen::MatrixXd> a = system.jacobians(system.stack_constant(x0), with(system, j, par0));
    Eigen::MatrixXd jx = a[0];
    for (std::size_t k = 1; k < a.size(); ++k) jx += a[k];
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jx, Eigen::ComputeFullV);
    const Eigen::VectorXd v0 = svd.matrixV().col(n - 1);
    auto F = [&](const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac) { return fold_system(system, j, v0, z, out, jac); };
    Eigen::VectorXd z(2 * n + 1);
    z << x0, par0, v0;
    const NewtonSummary s = newton_square(z, F, options, r.residuals, minimum_norm);
    Eigen::VectorXd f;
    r.iterations = s.iterations;
    if (z.allFinite() && F(z, f, nullptr)) r.residual = f.cwiseAbs().maxCoeff();
    if (static_cast<int>(r.residuals.size()) == s.iterations) r.residuals.push_back(r.residual);
    r.x = z.head(n);
    r.par = z[n];
    r.status = converged(s.status) && !(r.residual <= residual_tolerance) ? Status::NumericalIssue : s.status;
    return r;
}
}  // namespace

EquilibriumRoots equilibrium_roots(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, RootOptions ro) {
    return equilibrium_roots(linearise(system, x, p), std::move(ro));
}

EquilibriumRoots equilibrium_roots(const LinearDDE& lin, RootOptions ro) {
    EquilibriumRoots r;
    ro.count = std::max(ro.count, 2);
    RootResult rr = rightmost_roots(lin, ro);
    if (!converged(rr.status) && ro.count < 8) {
        // a few roots may not settle between degrees where more do (a cut through a cluster,
        // as on DDE-BIFTOOL's delayed Duffing oscillator): the former request of 8
        ro.count = 8;
        rr = rightmost_roots(lin, ro);
    }
    while (converged(rr.status) && !rr.roots.empty() && !(rr.strip_floor < 0.0) && ro.count < 256 &&
           static_cast<int>(rr.roots.size()) >= ro.count) {
        ro.count *= 2;
        rr = rightmost_roots(lin, ro);
    }
    r.status = rr.status;
    r.abscissa = rr.spectral_abscissa();
    for (const Root& root : rr.roots) {
        r.roots.push_back(root.value);
        if (root.value.real() > marginal_band(root.value)) ++r.unstable;
    }
    r.stable = converged(rr.status) && !rr.roots.empty() && r.abscissa < -marginal_band(rr.roots.front().value);
    return r;
}

HopfPoint correct_hopf(const NonlinearDDE& system, int j, const Eigen::VectorXd& x0, double par0, double omega0, const VectorXc& q0in,
                       const NewtonOptions& options, double residual_tolerance) {
    check_parameter(system, j);
    check_derivatives(system);
    if (!(std::isfinite(omega0) && omega0 > 0.0)) throw std::invalid_argument("omega0 = " + detail::format_number(omega0) + ": expected a value > 0");
    const int n = system.dimension();
    HopfPoint r;
    r.x = x0;
    r.par = par0;
    r.omega = omega0;
    VectorXc q0 = q0in;
    if (q0.size() == 0) {
        const MatrixXc d = linearise(system, x0, with(system, j, par0)).characteristic_matrix(cplx(0.0, omega0));
        const Eigen::JacobiSVD<MatrixXc> svd(d, Eigen::ComputeFullV);
        q0 = svd.matrixV().col(n - 1);
    }
    if (q0.size() != n) throw std::invalid_argument("q0 has " + std::to_string(q0.size()) + " entries: expected the dimension " + std::to_string(n));
    q0 /= q0.norm();
    auto F = [&](const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac) { return hopf_system(system, j, q0, z, out, jac); };
    Eigen::VectorXd z(3 * n + 2);
    z << x0, par0, q0.real(), q0.imag(), omega0;
    const NewtonSummary s = newton_square(z, F, options, r.residuals);
    Eigen::VectorXd f;
    r.iterations = s.iterations;
    if (z.allFinite() && F(z, f, nullptr)) r.residual = f.cwiseAbs().maxCoeff();
    if (static_cast<int>(r.residuals.size()) == s.iterations) r.residuals.push_back(r.residual);
    r.x = z.head(n);
    r.par = z[n];
    r.q = z.segment(n + 1, n).cast<cplx>() + cplx(0.0, 1.0) * z.segment(2 * n + 1, n).cast<cplx>();
    r.omega = z[3 * n + 1];
    r.status = converged(s.status) && !(r.residual <= residual_tolerance && r.omega > 0.0) ? Status::NumericalIssue : s.status;
    return r;
}

bool TwoParameterOptions::is_valid(std::string* why) const {
    std::string m;
    if (!branch.is_valid(&m)) m = "branch." + m;
    else if (parameter2.empty()) m = "parameter2: expected the name of the second parameter";
    else if (parameter2 == branch.parameter) m = "parameter2 = '" + parameter2 + "': expected a parameter other than the first";
    else if (!std::isfinite(from2) || !std::isfinite(to2) || from2 == to2) m = "from2/to2: expected finite, distinct values";
    else if (segment < 2) m = "segment: expected at least 2 points";
    else if (continuation.initial_step < 0.0 || continuation.max_step < 0.0) m = "continuation steps: expected values >= 0 (0 = automatic)";
    if (!m.empty() && why) *why = m;
    return m.empty();
}


double TwoParameterOptions::held_second(const NonlinearDDE& system) const {
    const double held = system.parameter_values()[static_cast<std::size_t>(system.parameter_index(parameter2))];
    const double lo = std::min(from2, to2), hi = std::max(from2, to2);
    if (!(held >= lo && held <= hi))
        throw std::invalid_argument(parameter2 + " = " + detail::format_number(held) + " (its value in the system): expected a value in [" +
                                    detail::format_number(lo) + ", " + detail::format_number(hi) + "]");
    return held;
}

namespace {

/// The branch's analysis from the continuation's result c (points, fold tests, events): the roots
/// at every point, folds, branch points and Hopf points located (the body shared by
/// equilibrium_branch and equilibrium_branch_from_branch_point).
/// from_branch_point: the first point is a branch point (det Delta(0) = 0 there: the first step's
/// sign change is that point, not another one).
EquilibriumBranch analyse_branch(const NonlinearDDE& system, int j, const EquilibriumCurve& curve, const ContinuationResult& c,
                                 const EquilibriumBranchOptions& options, EquilibriumBranch br, bool from_branch_point = false) {
    const int n = system.dimension();
    br.stop = c.stop;

    bool roots_ok = true;
    // the roots of the linearisation at u: the count of unstable roots, the abscissa, stability
    long done = 0;  // points whose roots are computed
    auto evaluate = [&](const Eigen::VectorXd& u) {
        EquilibriumPoint pt;
        pt.par = u[n];
        pt.x = u.head(n);
        // every root with Re >= 0 is counted: the request grows until the result is certified
        // complete in a strip reaching below the axis (strip_floor < 0: every root with
        // Re >= strip_floor is among those found), so no unstable root is missed and the stable
        // ones nearest the axis are seen. (Asking for a fixed number of stable roots instead
        // cost a dense collocation of degree ~90 and 3 s per point on a 5-car ring; starting from
        // 8 roots, 20 s per point on the 3-car ov ring at tau = 0.3, where the 7th and 8th lie near
        // Re = -24 and the dense degree grew to its cap for them: the request starts at the
        // options' count and grows only while the strip does not reach below the axis.)
        RootOptions ro = options.roots;
        if (options.progress && !ro.progress && done < static_cast<long>(c.points.size())) {
            // within the point's search: the count of points done repeated (a heartbeat)
            const long total = static_cast<long>(c.points.size());
            const double par = u[n];
            ro.progress = [&options, done, total, par](long, long, double) { options.progress(done, total, par); };
        }
        const EquilibriumRoots er = equilibrium_roots(system, pt.x, curve.values(u), ro);
        // a progress callback's Cancelled ends in the roots' status: it stops the branch too
        if (er.status == Status::Cancelled) throw Cancelled();
        pt.roots_status = er.status;
        roots_ok = roots_ok && converged(er.status);
        pt.abscissa = er.abscissa;
        pt.roots = er.roots;
        pt.unstable = er.unstable;
        pt.stable = er.stable;
        return pt;
    };
    RootWorkEstimate predicted;
    if (options.before_roots && !c.points.empty()) {
        const Eigen::VectorXd& u = c.points.front();
        RootOptions ro = options.roots;
        ro.count = std::max(ro.count, 2);
        predicted = estimate_root_work(RootProblem{linearise(system, u.head(n), curve.values(u)), nullptr}, ro);
        options.before_roots(static_cast<long>(c.points.size()), predicted, false);
    }
    // five pilot points first (the ends, the middle and the quarters): their mean time predicts
    // the rest. The cost of a point grows with the roots near the axis, which change along the
    // branch: on the 33-car ov ring 0.03 s at both ends, 0.35 s in the unstable middle.
    const long total = static_cast<long>(c.points.size());
    std::vector<long> order;
    std::vector<char> first(c.points.size(), 0);
    for (const long i : {0L, total - 1, total / 2, total / 4, (3 * total) / 4})
        if (i >= 0 && i < total && !first[static_cast<std::size_t>(i)]) {
            first[static_cast<std::size_t>(i)] = 1;
            order.push_back(i);
        }
    const long pilots = static_cast<long>(order.size());
    for (long i = 0; i < total; ++i)
        if (!first[static_cast<std::size_t>(i)]) order.push_back(i);
    br.points.resize(c.points.size());
    double pilot = 0.0;
    for (const long i : order) {
        const Eigen::VectorXd& u = c.points[static_cast<std::size_t>(i)];
        const auto start = std::chrono::steady_clock::now();
        br.points[static_cast<std::size_t>(i)] = evaluate(u);
        ++done;
        if (options.before_roots && done <= pilots) {
            pilot += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            RootWorkEstimate measured = predicted;
            measured.seconds = pilot / static_cast<double>(done);
            measured.units = static_cast<double>(done);
            measured.basis = "the mean over " + std::to_string(done) + (done == 1 ? " point" : " points") + " along the branch, measured";
            options.before_roots(total, measured, static_cast<int>(done));
        }
        if (options.progress) options.progress(done, total, u[n]);
    }

    bool special_ok = true;
    for (const ContinuationEvent& ev : c.events) {
        if (ev.kind != ContinuationEvent::Kind::Test) continue;
        FoldPoint f = correct_fold(system, j, ev.u.head(n), ev.u[n], options.special, options.special_residual);
        f.after = ev.after;
        special_ok = special_ok && converged(f.status);
        br.folds.push_back(std::move(f));
    }

    // Steady-state bifurcations: det(A_0 + ... + A_m) = det Delta(0) changes sign between two
    // points, i.e. an odd number of real roots crosses 0. Where the step holds no fold (the
    // tangent test above), it is a branch point, located by Newton on the same system as a fold.
    std::vector<double> dets;
    for (std::size_t k = 0; k < c.points.size(); ++k) {
        Eigen::MatrixXd jac;
        dets.push_back(curve.jacobian(c.points[k], jac) ? jac.leftCols(n).determinant() : std::numeric_limits<double>::quiet_NaN());
    }
    std::vector<int> real_crossing(br.points.size(), 0);  // +-1 at step k when det Delta(0) changes sign there
    for (std::size_t k = 0; k + 1 < dets.size(); ++k) {
        const bool start = from_branch_point && k == 0;  // the branch point itself: a real root leaves 0 here
        if (!(dets[k] * dets[k + 1] < 0.0) && !start) continue;
        real_crossing[k] = 1;
        if (start) continue;
        bool fold_here = false;
        for (const FoldPoint& f : br.folds) fold_here = fold_here || f.after == static_cast<int>(k);
        if (fold_here) continue;
        const std::size_t from = std::abs(dets[k]) <= std::abs(dets[k + 1]) ? k : k + 1;
        FoldPoint f = correct_steady_state(system, j, br.points[from].x, br.points[from].par, options.special, options.special_residual, true);
        f.kind = "branch_point";
        f.after = static_cast<int>(k);
        special_ok = special_ok && converged(f.status);
        br.folds.push_back(std::move(f));
    }
    std::sort(br.folds.begin(), br.folds.end(), [](const FoldPoint& x, const FoldPoint& y) { return x.after < y.after; });

    // Hopf candidates between consecutive points: a genuine complex root (Im > kComplexFloor
    // |lambda|) whose nearest genuine complex partner at the next point has a real part of the
    // other sign; and, where these matched crossings do not account for the change in the number
    // of unstable roots (counted with conjugates, less one for a real root through 0), the
    // complex root nearest the axis. A complex pair that meets on the real axis (two real roots
    // after it) changes no count and a real root through 0 is a branch point or fold: neither
    // is a Hopf candidate, and a corrected point with omega <= kComplexFloor max(1, |lambda|) is
    // dropped (a real root at 0, not a Hopf point).
    constexpr double kComplexFloor = 1e-6;
    auto genuine = [](const cplx& r) { return r.imag() > kComplexFloor * std::max(1.0, std::abs(r)); };
    auto add_hopf = [&](const EquilibriumPoint& from, const cplx& root, int after) {
        HopfPoint h = correct_hopf(system, j, from.x, from.par, root.imag(), {}, options.special, options.special_residual);
        h.after = after;
        if (!(h.omega > kComplexFloor * std::max(1.0, std::abs(root)))) return;  // converged to a real root at 0
        for (const HopfPoint& o : br.hopf)
            if (converged(h.status) && converged(o.status) && std::abs(o.par - h.par) <= 1e-8 * std::max(1.0, std::abs(h.par)) &&
                std::abs(o.omega - h.omega) <= 1e-8 * std::max(1.0, h.omega))
                return;  // the same point from two candidates
        special_ok = special_ok && converged(h.status);
        br.hopf.push_back(std::move(h));
    };
    // One step [a, b]: the matched crossings, then the unexplained rest. Several crossings in one
    // step (the ring modes of a long ring crowd near the ends of the unstable range) defeat the
    // matching by nearest root: when the Hopf points located in the step do not explain the
    // change in the count of unstable roots (2 per Hopf point, 1 for a real crossing), the step
    // is halved (the equilibrium at the midpoint by Newton at fixed parameter from the chord's
    // midpoint) and each half searched again, up to 2^12 pieces; a change still unexplained is
    // reported (the branch's status: a special point was not located).
    // Hopf points located in [lo, hi], from whichever step's candidate they were corrected (a
    // candidate may converge to a crossing of a neighbouring step)
    auto located_in = [&](double lo, double hi) {
        int count = 0;
        for (const HopfPoint& h : br.hopf)
            if (converged(h.status) && h.par >= std::min(lo, hi) - 1e-12 && h.par <= std::max(lo, hi) + 1e-12) ++count;
        return count;
    };
    std::function<void(const EquilibriumPoint&, const EquilibriumPoint&, int, int)> search_step =
        [&](const EquilibriumPoint& a, const EquilibriumPoint& b, int k, int depth) {
            int net = 0;  // matched crossings: +1 to the right, -1 to the left
            for (const cplx& ra : a.roots) {
                if (!genuine(ra)) continue;
                const cplx* nearest = nullptr;
                for (const cplx& rb : b.roots)
                    if (genuine(rb) && (!nearest || std::abs(rb - ra) < std::abs(*nearest - ra))) nearest = &rb;
                if (!nearest || (ra.real() > 0.0) == (nearest->real() > 0.0)) continue;
                net += nearest->real() > 0.0 ? 1 : -1;
                const bool from_a = std::abs(ra.real()) <= std::abs(nearest->real());
                add_hopf(from_a ? a : b, from_a ? ra : *nearest, k);
            }
            const int change = b.unstable - a.unstable - 2 * net;  // what the matched crossings leave unexplained
            if (std::abs(change) > real_crossing[static_cast<std::size_t>(k)]) {
                const EquilibriumPoint* from = nullptr;
                cplx best(std::numeric_limits<double>::infinity(), 0.0);
                for (const EquilibriumPoint* p : {&a, &b})
                    for (const cplx& r : p->roots)
                        if (genuine(r) && std::abs(r.real()) < std::abs(best.real())) best = r, from = p;
                if (from) add_hopf(*from, best, k);
            }
            const int needed = std::abs(b.unstable - a.unstable) - real_crossing[static_cast<std::size_t>(k)];
            if (needed <= 2 * located_in(a.par, b.par)) return;
            if (depth >= 12 || !(a.roots_status == Status::Converged && b.roots_status == Status::Converged)) {
                special_ok = false;
                return;
            }
            Eigen::VectorXd mid(n);
            mid = 0.5 * (a.x + b.x);
            const double pm = 0.5 * (a.par + b.par);
            const EquilibriumResult em = find_equilibrium(system, mid, options.equilibrium, with(system, j, pm));
            if (!converged(em.status)) {
                special_ok = false;
                return;
            }
            Eigen::VectorXd um(n + 1);
            um << em.x, pm;
            const EquilibriumPoint m = evaluate(um);
            search_step(a, m, k, depth + 1);
            search_step(m, b, k, depth + 1);
        };
    for (std::size_t k = 0; k + 1 < br.points.size(); ++k) search_step(br.points[k], br.points[k + 1], static_cast<int>(k), 0);
    // each located point belongs to the step whose parameter range holds it
    for (HopfPoint& h : br.hopf) {
        if (!converged(h.status)) continue;
        for (std::size_t k = 0; k + 1 < br.points.size(); ++k)
            if (h.par >= std::min(br.points[k].par, br.points[k + 1].par) && h.par <= std::max(br.points[k].par, br.points[k + 1].par)) {
                h.after = static_cast<int>(k);
                break;
            }
    }
    // in the order met along the branch: by step, and within a step in its direction
    std::sort(br.hopf.begin(), br.hopf.end(), [&](const HopfPoint& x, const HopfPoint& y) {
        if (x.after != y.after) return x.after < y.after;
        const auto k = static_cast<std::size_t>(x.after);
        const bool up = k + 1 < br.points.size() ? br.points[k + 1].par >= br.points[k].par : true;
        return up ? x.par < y.par : x.par > y.par;
    });

    for (EquilibriumPoint& p : br.points)
        if (static_cast<int>(p.roots.size()) > options.roots.count) p.roots.resize(static_cast<std::size_t>(options.roots.count));

    const bool ended_well = c.stop == ContinuationStop::Bound || c.stop == ContinuationStop::ClosedLoop || c.stop == ContinuationStop::LeftDomain;
    br.status = !ended_well ? (converged(c.status) ? Status::NumericalIssue : c.status)
                : !roots_ok ? Status::MaxDegreeReached
                : !special_ok ? Status::MaxIterations
                              : Status::Converged;
    std::string cm = c.message;  // the engine names unknowns by index: the last one is the parameter
    const std::string unknown = "unknown " + std::to_string(n);
    for (std::size_t at = cm.find(unknown); at != std::string::npos; at = cm.find(unknown, at + 1))
        if (at + unknown.size() == cm.size() || !std::isdigit(static_cast<unsigned char>(cm[at + unknown.size()])))
            cm.replace(at, unknown.size(), "the parameter " + options.parameter);
    br.message = std::to_string(br.points.size()) + " points, " + std::to_string(br.folds.size()) + " folds, " + std::to_string(br.hopf.size()) +
                 " Hopf points; the branch ended: " + to_string(c.stop) + (cm.empty() ? "" : " (" + cm + ")");
    if (!roots_ok) br.message += "; the roots did not converge at some points";
    if (!special_ok) br.message += "; a fold, branch point or Hopf point was not located";
    return br;
}


/// The continuation options of a branch of options (steps from the range, the box of the parameter).
ContinuationOptions branch_continuation(const EquilibriumBranchOptions& options, int n) {
    ContinuationOptions co = options.continuation;
    const double range = std::abs(options.to - options.from);
    if (co.initial_step == 0.0) co.initial_step = range / 100.0;
    if (co.max_step == 0.0) co.max_step = range / 20.0;
    co.initial_step = std::min(co.initial_step, co.max_step);
    co.min_step = std::min(co.min_step, co.initial_step);
    co.lower = Eigen::VectorXd::Constant(n + 1, -std::numeric_limits<double>::infinity());
    co.upper = Eigen::VectorXd::Constant(n + 1, std::numeric_limits<double>::infinity());
    co.lower[n] = std::min(options.from, options.to);
    co.upper[n] = std::max(options.from, options.to);
    return co;
}

}  // namespace

EquilibriumBranch equilibrium_branch(const NonlinearDDE& system, const Eigen::VectorXd& guess, const EquilibriumBranchOptions& options) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("equilibrium branch options: " + why);
    const int j = system.parameter_index(options.parameter);
    check_derivatives(system);
    const int n = system.dimension();
    EquilibriumBranch br;
    br.parameter = options.parameter;

    const std::vector<double> p0 = with(system, j, options.from);
    const EquilibriumResult e = find_equilibrium(system, guess, options.equilibrium, p0);
    if (!converged(e.status)) {
        br.status = e.status;
        br.message = "no equilibrium at " + options.parameter + " = " + detail::format_number(options.from) + " from the guess: " + e.message;
        return br;
    }

    const ContinuationOptions co = branch_continuation(options, n);

    const EquilibriumCurve curve(system, j);
    Eigen::VectorXd u0(n + 1), dir = Eigen::VectorXd::Zero(n + 1);
    u0 << e.x, options.from;
    dir[n] = options.to > options.from ? 1.0 : -1.0;
    const std::vector<TestFunction> tests{{"fold", [n](const Eigen::VectorXd&, const Eigen::VectorXd& t) { return t[n]; }, false}};
    const ContinuationResult c = continue_branch(curve, u0, dir, co, tests);
    return analyse_branch(system, j, curve, c, options, std::move(br));
}

namespace {

/// The two halves of a switched branch joined through their common first point (the branch
/// point): `away` reversed, then `towards` after its first point.
EquilibriumBranch join_halves(EquilibriumBranch away, const EquilibriumBranch& towards) {
    EquilibriumBranch j;
    j.parameter = towards.parameter;
    const int m = static_cast<int>(away.points.size());
    j.points.assign(away.points.rbegin(), away.points.rend());
    j.points.insert(j.points.end(), towards.points.begin() + (towards.points.empty() ? 0 : 1), towards.points.end());
    // a special point between points k and k + 1 of the away half lies between m - 2 - k and
    // m - 1 - k of the reversed one; one of the towards half after point k after m - 1 + k
    auto join = [m](auto away_points, const auto& towards_points, auto& out) {
        std::reverse(away_points.begin(), away_points.end());  // in the order met along the reversed half
        for (auto& x : away_points) x.after = m - 2 - x.after;
        out = std::move(away_points);
        for (auto x : towards_points) {
            x.after += m - 1;
            out.push_back(std::move(x));
        }
        std::stable_sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.after < b.after; });
    };
    join(away.folds, towards.folds, j.folds);
    join(away.hopf, towards.hopf, j.hopf);
    j.stop = towards.stop;
    j.status = towards.status != Status::Converged ? towards.status : away.status;
    j.message = std::to_string(j.points.size()) + " points, " + std::to_string(j.folds.size()) + " folds, " + std::to_string(j.hopf.size()) +
                " Hopf points (both halves through the branch point); the half towards the end: " + towards.message + "; the other half: " + away.message;
    return j;
}

}  // namespace

EquilibriumBranch equilibrium_branch_from_branch_point(const NonlinearDDE& system, const EquilibriumBranch& branch, const FoldPoint& bp,
                                                       const EquilibriumBranchOptions& options, BranchSide side) {
    if (side == BranchSide::Both) {
        const EquilibriumBranch towards = equilibrium_branch_from_branch_point(system, branch, bp, options, BranchSide::Towards);
        const EquilibriumBranch away = equilibrium_branch_from_branch_point(system, branch, bp, options, BranchSide::Away);
        // a half without points (its first point did not converge): the other alone, undecided
        // with the reason
        if (towards.points.empty() || away.points.empty()) {
            EquilibriumBranch r = towards.points.empty() ? away : towards;
            const EquilibriumBranch& failed = towards.points.empty() ? towards : away;
            r.status = failed.status != Status::Converged ? failed.status : Status::NumericalIssue;
            r.message = "one half only: " + r.message + "; the other half: " + failed.message;
            return r;
        }
        return join_halves(away, towards);
    }
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("equilibrium branch options: " + why);
    const int j = system.parameter_index(options.parameter);
    check_derivatives(system);
    const int n = system.dimension();
    if (bp.kind != "branch_point" || !converged(bp.status) || bp.x.size() != n)
        throw std::invalid_argument("branch switching: expected a located branch point of the system's dimension");
    if (bp.after < 0 || bp.after + 1 >= static_cast<int>(branch.points.size()))
        throw std::invalid_argument("branch switching: the branch point must lie between two points of its branch");
    EquilibriumBranch br;
    br.parameter = options.parameter;
    const EquilibriumCurve curve(system, j);
    Eigen::VectorXd u0(n + 1);
    u0 << bp.x, bp.par;
    // the kernel of [Delta(0) f_p] at the point (two dimensions at a branch point), and in it the
    // direction orthogonal to the old branch (its chord across the point)
    Eigen::MatrixXd J;
    if (!curve.jacobian(u0, J)) throw std::invalid_argument("branch switching: no finite Jacobian at the branch point");
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
    const Eigen::MatrixXd K = svd.matrixV().rightCols(2);
    const EquilibriumPoint &a = branch.points[static_cast<std::size_t>(bp.after)], &b = branch.points[static_cast<std::size_t>(bp.after) + 1];
    Eigen::VectorXd t1(n + 1);
    t1 << b.x - a.x, b.par - a.par;
    const Eigen::Vector2d c1 = K.transpose() * t1;
    if (!(c1.norm() > 0.0)) throw std::invalid_argument("branch switching: the old branch does not cross the point");
    Eigen::VectorXd t2 = K * Eigen::Vector2d(-c1(1), c1(0));
    t2 /= t2.norm();
    // the first point: Newton on [F(u); t2 . (u - u0) - h] from u0 + h t2 (the hyperplane meets
    // the new branch at distance ~h, the old one only at ~sqrt(h)); on the side of t2 whose
    // tangent there moves the parameter towards `to` (either side when the branch is vertical)
    const ContinuationOptions co = branch_continuation(options, n);
    const double h = co.initial_step;
    auto first_point = [&](const Eigen::VectorXd& dir, Eigen::VectorXd& u) {
        u = u0 + h * dir;
        for (int it = 0; it < 30; ++it) {
            Eigen::VectorXd F;
            Eigen::MatrixXd Ju;
            if (!curve.residual(u, F) || !curve.jacobian(u, Ju)) return false;
            Eigen::VectorXd R(n + 1);
            R << F, dir.dot(u - u0) - h;
            Eigen::MatrixXd E(n + 1, n + 1);
            E << Ju, dir.transpose();
            const Eigen::VectorXd du = E.partialPivLu().solve(R);
            if (!du.allFinite()) return false;
            u -= du;
            if (du.lpNorm<Eigen::Infinity>() <= 1e-12 * std::max(1.0, u.lpNorm<Eigen::Infinity>()) && R.lpNorm<Eigen::Infinity>() <= 1e-10) return true;
        }
        return false;
    };
    Eigen::VectorXd u, dir;
    bool ok = false;
    for (const double sign : {1.0, -1.0}) {
        Eigen::VectorXd us, ts;
        if (!first_point(sign * t2, us) || !tangent(curve, us, sign * t2, ts)) continue;
        const bool towards = (ts[n] > 0.0) == (options.to > options.from);
        if (!ok || towards) {
            u = us;
            dir = sign * t2;
            ok = true;
        }
        if (towards) break;
    }
    if (ok && side == BranchSide::Away) {
        // the opposite half: its first point along -dir
        const Eigen::VectorXd back = -dir;
        ok = first_point(back, u);
        dir = back;
    }
    if (!ok) {
        br.status = Status::MaxIterations;
        br.message = "the first point of the other branch did not converge from the branch point at " + options.parameter + " = " +
                     detail::format_number(bp.par) + (side == BranchSide::Away ? " (the half away from the end)" : "");
        return br;
    }
    const std::vector<TestFunction> tests{{"fold", [n](const Eigen::VectorXd&, const Eigen::VectorXd& t) { return t[n]; }, false}};
    ContinuationResult c = continue_branch(curve, u, dir, co, tests);
    // the branch point itself first: the new branch starts there
    c.points.insert(c.points.begin(), u0);
    for (ContinuationEvent& ev : c.events) ++ev.after;
    return analyse_branch(system, j, curve, c, options, std::move(br), true);
}
}  // namespace ddemap
