#include "ddemap/analysis/bifurcation/normal_forms.hpp"

#include "analysis/bifurcation/internal/multilinear.hpp"

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

namespace ddemap {

namespace {

/// Delta and its first three derivatives at lambda = 0 (the header's formulas).
struct DeltaAtZero {
    Eigen::MatrixXd d0, d1, d2, d3;
    Eigen::VectorXd stacked;
    std::vector<double> tau;
};

DeltaAtZero delta_at_zero(const NonlinearDDE& s, const Eigen::VectorXd& x, const std::vector<double>& p) {
    if (!s.has_higher_derivatives()) throw std::invalid_argument("normal form: the system has no second and third derivatives");
    const int n = s.dimension();
    if (x.size() != n) throw std::invalid_argument("normal form: expected an equilibrium of " + std::to_string(n) + " entries");
    DeltaAtZero d;
    d.stacked = s.stack_constant(x);
    d.tau = s.delays(p);
    const std::vector<Eigen::MatrixXd> a = s.jacobians(d.stacked, p);
    d.d0 = -a[0];
    d.d1 = Eigen::MatrixXd::Identity(n, n);
    d.d2 = Eigen::MatrixXd::Zero(n, n);
    d.d3 = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t k = 1; k < a.size(); ++k) {
        const double t = d.tau[k - 1];
        d.d0 -= a[k];
        d.d1 += t * a[k];
        d.d2 -= t * t * a[k];
        d.d3 += t * t * t * a[k];
    }
    return d;
}

/// The unit null vector of m (its smallest right singular vector), the largest component
/// positive; `residual` sigma_min / sigma_max.
Eigen::VectorXd null_vector(const Eigen::MatrixXd& m, double& residual) {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(m, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const Eigen::Index last = sv.size() - 1;
    residual = sv[0] > 0.0 ? sv[last] / sv[0] : 0.0;
    Eigen::VectorXd v = svd.matrixV().col(last);
    Eigen::Index i = 0;
    v.cwiseAbs().maxCoeff(&i);
    if (v[i] < 0.0) v = -v;
    return v;
}

/// [m b; c^T 0] [y; s] = [r; 0] (the bordered system of a matrix with a one-dimensional kernel);
/// false when it is singular or the solution not finite.
bool bordered_solve(const Eigen::MatrixXd& m, const Eigen::VectorXd& b, const Eigen::VectorXd& c, const Eigen::VectorXd& r, Eigen::VectorXd& y) {
    const Eigen::Index n = m.rows();
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n + 1, n + 1);
    k.topLeftCorner(n, n) = m;
    k.topRightCorner(n, 1) = b;
    k.bottomLeftCorner(1, n) = c.transpose();
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 1);
    rhs.head(n) = r;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(k);
    if (lu.rank() < n + 1) return false;
    y = lu.solve(rhs).head(n);
    return y.allFinite();
}

/// The constant function v stacked over the delays: (v, v, ..., v).
Eigen::VectorXd stack(const NonlinearDDE& s, const Eigen::VectorXd& v) { return s.stack_constant(v); }

}  // namespace

BogdanovTakensNormalForm bogdanov_takens_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p) {
    const DeltaAtZero d = delta_at_zero(system, x, p);
    const int n = system.dimension();
    BogdanovTakensNormalForm r;
    double left = 0.0;
    r.q0 = null_vector(d.d0, r.kernel_residual);
    Eigen::VectorXd p1 = null_vector(d.d0.transpose(), left);
    r.double_root_residual = std::abs(p1.dot(d.d1 * r.q0)) / std::max(d.d1.norm(), 1e-300);
    Eigen::VectorXd q1, p0;
    // q1: Delta(0) q1 = -Delta'(0) q0, q0 . q1 = 0; p0: Delta(0)^T p0 = -Delta'(0)^T p1, p1 . p0 = 0
    // (a multiple of p1 is fixed by the normalisation below). The borders lie outside the ranges
    // (range Delta(0) = p1-perp, range Delta(0)^T = q0-perp), the rows do not vanish on the kernels.
    if (!bordered_solve(d.d0, p1, r.q0, -(d.d1 * r.q0), q1) || !bordered_solve(d.d0.transpose(), r.q0, p1, -(d.d1.transpose() * p1), p0)) {
        r.message = "the Jordan chain at 0 could not be formed (the bordered systems are singular: the kernel of Delta(0) is not one-dimensional)";
        return r;
    }
    const double den = p1.dot(d.d1 * q1) + 0.5 * p1.dot(d.d2 * r.q0);
    if (!(std::abs(den) > 0.0)) {
        r.message = "the adjoint chain cannot be normalised (p1 Delta' q1 + p1 Delta'' q0 / 2 = 0)";
        return r;
    }
    const double beta = -(p0.dot(d.d1 * q1) + 0.5 * p0.dot(d.d2 * r.q0) + 0.5 * p1.dot(d.d2 * q1) + p1.dot(d.d3 * r.q0) / 6.0) / den;
    p0 += beta * p1;
    const double alpha = p0.dot(d.d1 * r.q0) + 0.5 * p1.dot(d.d2 * r.q0);
    p0 /= alpha;
    p1 /= alpha;
    r.q1 = q1;
    r.p0 = p0;
    r.p1 = p1;
    // phi0 = q0 at every delay; phi1(-tau_k) = q1 - tau_k q0
    const Eigen::VectorXd phi0 = stack(system, r.q0);
    Eigen::VectorXd phi1 = stack(system, q1);
    for (std::size_t k = 0; k < d.tau.size(); ++k) phi1.segment(static_cast<Eigen::Index>(k + 1) * n, n) -= d.tau[k] * r.q0;
    const Eigen::VectorXd b00 = system.second_derivative(d.stacked, p, phi0, phi0);
    const Eigen::VectorXd b01 = system.second_derivative(d.stacked, p, phi0, phi1);
    r.a = 0.5 * p1.dot(b00);
    r.b = p0.dot(b00) + p1.dot(b01);
    if (!std::isfinite(r.a) || !std::isfinite(r.b)) {
        r.message = "a coefficient is not finite";
        return r;
    }
    r.status = Status::Converged;
    r.message = "Bogdanov-Takens normal form w0' = w1, w1' = a w0^2 + b w0 w1 (DDE-BIFTOOL's nmfm_bt normalisation)";
    return r;
}

CuspNormalForm cusp_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p) {
    const DeltaAtZero d = delta_at_zero(system, x, p);
    CuspNormalForm r;
    double left = 0.0;
    r.q = null_vector(d.d0, r.kernel_residual);
    Eigen::VectorXd pv = null_vector(d.d0.transpose(), left);
    const double ainv = pv.dot(d.d1 * r.q);
    if (!(std::abs(ainv) > 0.0)) {
        r.message = "p Delta'(0) q = 0: the root at 0 is not simple (a Bogdanov-Takens point, not a cusp)";
        return r;
    }
    pv /= ainv;
    r.p = pv;
    const Eigen::VectorXd phi = stack(system, r.q);
    const Eigen::VectorXd b2 = system.second_derivative(d.stacked, p, phi, phi);
    Eigen::VectorXd y;
    if (!bordered_solve(d.d0, r.q, pv, b2, y)) {
        r.message = "the bordered system [Delta(0) q; p 0] is singular";
        return r;
    }
    // the centre manifold's quadratic term: Delta(0) h2 = B[phi, phi] (A h2 = -B with A = -Delta(0)
    // the linear part, as in Kuznetsov's ODE formulas and DDE-BIFTOOL's nmfm_zeho), projected so
    // that p Delta'(0) h2 = 0
    const Eigen::VectorXd h2 = y - pv.dot(d.d1 * y) * r.q;
    const Eigen::VectorXd sh2 = stack(system, h2);
    r.b = 0.5 * pv.dot(b2);
    r.c = pv.dot(3.0 * system.second_derivative(d.stacked, p, phi, sh2) + system.third_derivative(d.stacked, p, phi, phi, phi)) / 6.0;
    if (!std::isfinite(r.b) || !std::isfinite(r.c)) {
        r.message = "a coefficient is not finite";
        return r;
    }
    r.status = Status::Converged;
    r.message = "cusp normal form w' = b w^2 + c w^3 (DDE-BIFTOOL's nmfm_cusp normalisation; b = 0 at the cusp)";
    return r;
}

}  // namespace ddemap

namespace ddemap {

namespace {

using namespace detail::multilinear;

/// A history function sum_k v_k theta^{t_k} e^{lambda_k theta} (t_k = 0 or 1), the form of the
/// eigenfunctions and the centre manifold's coefficients.
struct History {
    struct Term {
        VectorXc v;
        cplx lambda;
        int t = 0;
    };
    std::vector<Term> terms;
    /// (h(0), h(-tau_1), ...) stacked
    VectorXc stacked(const std::vector<double>& tau0) const {
        const Eigen::Index n = terms.empty() ? 0 : terms.front().v.size();
        VectorXc r = VectorXc::Zero(n * static_cast<Eigen::Index>(tau0.size()));
        for (std::size_t k = 0; k < tau0.size(); ++k)
            for (const Term& term : terms) {
                const double theta = -tau0[k];
                r.segment(static_cast<Eigen::Index>(k) * n, n) += term.v * (std::pow(theta, term.t) * std::exp(term.lambda * theta));
            }
        return r;
    }
    History conj() const {
        History h = *this;
        for (Term& t : h.terms) {
            t.v = t.v.conjugate();
            t.lambda = std::conj(t.lambda);
        }
        return h;
    }
};

/// Delta''(lambda) = -sum_k tau_k^2 A_k e^{-lambda tau_k}.
MatrixXc delta2(const std::vector<Eigen::MatrixXd>& a, const std::vector<double>& tau0, cplx lambda) {
    const Eigen::Index n = a[0].rows();
    MatrixXc m = MatrixXc::Zero(n, n);
    for (std::size_t k = 0; k < a.size(); ++k) m -= tau0[k] * tau0[k] * std::exp(-lambda * tau0[k]) * a[k].cast<cplx>();
    return m;
}

/// The unit null vector of m (complex), its largest component real and positive; `residual`
/// sigma_min / sigma_max.
VectorXc null_vector_c(const MatrixXc& m, double& residual) {
    Eigen::JacobiSVD<MatrixXc> svd(m, Eigen::ComputeFullV);
    const Eigen::VectorXd& sv = svd.singularValues();
    const Eigen::Index last = sv.size() - 1;
    residual = sv[0] > 0.0 ? sv[last] / sv[0] : 0.0;
    VectorXc v = svd.matrixV().col(last);
    Eigen::Index i = 0;
    v.cwiseAbs().maxCoeff(&i);
    return v * (std::abs(v[i]) / v[i]);
}

}  // namespace

ZeroHopfNormalForm zero_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, double omega) {
    if (!system.has_higher_derivatives()) throw std::invalid_argument("normal form: the system has no second and third derivatives");
    const int n = system.dimension();
    if (x.size() != n) throw std::invalid_argument("normal form: expected an equilibrium of " + std::to_string(n) + " entries");
    if (!(std::isfinite(omega) && omega > 0.0)) throw std::invalid_argument("zero-Hopf normal form: omega = " + std::to_string(omega) + ": expected a value > 0");
    ZeroHopfNormalForm r;
    const Eigen::VectorXd u = system.stack_constant(x);
    const std::vector<Eigen::MatrixXd> a = system.jacobians(u, p);
    std::vector<double> tau0{0.0};
    for (const double t : system.delays(p)) tau0.push_back(t);
    const cplx l0(0.0, 0.0), l1(0.0, omega);
    const MatrixXc D0 = delta(a, tau0, l0), D1 = delta(a, tau0, l1);
    const MatrixXc dD0 = delta(a, tau0, l0, true), dD1 = delta(a, tau0, l1, true);

    double left = 0.0;
    VectorXc q0 = null_vector_c(D0, r.kernel_residual), q1 = null_vector_c(D1, r.hopf_residual);
    q0 = q0.real().cast<cplx>();  // Delta(0) is real: its null vector too (the phase made it so)
    q0 /= q0.norm();
    VectorXc p0 = null_vector_c(D0.transpose(), left).conjugate(), p1 = null_vector_c(D1.transpose(), left);
    p0 = p0.real().cast<cplx>();
    const cplx n0 = p0.transpose() * dD0 * q0, n1 = p1.transpose() * dD1 * q1;
    if (!(std::abs(n0) > 0.0) || !(std::abs(n1) > 0.0)) {
        r.message = "the eigenvectors cannot be normalised (p Delta'(lambda) q = 0: the root is not simple)";
        return r;
    }
    p0 /= n0;
    p1 /= n1;

    // the bordered inverse (the header's binv)
    bool ok = true;
    auto binv = [&](cplx lambda, const VectorXc& q, const VectorXc& pv, const VectorXc& zeta, cplx kappa) {
        const MatrixXc D = delta(a, tau0, lambda), dD = delta(a, tau0, lambda, true), ddD = delta2(a, tau0, lambda);
        MatrixXc k = MatrixXc::Zero(n + 1, n + 1);
        k.topLeftCorner(n, n) = D;
        k.topRightCorner(n, 1) = q;
        k.bottomLeftCorner(1, n) = pv.transpose();
        VectorXc rhs = VectorXc::Zero(n + 1);
        rhs.head(n) = zeta + kappa * (dD * q);
        const Eigen::FullPivLU<MatrixXc> lu(k);
        if (lu.rank() < n + 1) ok = false;
        const VectorXc xi = lu.solve(rhs).head(n);
        const cplx gamma = -cplx(pv.transpose() * dD * xi) + 0.5 * kappa * cplx(pv.transpose() * ddD * q);
        History h;
        h.terms.push_back({xi + gamma * q, lambda, 0});
        h.terms.push_back({-kappa * q, lambda, 1});
        return h;
    };
    auto B = [&](const History& f, const History& g) { return b_complex(system, u, p, f.stacked(tau0), g.stacked(tau0)); };
    auto C = [&](const History& f, const History& g, const History& h) { return c_complex(system, u, p, f.stacked(tau0), g.stacked(tau0), h.stacked(tau0)); };
    auto dot = [](const VectorXc& pv, const VectorXc& v) { return cplx(pv.transpose() * v); };

    History phi0, phi1;
    phi0.terms.push_back({q0, l0, 0});
    phi1.terms.push_back({q1, l1, 0});
    const History phi1b = phi1.conj();
    const VectorXc B00 = B(phi0, phi0), B01 = B(phi0, phi1);
    const VectorXc B11b = B(phi1, phi1b).real().cast<cplx>();  // real up to rounding
    const cplx g200 = 0.5 * dot(p0, B00), g110 = dot(p1, B01), g011 = dot(p0, B11b);
    const History h200 = binv(l0, q0, p0, B00, -dot(p0, B00));
    const History h011 = binv(l0, q0, p0, B11b, -dot(p0, B11b));
    const History h110 = binv(l1, q1, p1, B01, -dot(p1, B01));
    const History h110b = h110.conj();
    History h020;
    {
        const Eigen::FullPivLU<MatrixXc> lu(delta(a, tau0, 2.0 * l1));
        if (lu.rank() < n) ok = false;
        h020.terms.push_back({lu.solve(B(phi1, phi1)), 2.0 * l1, 0});
    }
    if (!ok) {
        r.message = "a bordered system of the centre manifold is singular (a kernel is not one-dimensional, or 2 i omega is a root too)";
        return r;
    }
    const cplx g300 = dot(p0, 3.0 * B(phi0, h200) + C(phi0, phi0, phi0)) / 6.0;
    const cplx g111 = dot(p0, B(phi0, h011) + B(phi1b, h110) + B(phi1, h110b) + C(phi0, phi1, phi1b));
    const cplx g210 = 0.5 * dot(p1, B(phi1, h200) + 2.0 * B(phi0, h110) + C(phi0, phi0, phi1));
    const cplx g021 = 0.5 * dot(p1, B(phi1b, h020) + 2.0 * B(phi1, h011) + C(phi1, phi1, phi1b));

    r.g200 = g200.real();
    r.g011 = g011.real();
    r.g300 = g300.real();
    r.g111 = g111.real();
    r.g110 = g110;
    r.g210 = g210;
    r.g021 = g021;
    r.b = r.g200;
    r.c = r.g011;
    r.d = g110 - l1 * r.g300 / r.g200;
    r.e = (g210 + g110 * (g021.real() / r.g011 - 1.5 * r.g300 / r.g200 + r.g111 / (2.0 * r.g011)) - g021 * r.g200 / r.g011).real();
    r.s = r.b * r.c + 0.0;  // no -0
    r.theta = g110.real() / r.g200;
    r.q0 = q0.real();
    r.p0 = p0.real();
    r.q1 = q1;
    r.p1 = p1;
    const double all[] = {r.g200, r.g011, r.g300, r.g111, std::abs(g110), std::abs(g210), std::abs(g021)};
    for (const double v : all)
        if (!std::isfinite(v)) {
            r.message = "a coefficient g is not finite";
            return r;
        }
    // a degenerate point (g200 = 0 or g011 = 0, e.g. a system whose fold variable does not feel
    // the oscillation at second order): the g are the result; what divides by zero is NaN (null)
    if (!(r.g200 != 0.0)) r.d = cplx(std::numeric_limits<double>::quiet_NaN(), 0.0), r.theta = std::numeric_limits<double>::quiet_NaN();
    if (!(r.g200 != 0.0) || !(r.g011 != 0.0)) r.e = std::numeric_limits<double>::quiet_NaN();
    r.status = Status::Converged;
    r.message = std::isfinite(r.e) ? "s = " + std::to_string(r.s) + ", theta = " + std::to_string(r.theta)
                                   : std::string("degenerate: ") + (r.g200 != 0.0 ? "g011 = 0 (e undefined)" : "g200 = 0 (d, e, theta undefined)");
    return r;
}

}  // namespace ddemap
