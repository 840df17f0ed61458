#include "ddemap/analysis/bifurcation/hopf.hpp"
#include "ddemap/analysis/bifurcation/normal_forms.hpp"

#include "analysis/bifurcation/internal/chord_zero.hpp"
#include "analysis/bifurcation/internal/curve_trace.hpp"
#include "analysis/bifurcation/internal/multilinear.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <Eigen/Dense>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

using namespace detail::multilinear;

void check_system(const NonlinearDDE& s, int j, const char* what) {
    if (!s.has_higher_derivatives() || !s.has_delay_derivatives())
        throw std::invalid_argument(std::string(what) +
                                    ": the system gives no higher derivatives or no derivatives of its delays: expected an expression system or a built-in model (NonlinearDDEOf)");
    if (j < 0 || j >= static_cast<int>(s.parameter_names().size()))
        throw std::invalid_argument(std::string(what) + ": parameter index " + std::to_string(j) + ": expected 0.." +
                                    std::to_string(static_cast<int>(s.parameter_names().size()) - 1));
}

/// The Hopf curve in u = (x, p1, Re q, Im q, omega, p2).
class HopfCurveProblem final : public detail::TwoParameterCurve {
public:
    HopfCurveProblem(const NonlinearDDE& s, int j1, int j2, VectorXc q0)
        : TwoParameterCurve(s, j1, j2, 3 * s.dimension() + 2,
                            [&s, q0](int j, const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac, const std::vector<double>& p) {
                                return hopf_system(s, j, q0, z, out, jac, p);
                            }),
          m_q0(std::move(q0)), m_n(s.dimension()) {}
    bool in_domain(const Eigen::VectorXd& u) const override { return u[3 * m_n + 1] > 0.0 && TwoParameterCurve::in_domain(u); }
    const VectorXc& q0() const { return m_q0; }

private:
    VectorXc m_q0;
    int m_n;
};

VectorXc q_of(const Eigen::VectorXd& u, int n) {
    return u.segment(n + 1, n).cast<cplx>() + I1 * u.segment(2 * n + 1, n).cast<cplx>();
}

}  // namespace

std::string to_string(Criticality c) {
    switch (c) {
        case Criticality::Supercritical: return "supercritical";
        case Criticality::Subcritical: return "subcritical";
        case Criticality::Degenerate: return "degenerate";
    }
    return "degenerate";
}

bool HopfCoefficientOptions::is_valid(std::string* why) const {
    std::string m;
    if (!(std::isfinite(degenerate_tolerance) && degenerate_tolerance >= 0.0 && degenerate_tolerance < 1.0))
        m = "degenerate_tolerance: expected a value in [0, 1)";
    else if (!(std::isfinite(transversal_tolerance) && transversal_tolerance >= 0.0 && transversal_tolerance < 1.0))
        m = "transversal_tolerance: expected a value in [0, 1)";
    if (!m.empty() && why) *why = m;
    return m.empty();
}

HopfCoefficients hopf_coefficients(const NonlinearDDE& s, int j, const std::vector<double>& values, const Eigen::VectorXd& x, double omega,
                                   const HopfCoefficientOptions& options) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("Hopf coefficient options: " + why);
    check_system(s, j, "Hopf coefficients");
    if (values.size() != s.parameter_values().size())
        throw std::invalid_argument("Hopf coefficients: " + std::to_string(values.size()) + " parameter values: expected " +
                                    std::to_string(s.parameter_values().size()));
    if (!(std::isfinite(omega) && omega > 0.0))
        throw std::invalid_argument("Hopf coefficients: omega = " + detail::format_number(omega) + ": expected a value > 0");
    const int n = s.dimension();
    HopfCoefficients r;
    r.par = values[static_cast<std::size_t>(j)];
    r.x = x;
    r.omega = omega;
    const Eigen::VectorXd u = s.stack_constant(x);  // checks the size and finiteness of x
    std::vector<Eigen::MatrixXd> a;
    std::vector<double> tau, dtau;
    try {
        a = s.jacobians(u, values);
        tau = s.delays(values);
        dtau = s.delay_derivatives(values, j);
    } catch (const std::invalid_argument& e) {
        r.message = std::string("the system cannot be evaluated at the Hopf point: ") + e.what();
        return r;
    }
    tau.insert(tau.begin(), 0.0);
    dtau.insert(dtau.begin(), 0.0);
    const cplx lambda(0.0, omega);

    // null vectors
    const MatrixXc dl = delta(a, tau, lambda);
    const Eigen::JacobiSVD<MatrixXc> svd(dl, Eigen::ComputeFullU | Eigen::ComputeFullV);
    VectorXc q = svd.matrixV().col(n - 1);
    Eigen::Index big = 0;
    q.cwiseAbs().maxCoeff(&big);
    q *= std::conj(q[big]) / std::abs(q[big]);
    Eigen::RowVectorXcd p = svd.matrixU().col(n - 1).adjoint();
    const double size = std::max(1.0, svd.singularValues()[0]);
    r.null_residual = std::max((dl * q).norm(), (p * dl).norm() / p.norm()) / size;
    if (n > 1 && svd.singularValues()[n - 2] <= 1e-8 * size) {
        r.message = "Delta(i omega) has a null space of dimension > 1 (a double Hopf eigenvalue): the normal form of a simple Hopf point does not apply";
        return r;
    }
    const cplx scale = (p * delta(a, tau, lambda, true) * q)(0, 0);
    if (!(std::abs(scale) > 1e-12 * delta(a, tau, lambda, true).norm())) {
        r.message = "p Delta'(i omega) q = 0: the eigenvalue i omega is not simple";
        return r;
    }
    p /= scale;
    r.q = q;
    r.p = p;

    const Eigen::PartialPivLU<MatrixXc> lu2(delta(a, tau, 2.0 * lambda));
    const Eigen::PartialPivLU<MatrixXc> lu0(delta(a, tau, cplx(0.0, 0.0)));
    if (!(lu2.rcond() > 1e-13)) {
        r.message = "Delta(2 i omega) is singular (a 1:2 resonance): the normal form needs higher order";
        return r;
    }
    if (!(lu0.rcond() > 1e-13)) {
        r.message = "Delta(0) is singular (a zero-Hopf point): the normal form needs higher order";
        return r;
    }
    const VectorXc phi = stack(q, lambda, tau), phibar = phi.conjugate();
    const VectorXc h20 = lu2.solve(b_complex(s, u, values, phi, phi));
    const VectorXc h11 = lu0.solve(b_complex(s, u, values, phi, phibar));
    const VectorXc H20 = stack(h20, 2.0 * lambda, tau), H11 = stack(h11, cplx(0.0, 0.0), tau);
    const cplx t1 = (p * c_complex(s, u, values, phi, phi, phibar))(0, 0);
    const cplx t2 = (p * b_complex(s, u, values, phibar, H20))(0, 0);
    const cplx t3 = (p * b_complex(s, u, values, phi, H11))(0, 0);
    r.c1 = 0.5 * (t1 + t2 + 2.0 * t3);
    r.l1 = r.c1.real() / omega;
    r.l1_scale = (std::abs(t1) + std::abs(t2) + 2.0 * std::abs(t3)) / (2.0 * omega);
    const bool degenerate = !(std::abs(r.l1) > options.degenerate_tolerance * r.l1_scale);
    r.criticality = degenerate ? Criticality::Degenerate : r.l1 < 0.0 ? Criticality::Supercritical : Criticality::Subcritical;

    // transversality: dDelta/dp q = -D^2 f[Phi, (S x', e_j)] + lambda sum_k tau_k' A_k Phi_k
    const Eigen::VectorXd fp = s.parameter_derivative(u, j, values);
    const VectorXc xp = lu0.solve(fp.cast<cplx>());
    const Eigen::VectorXd sx = s.stack_constant(xp.real());
    Eigen::VectorXd ej = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(values.size()));
    ej[j] = 1.0;
    VectorXc dq = -(d2(s, u, values, phi.real(), sx, ej).cast<cplx>() + I1 * d2(s, u, values, phi.imag(), sx, ej).cast<cplx>());
    for (std::size_t k = 0; k < a.size(); ++k)
        if (dtau[k] != 0.0) dq += lambda * dtau[k] * (a[k].cast<cplx>() * phi.segment(static_cast<Eigen::Index>(k) * n, n));
    r.dlambda = -(p * dq)(0, 0);
    r.dre_dpar = r.dlambda.real();
    const bool transversal = std::abs(r.dre_dpar) > options.transversal_tolerance * std::abs(r.dlambda);
    if (!degenerate && transversal) {
        r.side = (-r.dre_dpar / r.c1.real()) > 0.0 ? 1 : -1;
        r.amplitude_coefficient = 4.0 * q.cwiseAbs() * std::sqrt(std::abs(r.dre_dpar / r.c1.real()));
    }
    const Eigen::VectorXd fx = s.f(u, values);
    r.residual = std::max(fx.cwiseAbs().maxCoeff(), (dl * q).cwiseAbs().maxCoeff());
    const bool finite = std::isfinite(r.l1) && std::isfinite(r.l1_scale) && std::isfinite(r.dre_dpar) && r.amplitude_coefficient.allFinite();
    r.status = finite ? Status::Converged : Status::NumericalIssue;
    r.message = !finite ? "a coefficient is not finite"
                : degenerate ? "L1 = " + detail::format_number(r.l1) + " is within the tolerance of 0: degenerate (a generalised Hopf point)"
                : !transversal ? "the root crosses the imaginary axis with zero speed: no side and no amplitude"
                               : "";
    return r;
}

HopfCoefficients hopf_coefficients(const NonlinearDDE& s, int j, const HopfPoint& h, const HopfCoefficientOptions& options) {
    check_system(s, j, "Hopf coefficients");
    if (!converged(h.status) || !(h.omega > 0.0) || h.x.size() != s.dimension() || !h.x.allFinite()) {
        HopfCoefficients r;
        r.status = converged(h.status) ? Status::NumericalIssue : h.status;
        r.par = h.par;
        r.x = h.x;
        r.omega = h.omega;
        r.residual = h.residual;
        r.message = "the Hopf point was not located (" + to_string(h.status) + ", residual " + detail::format_number(h.residual) + ")";
        return r;
    }
    std::vector<double> p = s.parameter_values();
    p[static_cast<std::size_t>(j)] = h.par;
    HopfCoefficients r = hopf_coefficients(s, j, p, h.x, h.omega, options);
    r.residual = h.residual;
    return r;
}

HopfAnalysis hopf_points(const NonlinearDDE& s, const Eigen::VectorXd& guess, const EquilibriumBranchOptions& branch,
                         const HopfCoefficientOptions& options) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument("Hopf coefficient options: " + why);
    HopfAnalysis r;
    r.branch = equilibrium_branch(s, guess, branch);
    const int j = s.parameter_index(branch.parameter);
    int failed = 0;
    for (const HopfPoint& h : r.branch.hopf) {
        r.points.push_back(hopf_coefficients(s, j, h, options));
        if (!converged(r.points.back().status)) {
            ++failed;
            if (converged(r.status)) r.status = r.points.back().status;
        }
    }
    if (!converged(r.branch.status)) r.status = r.branch.status;
    r.message = r.branch.message;
    if (failed > 0) r.message += "; " + std::to_string(failed) + " Hopf point(s) without coefficients";
    return r;
}

bool HopfCurveOptions::is_valid(std::string* why) const {
    std::string m;
    if (!TwoParameterOptions::is_valid(&m)) {
    } else if (!coefficients.is_valid(&m)) {
        m = "coefficients." + m;
    }
    if (!m.empty() && why) *why = m;
    return m.empty();
}

namespace {

/// L1 at a point u of the curve.
HopfCoefficients coefficients_at(const NonlinearDDE& s, int j1, const HopfCurveProblem& pr, const Eigen::VectorXd& u,
                                 const HopfCoefficientOptions& o) {
    const int n = s.dimension();
    HopfCoefficients c = hopf_coefficients(s, j1, pr.values(u), u.head(n), u[3 * n + 1], o);
    Eigen::VectorXd f;
    if (pr.residual(u, f)) c.residual = f.cwiseAbs().maxCoeff();
    return c;
}

/// Illinois regula falsi on L1 along the chord from ua to ub.
GeneralisedHopfPoint locate_generalised(const NonlinearDDE& s, int j1, const HopfCurveProblem& pr, const Eigen::VectorXd& ua,
                                        const Eigen::VectorXd& ub, double fa, double fb, const HopfCurveOptions& o) {
    const int n = s.dimension();
    GeneralisedHopfPoint g;
    HopfCoefficients last;
    const detail::ChordZero z = detail::chord_zero(
        pr, ua, ub, fa, fb, o.continuation.newton,
        [&](const Eigen::VectorXd& u, double& value) {
            last = coefficients_at(s, j1, pr, u, o.coefficients);
            value = last.l1;
            return converged(last.status);
        },
        [&](const Eigen::VectorXd&, double value) { return std::abs(value) <= 1e-13 * last.l1_scale; });
    g.status = z.status;
    if (z.u.size() == ua.size() && converged(last.status)) g.l1 = last.l1, g.residual = last.residual;
    g.x = z.u.head(n);
    g.par = z.u[n];
    g.omega = z.u[3 * n + 1];
    g.par2 = z.u[3 * n + 2];
    if (converged(g.status) && g.omega > 0.0 && s.has_higher_derivatives()) g.normal_form = generalised_hopf_normal_form(s, g.x, pr.values(z.u), g.omega);
    return g;
}

/// det Delta(0) = det(-sum_k A_k) at the equilibrium x, scaled by the n-th power of the largest
/// column norm (a real root through 0 changes its sign), with the size of its terms.
bool scaled_det0(const NonlinearDDE& s, const Eigen::VectorXd& x, const std::vector<double>& p, double& value) {
    try {
        const LinearDDE lin = linearise(s, x, p);
        const MatrixXc d = lin.characteristic_matrix(cplx(0.0, 0.0));
        const Eigen::MatrixXd m = d.real();
        double scale = 1.0;
        for (Eigen::Index c = 0; c < m.cols(); ++c) scale = std::max(scale, m.col(c).norm());
        value = (m / scale).partialPivLu().determinant();
        return std::isfinite(value);
    } catch (const std::invalid_argument&) {
        return false;
    }
}

/// The zero of det Delta(0) along the chord from ua to ub by Illinois regula falsi, every trial
/// corrected onto the curve by Newton with minimum-norm steps (a complete orthogonal
/// decomposition of the bordered Jacobian, rank threshold 1e-10) until the residual is at
/// rounding. Where the equilibrium is itself a branch point (the trivial equilibrium of a
/// symmetric system at its pitchfork: f(0, p) = 0 for all p) the curve system is singular exactly
/// at the zero-Hopf point (the equilibrium equations lose a rank), and plain Newton fails near it
/// (DDE-BIFTOOL's two-layer neuron demo); the minimum-norm steps leave the undetermined direction
/// alone and converge.
detail::ChordZero chord_zero_minimum_norm(const NonlinearDDE& s, const HopfCurveProblem& pr, const Eigen::VectorXd& ua, const Eigen::VectorXd& ub,
                                          double fa, double fb) {
    const int n = s.dimension();
    auto correct_mn = [&](Eigen::VectorXd& u, const Eigen::VectorXd& dir, double b) {
        const Eigen::Index m = u.size();
        Eigen::VectorXd f, rhs(m);
        Eigen::MatrixXd j, bordered(m, m);
        for (int it = 0; it < 100; ++it) {
            if (!pr.residual(u, f) || !pr.jacobian(u, j)) return Status::NumericalIssue;
            rhs.head(m - 1) = f;
            rhs(m - 1) = dir.dot(u) - b;
            if (rhs.lpNorm<Eigen::Infinity>() <= 1e-14 * std::max(1.0, u.lpNorm<Eigen::Infinity>())) return Status::Converged;
            bordered.topRows(m - 1) = j;
            bordered.row(m - 1) = dir.transpose();
            Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(bordered);
            cod.setThreshold(1e-10);
            const Eigen::VectorXd du = cod.solve(rhs);
            if (!du.allFinite()) return Status::NumericalIssue;
            u -= du;
            if (du.lpNorm<Eigen::Infinity>() <= 1e-15 * std::max(1.0, u.lpNorm<Eigen::Infinity>())) break;
        }
        return pr.residual(u, f) && f.lpNorm<Eigen::Infinity>() <= 1e-12 ? Status::Converged : Status::MaxIterations;
    };
    return detail::chord_zero_with(
        ua, ub, fa, fb, correct_mn, [&](const Eigen::VectorXd& u, double& value) { return scaled_det0(s, u.head(n), pr.values(u), value); },
        [](const Eigen::VectorXd&, double value) { return std::abs(value) <= 1e-13; });
}

ZeroHopfPoint locate_zero_hopf(const NonlinearDDE& s, const HopfCurveProblem& pr, const Eigen::VectorXd& ua, const Eigen::VectorXd& ub,
                               const HopfCurveOptions& o) {
    const int n = s.dimension();
    ZeroHopfPoint zh;
    double fa = 0.0, fb = 0.0;
    if (!scaled_det0(s, ua.head(n), pr.values(ua), fa) || !scaled_det0(s, ub.head(n), pr.values(ub), fb) || (fa < 0.0) == (fb < 0.0)) {
        zh.status = Status::NumericalIssue;
        zh.x = ua.head(n), zh.par = ua[n], zh.omega = ua[3 * n + 1], zh.par2 = ua[3 * n + 2];
        return zh;
    }
    const detail::ChordZero first = detail::chord_zero(
        pr, ua, ub, fa, fb, o.continuation.newton,
        [&](const Eigen::VectorXd& u, double& value) { return scaled_det0(s, u.head(n), pr.values(u), value); },
        [&](const Eigen::VectorXd&, double value) { return std::abs(value) <= 1e-13; });
    detail::ChordZero z = first;
    if (!converged(first.status)) z = chord_zero_minimum_norm(s, pr, ua, ub, fa, fb);
    zh.status = z.status;
    zh.x = z.u.head(n), zh.par = z.u[n], zh.omega = z.u[3 * n + 1], zh.par2 = z.u[3 * n + 2];
    scaled_det0(s, zh.x, pr.values(z.u), zh.det);
    Eigen::VectorXd f;
    if (pr.residual(z.u, f)) zh.residual = f.cwiseAbs().maxCoeff();
    if (converged(zh.status) && zh.omega > 0.0) zh.normal_form = zero_hopf_normal_form(s, zh.x, pr.values(z.u), zh.omega);
    return zh;
}

/// The Bogdanov-Takens system of HopfCurveBogdanovTakens at z = (x, p1, p2, v0, v1); false when it
/// cannot be evaluated there.
bool bogdanov_takens_system(const NonlinearDDE& s, int j1, int j2, const Eigen::VectorXd& c, const Eigen::VectorXd& z, Eigen::VectorXd& g) {
    const int n = s.dimension();
    std::vector<double> p = s.parameter_values();
    p[static_cast<std::size_t>(j1)] = z[n];
    p[static_cast<std::size_t>(j2)] = z[n + 1];
    try {
        const Eigen::VectorXd x = z.head(n), v0 = z.segment(n + 2, n), v1 = z.segment(2 * n + 2, n);
        const Eigen::VectorXd u = s.stack_constant(x);
        const std::vector<Eigen::MatrixXd> a = s.jacobians(u, p);
        const std::vector<double> tau = s.delays(p);
        Eigen::MatrixXd d0 = -a[0], d1 = Eigen::MatrixXd::Identity(n, n);
        for (std::size_t k = 1; k < a.size(); ++k) d0 -= a[k], d1 += tau[k - 1] * a[k];
        g.resize(3 * n + 2);
        g.head(n) = s.f(u, p);
        g.segment(n, n) = d0 * v0;
        g.segment(2 * n, n) = d0 * v1 + d1 * v0;
        g[3 * n] = c.dot(v0) - 1.0;
        g[3 * n + 1] = c.dot(v1);
    } catch (const std::invalid_argument&) {
        return false;
    }
    return g.allFinite();
}

/// Newton (central-difference Jacobian) on the Bogdanov-Takens system from the end of a Hopf
/// curve: the equilibrium x, (p1, p2) and omega -> 0 there, v0 from Re q.
HopfCurveBogdanovTakens locate_bogdanov_takens(const NonlinearDDE& s, int j1, int j2, const HopfCurvePoint& end) {
    const int n = s.dimension();
    HopfCurveBogdanovTakens bt;
    bt.x = end.x, bt.par = end.par, bt.par2 = end.par2;
    std::vector<double> p = s.parameter_values();
    p[static_cast<std::size_t>(j1)] = end.par;
    p[static_cast<std::size_t>(j2)] = end.par2;
    Eigen::VectorXd z(3 * n + 2);
    try {
        const std::vector<Eigen::MatrixXd> a = s.jacobians(s.stack_constant(end.x), p);
        const std::vector<double> tau = s.delays(p);
        Eigen::MatrixXd d0 = -a[0], d1 = Eigen::MatrixXd::Identity(n, n);
        for (std::size_t k = 1; k < a.size(); ++k) d0 -= a[k], d1 += tau[k - 1] * a[k];
        Eigen::JacobiSVD<Eigen::MatrixXd> svd(d0, Eigen::ComputeFullV);
        Eigen::VectorXd v0 = svd.matrixV().col(n - 1);
        // v1: [Delta(0); v0^T] v1 = [-Delta'(0) v0; 0] in the least-squares sense
        Eigen::MatrixXd m(n + 1, n);
        m.topRows(n) = d0;
        m.row(n) = v0.transpose();
        Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 1);
        rhs.head(n) = -d1 * v0;
        const Eigen::VectorXd v1 = m.completeOrthogonalDecomposition().solve(rhs);
        z << end.x, end.par, end.par2, v0, v1;
    } catch (const std::invalid_argument&) {
        bt.status = Status::NumericalIssue;
        bt.message = "the linearisation is not defined at the curve's end";
        return bt;
    }
    const Eigen::VectorXd c = z.segment(n + 2, n);
    const int N = 3 * n + 2;
    Eigen::VectorXd g, gp, gm;
    Eigen::MatrixXd J(N, N);
    bt.status = Status::MaxIterations;
    for (int it = 0; it < 40; ++it) {
        if (!bogdanov_takens_system(s, j1, j2, c, z, g)) {
            bt.status = Status::NumericalIssue;
            bt.message = "the Bogdanov-Takens system is not defined at an iterate";
            break;
        }
        bt.residual = g.cwiseAbs().maxCoeff();
        for (int k = 0; k < N; ++k) {
            const double h = 1e-7 * std::max(1.0, std::abs(z[k]));
            Eigen::VectorXd zp = z, zm = z;
            zp[k] += h, zm[k] -= h;
            if (!bogdanov_takens_system(s, j1, j2, c, zp, gp) || !bogdanov_takens_system(s, j1, j2, c, zm, gm)) {
                bt.status = Status::NumericalIssue;
                bt.message = "the Bogdanov-Takens system is not defined next to an iterate";
                break;
            }
            J.col(k) = (gp - gm) / (2.0 * h);
        }
        if (bt.status == Status::NumericalIssue) break;
        const Eigen::FullPivLU<Eigen::MatrixXd> lu(J);
        if (!lu.isInvertible()) {
            bt.status = Status::NumericalIssue;
            bt.message = "the Bogdanov-Takens system is singular (a degenerate point)";
            break;
        }
        const Eigen::VectorXd step = lu.solve(g);
        z -= step;
        if (step.cwiseAbs().maxCoeff() <= 1e-13 * std::max(1.0, z.cwiseAbs().maxCoeff())) {
            if (bogdanov_takens_system(s, j1, j2, c, z, g)) bt.residual = g.cwiseAbs().maxCoeff();
            bt.status = bt.residual <= 1e-10 ? Status::Converged : Status::NumericalIssue;
            bt.message = bt.residual <= 1e-10 ? "located" : "Newton stalled with residual " + detail::format_number(bt.residual);
            break;
        }
    }
    bt.x = z.head(n), bt.par = z[n], bt.par2 = z[n + 1];
    if (converged(bt.status) && s.has_higher_derivatives()) {
        p[static_cast<std::size_t>(j1)] = bt.par;
        p[static_cast<std::size_t>(j2)] = bt.par2;
        bt.normal_form = bogdanov_takens_normal_form(s, bt.x, p);
    }
    if (bt.message.empty()) bt.message = "Newton did not converge in 40 iterations";
    return bt;
}

/// The stacked double Hopf system in v = (x, p1, Re q1, Im q1, omega1, p2, Re q2, Im q2, omega2).
bool double_hopf_system(const NonlinearDDE& s, int j1, int j2, const VectorXc& q01, const VectorXc& q02, const Eigen::VectorXd& v,
                        Eigen::VectorXd& g, Eigen::MatrixXd* jac) {
    const int n = s.dimension();
    std::vector<double> p = s.parameter_values();
    p[static_cast<std::size_t>(j1)] = v[n];
    p[static_cast<std::size_t>(j2)] = v[3 * n + 2];
    Eigen::VectorXd z1 = v.head(3 * n + 2), z2(3 * n + 2);
    z2 << v.head(n + 1), v.segment(3 * n + 3, 2 * n + 1);
    Eigen::VectorXd f1, f2, tmp;
    Eigen::MatrixXd J1, J2, J1b, J2b;
    if (!hopf_system(s, j1, q01, z1, f1, jac ? &J1 : nullptr, p) || !hopf_system(s, j1, q02, z2, f2, jac ? &J2 : nullptr, p)) return false;
    g.resize(5 * n + 4);
    g.head(3 * n + 2) = f1;
    g.tail(2 * n + 2) = f2.tail(2 * n + 2);
    if (jac) {
        // the p2 columns: the same systems with p2 as their parameter
        z1[n] = v[3 * n + 2];
        z2[n] = v[3 * n + 2];
        if (!hopf_system(s, j2, q01, z1, tmp, &J1b, p) || !hopf_system(s, j2, q02, z2, tmp, &J2b, p)) return false;
        Eigen::MatrixXd& J = *jac;
        J = Eigen::MatrixXd::Zero(5 * n + 4, 5 * n + 4);
        J.block(0, 0, 3 * n + 2, 3 * n + 2) = J1;
        J.block(0, 3 * n + 2, 3 * n + 2, 1) = J1b.col(n);
        const Eigen::Index r = 3 * n + 2, m = 2 * n + 2;
        J.block(r, 0, m, n + 1) = J2.block(n, 0, m, n + 1);
        J.block(r, 3 * n + 2, m, 1) = J2b.block(n, n, m, 1);
        J.block(r, 3 * n + 3, m, 2 * n + 1) = J2.block(n, n + 1, m, 2 * n + 1);
    }
    return g.allFinite();
}

/// Newton on the double Hopf system from (x, p1, q1, omega1, p2) on a Hopf curve and a guess of
/// the second pair's omega2 (its null vector from the smallest singular value of Delta(i omega2)).
DoubleHopfPoint locate_double_hopf(const NonlinearDDE& s, int j1, int j2, const Eigen::VectorXd& u, double omega2, const NewtonOptions& newton) {
    const int n = s.dimension();
    DoubleHopfPoint dh;
    const HopfCurveProblem pr1(s, j1, j2, q_of(u, n));
    const std::vector<double> p = pr1.values(u);
    VectorXc q2;
    try {
        const MatrixXc d = linearise(s, u.head(n), p).characteristic_matrix(cplx(0.0, omega2));
        const Eigen::JacobiSVD<MatrixXc> svd(d, Eigen::ComputeFullV);
        q2 = svd.matrixV().col(n - 1);
    } catch (const std::invalid_argument&) {
        dh.status = Status::NumericalIssue;
        dh.message = "the characteristic matrix is not defined at the guess";
        return dh;
    }
    const VectorXc q1 = q_of(u, n);
    const VectorXc q01 = q1 / q1.squaredNorm(), q02 = q2 / q2.squaredNorm();  // q0^H q = 1 at the start
    Eigen::VectorXd v(5 * n + 4);
    v << u.head(3 * n + 3), q2.real(), q2.imag(), omega2;
    Eigen::VectorXd g;
    Eigen::MatrixXd J;
    dh.status = Status::MaxIterations;
    for (int it = 0; it <= newton.max_iterations; ++it) {
        if (!double_hopf_system(s, j1, j2, q01, q02, v, g, &J)) {
            dh.status = Status::NumericalIssue;
            dh.message = "the double Hopf system is not defined at an iterate";
            break;
        }
        dh.residual = g.cwiseAbs().maxCoeff();
        const Eigen::FullPivLU<Eigen::MatrixXd> lu(J);
        if (!lu.isInvertible()) {
            dh.status = Status::NumericalIssue;
            dh.message = "the double Hopf system is singular (the two curves are tangent, or the frequencies coincide)";
            break;
        }
        const Eigen::VectorXd step = lu.solve(g);
        v -= step;
        if (step.cwiseAbs().maxCoeff() <= newton.step_tolerance * std::max(1.0, v.cwiseAbs().maxCoeff())) {
            if (double_hopf_system(s, j1, j2, q01, q02, v, g, nullptr)) dh.residual = g.cwiseAbs().maxCoeff();
            dh.status = dh.residual <= 1e-9 ? Status::Converged : Status::NumericalIssue;
            break;
        }
    }
    dh.x = v.head(n);
    dh.par = v[n];
    dh.omega1 = v[3 * n + 1];
    dh.par2 = v[3 * n + 2];
    dh.omega2 = v[5 * n + 3];
    dh.q2 = v.segment(3 * n + 3, n).cast<cplx>() + I1 * v.segment(4 * n + 3, n).cast<cplx>();
    dh.q2 /= dh.q2.norm();
    if (converged(dh.status)) {
        if (!(dh.omega1 > 0.0) || !(dh.omega2 > 0.0)) {
            dh.status = Status::NumericalIssue;
            dh.message = "a frequency converged to omega <= 0 (a Bogdanov-Takens or zero-Hopf point nearby)";
        } else if (std::abs(dh.omega1 - dh.omega2) <= 1e-6 * std::max(dh.omega1, dh.omega2)) {
            dh.resonant = true;
            dh.message = "a 1:1 resonance: the pair +-i omega is double there (the second curve is the same curve), residual " +
                         detail::format_number(dh.residual);
        } else {
            dh.message = "two pairs on the imaginary axis, residual " + detail::format_number(dh.residual);
            std::vector<double> pv = p;
            pv[static_cast<std::size_t>(j1)] = dh.par;
            pv[static_cast<std::size_t>(j2)] = dh.par2;
            if (s.has_higher_derivatives()) dh.normal_form = double_hopf_normal_form(s, dh.x, pv, dh.omega1, dh.omega2);
        }
    }
    return dh;
}

/// A root that crossed the axis between two points of a curve: its real parts at both ends and
/// its imaginary part, matched by nearness (the curve's own pair +-i omega left out).
struct Crossing {
    double re_a, re_b, im_a, im_b;
};

std::vector<Crossing> crossings(const HopfCurvePoint& a, const HopfCurvePoint& b) {
    // the roots with Im >= 0 but the curve's own root i omega (the one nearest it: a second root
    // near i omega, as next to a 1:1 resonance, stays in)
    auto upper = [](const HopfCurvePoint& p) {
        std::vector<cplx> v;
        for (const cplx z : p.roots)
            if (z.imag() >= 0.0) v.push_back(z);
        const auto own = std::min_element(v.begin(), v.end(), [&](cplx x, cplx y) {
            return std::abs(x - cplx(0.0, p.omega)) < std::abs(y - cplx(0.0, p.omega));
        });
        if (own != v.end()) v.erase(own);
        return v;
    };
    const std::vector<cplx> ra = upper(a), rb = upper(b);
    // one-to-one matching, nearest pairs first
    struct Pair {
        double d;
        std::size_t i, k;
    };
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < ra.size(); ++i)
        for (std::size_t k = 0; k < rb.size(); ++k) pairs.push_back({std::abs(ra[i] - rb[k]), i, k});
    std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.d < y.d; });
    std::vector<char> used_a(ra.size(), 0), used_b(rb.size(), 0);
    std::vector<Crossing> out;
    for (const Pair& pr : pairs) {
        if (used_a[pr.i] || used_b[pr.k]) continue;
        used_a[pr.i] = used_b[pr.k] = 1;
        const cplx za = ra[pr.i], zb = rb[pr.k];
        if ((za.real() > marginal_band(za)) != (zb.real() > marginal_band(zb))) out.push_back({za.real(), zb.real(), za.imag(), zb.imag()});
    }
    return out;
}

/// The Hopf curve through `start` (p1 = start.par) at p2 = held2.
HopfCurve trace_hopf_curve(const NonlinearDDE& s, const HopfPoint& start, double held2, const HopfCurveOptions& o) {
    const int j1 = s.parameter_index(o.branch.parameter), j2 = s.parameter_index(o.parameter2);
    check_system(s, j1, "Hopf curve");
    const int n = s.dimension();
    HopfCurve curve;
    if (!converged(start.status) || start.q.size() != n) {
        curve.status = converged(start.status) ? Status::NumericalIssue : start.status;
        curve.message = "the starting Hopf point was not located";
        return curve;
    }
    const double lo1 = std::min(o.branch.from, o.branch.to), hi1 = std::max(o.branch.from, o.branch.to);
    const double lo2 = std::min(o.from2, o.to2), hi2 = std::max(o.from2, o.to2);
    if (!(held2 >= lo2 && held2 <= hi2))
        throw std::invalid_argument(o.parameter2 + " = " + detail::format_number(held2) + " (its value in the system): expected a value in [" +
                                    detail::format_number(lo2) + ", " + detail::format_number(hi2) + "]");

    const int N = 3 * n + 3;
    ContinuationOptions co = detail::curve_options(o.continuation, N, n, lo1, hi1, 3 * n + 2, lo2, hi2, start.x);
    const int budget = o.continuation.max_points;

    VectorXc q = start.q / start.q.norm();
    Eigen::VectorXd u0(N);
    u0 << start.x, start.par, q.real(), q.imag(), start.omega, held2;

    long traced = 1;  // the start
    if (o.progress)
        co.on_point = [&](const Eigen::VectorXd& u) { o.progress(++traced, 2L * budget - 1, u[n]); };
    // between segments the normalisation is renewed: q / |q| becomes both q and q0
    auto renew = [&](Eigen::VectorXd& u, Eigen::VectorXd& t) {
        const double len = q_of(u, n).norm();
        u.segment(n + 1, 2 * n) /= len;
        t.segment(n + 1, 2 * n) /= len;
        return std::make_shared<HopfCurveProblem>(s, j1, j2, q_of(u, n));
    };
    const detail::TracedCurve<HopfCurveProblem> traced_curve = detail::trace_both_ways(
        std::make_shared<HopfCurveProblem>(s, j1, j2, q), u0, co, o.segment, budget, renew,
        "no tangent at the starting Hopf point (the Hopf system is singular there)");
    const ContinuationStop* stops = traced_curve.stops;
    curve.stop_forward = stops[0];
    curve.stop_backward = stops[1];
    const auto& all = traced_curve.samples;

    bool coefficients_ok = true;
    for (const auto& sm : all) {
        HopfCurvePoint pt;
        pt.par = sm.u[n];
        pt.par2 = sm.u[3 * n + 2];
        pt.omega = sm.u[3 * n + 1];
        pt.x = sm.u.head(n);
        pt.coefficients = coefficients_at(s, j1, *sm.problem, sm.u, o.coefficients);
        coefficients_ok = coefficients_ok && converged(pt.coefficients.status);
        curve.points.push_back(std::move(pt));
    }
    bool genh_ok = true;
    for (std::size_t k = 0; k + 1 < all.size(); ++k) {
        const HopfCoefficients& a = curve.points[k].coefficients;
        const HopfCoefficients& b = curve.points[k + 1].coefficients;
        if (!converged(a.status) || !converged(b.status) || a.criticality == Criticality::Degenerate || b.criticality == Criticality::Degenerate ||
            (a.l1 < 0.0) == (b.l1 < 0.0))
            continue;
        // both samples satisfy the later sample's normalisation up to a scale of q: use the later one's
        const HopfCurveProblem& pr = *all[k + 1].problem;
        Eigen::VectorXd ua = all[k].u;
        const VectorXc qa = q_of(ua, n);
        const cplx sc = pr.q0().dot(qa);
        const VectorXc qn = qa / sc;
        ua.segment(n + 1, n) = qn.real();
        ua.segment(2 * n + 1, n) = qn.imag();
        GeneralisedHopfPoint g = locate_generalised(s, j1, pr, ua, all[k + 1].u, a.l1, b.l1, o);
        g.after = static_cast<int>(k);
        // where a real root crosses 0 in the same step (a zero-Hopf point, located below) L1 has
        // a pole (its centre-manifold term Delta(0)^-1 B[phi, conj phi] blows up) and changes sign
        // through it: a search that fails or ends where |L1| is not below both ends found the
        // pole, not a generalised Hopf point (on DDE-BIFTOOL's two-layer neuron demo L1 reaches
        // 740 there)
        double da = 0.0, db = 0.0;
        const bool real_crossing = scaled_det0(s, ua.head(n), pr.values(ua), da) && scaled_det0(s, all[k + 1].u.head(n), pr.values(all[k + 1].u), db) &&
                                   (da < 0.0) != (db < 0.0);
        if (real_crossing && (!converged(g.status) || !(std::abs(g.l1) < std::min(std::abs(a.l1), std::abs(b.l1))))) continue;
        genh_ok = genh_ok && converged(g.status);
        curve.generalised.push_back(std::move(g));
    }
    // a degenerate sample is itself a generalised Hopf point (to the tolerance)
    for (std::size_t k = 0; k < curve.points.size(); ++k) {
        const HopfCurvePoint& p = curve.points[k];
        if (!converged(p.coefficients.status) || p.coefficients.criticality != Criticality::Degenerate || p.coefficients.l1_scale == 0.0) continue;
        GeneralisedHopfPoint g;
        g.par = p.par, g.par2 = p.par2, g.omega = p.omega, g.x = p.x, g.status = Status::Converged;
        g.l1 = p.coefficients.l1, g.residual = p.coefficients.residual, g.after = static_cast<int>(k);
        curve.generalised.push_back(std::move(g));
    }
    std::sort(curve.generalised.begin(), curve.generalised.end(),
              [](const GeneralisedHopfPoint& a, const GeneralisedHopfPoint& b) { return a.after < b.after; });

    // codimension two: the roots at every point; where the count right of the axis changes, the
    // roots that crossed (a pair: double Hopf, a real root: zero-Hopf) must explain the change
    bool codim2_ok = true;
    std::string codim2_message;
    if (o.codimension_two) {
        detail::RootsAlong ra = detail::roots_along(s, all, o.branch.roots);
        for (std::size_t k = 0; k < all.size(); ++k) {
            if (!converged(ra.roots[k].status)) continue;
            curve.points[k].roots = std::move(ra.roots[k].roots);
            curve.points[k].unstable = ra.roots[k].unstable;
        }
        if (ra.failed > 0) {
            codim2_ok = false;
            codim2_message = ra.message();
        }
        for (std::size_t k = 0; k + 1 < all.size(); ++k) {
            HopfCurvePoint &a = curve.points[k], &b = curve.points[k + 1];
            if (a.unstable < 0 || b.unstable < 0 || a.unstable == b.unstable) continue;
            std::vector<Crossing> cs;
            int explained = 0;
            // the root that crossed may lie beyond the strip certified at one end (just left of
            // the axis): more roots at both ends until the crossings explain the change
            for (int more = 0; more < 3; ++more) {
                cs = crossings(a, b);
                explained = 0;
                for (const Crossing& c : cs) explained += (c.re_b > c.re_a ? 1 : -1) * (std::abs(c.im_a) + std::abs(c.im_b) <= 1e-8 ? 1 : 2);
                if (explained == b.unstable - a.unstable) break;
                for (std::size_t e : {k, k + 1}) {
                    HopfCurvePoint& pt = curve.points[e];
                    RootOptions ro = o.branch.roots;
                    ro.count = 2 * static_cast<int>(pt.roots.size()) + 8;
                    const EquilibriumRoots er = equilibrium_roots(s, pt.x, all[e].problem->values(all[e].u), ro);
                    if (converged(er.status) && er.unstable == pt.unstable) pt.roots = er.roots;
                }
            }
            if (explained != b.unstable - a.unstable) {
                codim2_ok = false;
                codim2_message = "between points " + std::to_string(k) + " and " + std::to_string(k + 1) + " the count of roots right of the axis changes by " +
                                 std::to_string(b.unstable - a.unstable) + ", the crossings matched explain " + std::to_string(explained);
            }
            // the two samples in the later sample's normalisation
            const HopfCurveProblem& pr = *all[k + 1].problem;
            Eigen::VectorXd ua = all[k].u;
            const VectorXc qa = q_of(ua, n);
            const VectorXc qn = qa / pr.q0().dot(qa);
            ua.segment(n + 1, n) = qn.real();
            ua.segment(2 * n + 1, n) = qn.imag();
            const Eigen::VectorXd& ub = all[k + 1].u;
            for (const Crossing& c : cs) {
                if (std::abs(c.im_a) + std::abs(c.im_b) <= 1e-8) {
                    ZeroHopfPoint zh = locate_zero_hopf(s, pr, ua, ub, o);
                    zh.after = static_cast<int>(k);
                    if (!converged(zh.status)) codim2_ok = false, codim2_message = "a zero-Hopf point was not located";
                    curve.zero_hopf.push_back(std::move(zh));
                    continue;
                }
                const double frac = std::clamp(c.re_a / (c.re_a - c.re_b), 0.0, 1.0);
                Eigen::VectorXd u = ua + frac * (ub - ua);
                const Eigen::VectorXd dir = (ub - ua).normalized();
                const CorrectorResult cr = correct(pr, u, dir, dir.dot(u), o.continuation.newton);
                if (!converged(cr.status)) u = ua + frac * (ub - ua);
                DoubleHopfPoint dh = locate_double_hopf(s, j1, j2, u, c.im_a + frac * (c.im_b - c.im_a), o.branch.special);
                dh.after = static_cast<int>(k);
                if (!converged(dh.status)) codim2_ok = false, codim2_message = "a double Hopf point was not located: " + dh.message;
                curve.double_hopf.push_back(std::move(dh));
            }
        }
    }

    if (!traced_curve.ended_well()) {
        curve.status = traced_curve.end_status();
    } else if (!coefficients_ok) {
        curve.status = Status::NumericalIssue;
    } else if (!genh_ok) {
        curve.status = Status::MaxIterations;
    }
    curve.message = std::to_string(curve.points.size()) + " points, " + std::to_string(curve.generalised.size()) + " generalised Hopf, " +
                    std::to_string(curve.double_hopf.size()) + " double Hopf, " + std::to_string(curve.zero_hopf.size()) +
                    " zero-Hopf points; " + traced_curve.end_text();
    // a curve that leaves the domain as omega falls to 0 (its last point's omega below a tenth of
    // the largest on it) ends at a Bogdanov-Takens point: located from its last point
    double wmax = 0.0;
    for (const HopfCurvePoint& p : curve.points) wmax = std::max(wmax, p.omega);
    for (int d = 0; d < 2; ++d) {
        if (stops[d] != ContinuationStop::LeftDomain || curve.points.empty()) continue;
        const HopfCurvePoint& end = d == 0 ? curve.points.back() : curve.points.front();
        if (!(end.omega <= 0.1 * wmax)) continue;  // (the domain is omega > 0: a curve leaves it only there)
        HopfCurveBogdanovTakens bt = locate_bogdanov_takens(s, j1, s.parameter_index(o.parameter2), end);
        bt.forward = d == 0;
        curve.message += "; at its " + std::string(d == 0 ? "forward" : "backward") + " end (omega " + detail::format_number(end.omega) +
                         " -> 0) a Bogdanov-Takens point" +
                         (converged(bt.status) ? " (located, residual " + detail::format_number(bt.residual) + ")" : " not located: " + bt.message);
        curve.bogdanov_takens.push_back(std::move(bt));
    }
    if (!coefficients_ok) curve.message += "; L1 not computed at some points";
    if (!genh_ok) curve.message += "; a generalised Hopf point was not located";
    if (!codim2_ok) {
        if (converged(curve.status)) curve.status = Status::NumericalIssue;
        curve.message += "; " + codim2_message;
    }
    return curve;
}

}  // namespace

HopfCurve hopf_curve(const NonlinearDDE& s, const HopfPoint& start, const HopfCurveOptions& o) {
    std::string why;
    if (!o.is_valid(&why)) throw std::invalid_argument("Hopf curve options: " + why);
    const int j2 = s.parameter_index(o.parameter2);
    return trace_hopf_curve(s, start, s.parameter_values()[static_cast<std::size_t>(j2)], o);
}

HopfCurves hopf_curves(const NonlinearDDE& s, const Eigen::VectorXd& guess, const HopfCurveOptions& o) {
    std::string why;
    if (!o.is_valid(&why)) throw std::invalid_argument("Hopf curve options: " + why);
    const double held2 = o.held_second(s);  // an unknown parameter2 is refused here
    HopfCurves r;
    r.start = hopf_points(s, guess, o.branch, o.coefficients);
    r.status = r.start.branch.status;
    const double w1 = std::abs(o.branch.to - o.branch.from), w2 = std::abs(o.to2 - o.from2);
    // the index of the traced curve through (p1, p2, omega) (distance to its polyline in the scaled box), or -1
    auto on_curve = [&](double p1, double p2, double omega) {
        const Eigen::Vector3d ph(p1 / w1, p2 / w2, omega);
        for (std::size_t i = 0; i < r.curves.size(); ++i) {
            const HopfCurve& c = r.curves[i];
            for (std::size_t k = 0; k + 1 < c.points.size(); ++k) {
                const HopfCurvePoint &a = c.points[k], &b = c.points[k + 1];
                const Eigen::Vector3d pa(a.par / w1, a.par2 / w2, a.omega), pb(b.par / w1, b.par2 / w2, b.omega);
                const Eigen::Vector3d ab = pb - pa;
                const double t = ab.squaredNorm() > 0.0 ? std::clamp((ph - pa).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
                if ((pa + t * ab - ph).norm() <= 1e-3) return static_cast<int>(i);
            }
        }
        return -1;
    };
    for (std::size_t i = 0; i < r.start.branch.hopf.size(); ++i) {
        const HopfPoint& h = r.start.branch.hopf[i];
        if (!converged(h.status) || on_curve(h.par, held2, h.omega) >= 0) continue;  // on a curve already traced
        HopfCurve c = trace_hopf_curve(s, h, held2, o);
        c.start = static_cast<int>(i);
        if (converged(r.status) && !converged(c.status)) r.status = c.status;
        r.curves.push_back(std::move(c));
    }
    // the second curve through every double Hopf point, when no traced curve passes through it
    // (started from the point's second pair: p1 free at its p2), until every such point has one
    for (std::size_t i = 0; i < r.curves.size() && r.curves.size() < 64; ++i) {
        for (std::size_t k = 0; k < r.curves[i].double_hopf.size(); ++k) {
            const DoubleHopfPoint dh = r.curves[i].double_hopf[k];
            if (!converged(dh.status) || dh.resonant) continue;
            int other = on_curve(dh.par, dh.par2, dh.omega2);
            if (other < 0) {
                HopfPoint h;
                h.par = dh.par, h.x = dh.x, h.omega = dh.omega2, h.q = dh.q2, h.status = Status::Converged, h.residual = dh.residual;
                HopfCurve c = trace_hopf_curve(s, h, dh.par2, o);
                c.start = -1;
                if (converged(r.status) && !converged(c.status)) r.status = c.status;
                r.curves.push_back(std::move(c));
                other = static_cast<int>(r.curves.size()) - 1;
            }
            r.curves[i].double_hopf[k].other_curve = other;
        }
    }
    r.message = r.start.branch.message + "; " + std::to_string(r.curves.size()) + " Hopf curve(s)";
    for (const HopfCurve& c : r.curves)
        if (!converged(c.status)) r.message += "; a curve: " + c.message;
    return r;
}

}  // namespace ddemap
