#include "ddemap/analysis/bifurcation/normal_forms.hpp"

#include "analysis/bifurcation/internal/multilinear.hpp"

#include <cmath>
#include <initializer_list>
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

/// The pieces every normal form of this file is built from, at one equilibrium: the
/// characteristic matrix and its derivatives, the eigenvector pairs of a root, the multilinear
/// forms on history functions and the inverses that give the centre manifold's coefficients.
class CentreForms {
public:
    CentreForms(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, int order) : m_s(system), m_p(p) {
        if (!system.has_higher_derivatives())
            throw std::invalid_argument("normal form: the system has no derivatives of order 2 to " + std::to_string(order));
        const int n = system.dimension();
        if (x.size() != n) throw std::invalid_argument("normal form: expected an equilibrium of " + std::to_string(n) + " entries");
        m_u = system.stack_constant(x);
        m_a = system.jacobians(m_u, p);
        m_tau0.push_back(0.0);
        for (const double t : system.delays(p)) m_tau0.push_back(t);
    }
    int n() const { return m_s.dimension(); }
    MatrixXc D(cplx lambda) const { return delta(m_a, m_tau0, lambda); }
    MatrixXc dD(cplx lambda) const { return delta(m_a, m_tau0, lambda, true); }
    MatrixXc ddD(cplx lambda) const { return delta2(m_a, m_tau0, lambda); }

    /// Delta(lambda) q = 0, |q| = 1; p Delta(lambda) = 0 (a row, no conjugation) with
    /// p Delta'(lambda) q = 1; false when the root is not simple (the normalisation vanishes).
    bool pair(cplx lambda, VectorXc& q, VectorXc& p, double& residual) const {
        double left = 0.0;
        q = null_vector_c(D(lambda), residual);
        p = null_vector_c(D(lambda).transpose(), left);
        if (lambda.imag() == 0.0) {  // a real root: real vectors (the phase made them so)
            q = q.real().cast<cplx>();
            q /= q.norm();
            p = p.real().cast<cplx>();
        }
        const cplx norm = p.transpose() * dD(lambda) * q;
        if (!(std::abs(norm) > 0.0)) return false;
        p /= norm;
        return true;
    }

    /// The history v e^{lambda theta}.
    static History exp(const VectorXc& v, cplx lambda) { return History{{{v, lambda, 0}}}; }
    /// theta -> e^{lambda theta} Delta(lambda)^-1 rhs (lambda not a root); `ok` false when singular.
    History solve(cplx lambda, const VectorXc& rhs) {
        const Eigen::FullPivLU<MatrixXc> lu(D(lambda));
        if (lu.rank() < n()) m_ok = false;
        return exp(lu.solve(rhs), lambda);
    }
    /// The bordered inverse binv(lambda, q, p, zeta, kappa) of normal_forms.hpp (lambda a simple root).
    History binv(cplx lambda, const VectorXc& q, const VectorXc& pv, const VectorXc& zeta, cplx kappa) {
        const int m = n();
        MatrixXc k = MatrixXc::Zero(m + 1, m + 1);
        k.topLeftCorner(m, m) = D(lambda);
        k.topRightCorner(m, 1) = q;
        k.bottomLeftCorner(1, m) = pv.transpose();
        VectorXc rhs = VectorXc::Zero(m + 1);
        rhs.head(m) = zeta + kappa * (dD(lambda) * q);
        const Eigen::FullPivLU<MatrixXc> lu(k);
        if (lu.rank() < m + 1) m_ok = false;
        const VectorXc xi = lu.solve(rhs).head(m);
        const cplx gamma = -cplx(pv.transpose() * dD(lambda) * xi) + 0.5 * kappa * cplx(pv.transpose() * ddD(lambda) * q);
        History h;
        h.terms.push_back({xi + gamma * q, lambda, 0});
        h.terms.push_back({-kappa * q, lambda, 1});
        return h;
    }
    /// False when an inverse above met a singular matrix.
    bool ok() const { return m_ok; }

    VectorXc B(const History& f, const History& g) const { return form<2>({&f, &g}); }
    VectorXc C(const History& f, const History& g, const History& h) const { return form<3>({&f, &g, &h}); }
    VectorXc D4(const History& f, const History& g, const History& h, const History& k) const { return form<4>({&f, &g, &h, &k}); }
    VectorXc E5(const History& f, const History& g, const History& h, const History& k, const History& l) const {
        return form<5>({&f, &g, &h, &k, &l});
    }
    static cplx dot(const VectorXc& pv, const VectorXc& v) { return cplx(pv.transpose() * v); }

private:
    template <int K>
    VectorXc form(std::initializer_list<const History*> h) const {
        VectorXc stacked[K];
        const VectorXc* ptr[K];
        int k = 0;
        for (const History* f : h) {
            stacked[k] = f->stacked(m_tau0);
            ptr[k] = &stacked[k];
            ++k;
        }
        return dk_complex<K>(m_s, m_u, m_p, ptr);
    }
    const NonlinearDDE& m_s;
    std::vector<double> m_p;
    Eigen::VectorXd m_u;
    std::vector<Eigen::MatrixXd> m_a;
    std::vector<double> m_tau0;
    bool m_ok = true;
};

}  // namespace

ZeroHopfNormalForm zero_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, double omega) {
    if (!(std::isfinite(omega) && omega > 0.0)) throw std::invalid_argument("zero-Hopf normal form: omega = " + std::to_string(omega) + ": expected a value > 0");
    CentreForms f(system, x, p, 3);
    ZeroHopfNormalForm r;
    const cplx l0(0.0, 0.0), l1(0.0, omega);
    VectorXc q0, p0, q1, p1;
    if (!f.pair(l0, q0, p0, r.kernel_residual) || !f.pair(l1, q1, p1, r.hopf_residual)) {
        r.message = "the eigenvectors cannot be normalised (p Delta'(lambda) q = 0: the root is not simple)";
        return r;
    }
    auto B = [&](const History& a, const History& b) { return f.B(a, b); };
    auto C = [&](const History& a, const History& b, const History& c) { return f.C(a, b, c); };
    auto dot = CentreForms::dot;
    const History phi0 = CentreForms::exp(q0, l0), phi1 = CentreForms::exp(q1, l1);
    const History phi1b = phi1.conj();
    const VectorXc B00 = B(phi0, phi0), B01 = B(phi0, phi1);
    const VectorXc B11b = B(phi1, phi1b).real().cast<cplx>();  // real up to rounding
    const cplx g200 = 0.5 * dot(p0, B00), g110 = dot(p1, B01), g011 = dot(p0, B11b);
    const History h200 = f.binv(l0, q0, p0, B00, -dot(p0, B00));
    const History h011 = f.binv(l0, q0, p0, B11b, -dot(p0, B11b));
    const History h110 = f.binv(l1, q1, p1, B01, -dot(p1, B01));
    const History h110b = h110.conj();
    const History h020 = f.solve(2.0 * l1, B(phi1, phi1));
    if (!f.ok()) {
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

DoubleHopfNormalForm double_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p, double omega1,
                                             double omega2) {
    if (!(std::isfinite(omega1) && omega1 > 0.0 && std::isfinite(omega2) && omega2 > 0.0 && omega1 != omega2))
        throw std::invalid_argument("double Hopf normal form: omega1 = " + std::to_string(omega1) + ", omega2 = " + std::to_string(omega2) +
                                    ": expected two different values > 0");
    CentreForms f(system, x, p, 3);
    DoubleHopfNormalForm r;
    // the strong resonances 1:2 and 1:3 (omega2 = k omega1 or omega1 = k omega2) have another
    // normal form (resonant terms at second and third order); near them these coefficients grow
    std::string near;
    for (const int k : {2, 3}) {
        const double off = std::min(std::abs(omega2 - k * omega1), std::abs(omega1 - k * omega2)) / std::max(omega1, omega2);
        if (off <= 1e-6) {
            r.message = "a 1:" + std::to_string(k) + " resonance (one frequency " + std::to_string(k) +
                        " times the other): the normal form of a non-resonant double Hopf point does not apply";
            return r;
        }
        if (off <= 1e-2) near = " (near a 1:" + std::to_string(k) + " resonance: the coefficients may be large)";
    }
    const cplx l1(0.0, omega1), l2(0.0, omega2);
    VectorXc q1, p1, q2, p2;
    if (!f.pair(l1, q1, p1, r.hopf1_residual) || !f.pair(l2, q2, p2, r.hopf2_residual)) {
        r.message = "the eigenvectors cannot be normalised (p Delta'(i omega) q = 0: a pair is not simple)";
        return r;
    }
    auto B = [&](const History& a, const History& b) { return f.B(a, b); };
    auto C = [&](const History& a, const History& b, const History& c) { return f.C(a, b, c); };
    auto dot = CentreForms::dot;
    const History phi1 = CentreForms::exp(q1, l1), phi1b = phi1.conj(), phi2 = CentreForms::exp(q2, l2), phi2b = phi2.conj();
    const History h1100 = f.solve(0.0, B(phi1, phi1b)), h2000 = f.solve(2.0 * l1, B(phi1, phi1));
    const History h1010 = f.solve(l1 + l2, B(phi1, phi2)), h1001 = f.solve(l1 - l2, B(phi1, phi2b)), h1001b = h1001.conj();
    const History h0020 = f.solve(2.0 * l2, B(phi2, phi2)), h0011 = f.solve(0.0, B(phi2, phi2b));
    if (!f.ok()) {
        r.message = "an inverse of the centre manifold is singular (0, 2 i omega_j or i (omega1 +- omega2) is a root too: a resonance)";
        return r;
    }
    r.g2100 = 0.5 * dot(p1, 2.0 * B(h1100, phi1) + B(h2000, phi1b) + C(phi1, phi1, phi1b));
    r.g1011 = dot(p1, B(h0011, phi1) + B(h1001, phi2) + B(h1010, phi2b) + C(phi1, phi2, phi2b));
    r.g1110 = dot(p2, B(h1001b, phi1) + B(h1010, phi1b) + B(h1100, phi2) + C(phi1, phi1b, phi2));
    r.g0021 = 0.5 * dot(p2, 2.0 * B(h0011, phi2) + B(h0020, phi2b) + C(phi2, phi2, phi2b));
    r.q1 = q1, r.p1 = p1, r.q2 = q2, r.p2 = p2;
    for (const cplx g : {r.g2100, r.g1011, r.g1110, r.g0021})
        if (!std::isfinite(std::abs(g))) {
            r.message = "a coefficient g is not finite";
            return r;
        }
    if (r.g0021.real() != 0.0) r.theta = r.g1011.real() / r.g0021.real();
    if (r.g2100.real() != 0.0) r.delta = r.g1110.real() / r.g2100.real();
    r.status = Status::Converged;
    r.message = (std::isfinite(r.theta) && std::isfinite(r.delta)
                     ? "theta = " + std::to_string(r.theta) + ", delta = " + std::to_string(r.delta)
                     : std::string("degenerate: ") + (std::isfinite(r.theta) ? "Re g2100 = 0 (delta undefined)" : "Re g0021 = 0 (theta undefined)")) +
                near;
    return r;
}

GeneralisedHopfNormalForm generalised_hopf_normal_form(const NonlinearDDE& system, const Eigen::VectorXd& x, const std::vector<double>& p,
                                                       double omega) {
    if (!(std::isfinite(omega) && omega > 0.0))
        throw std::invalid_argument("generalised Hopf normal form: omega = " + std::to_string(omega) + ": expected a value > 0");
    CentreForms f(system, x, p, 5);
    GeneralisedHopfNormalForm r;
    const cplx l(0.0, omega);
    VectorXc q, pv;
    if (!f.pair(l, q, pv, r.hopf_residual)) {
        r.message = "the eigenvectors cannot be normalised (p Delta'(i omega) q = 0: the pair is not simple)";
        return r;
    }
    auto B = [&](const History& a, const History& b) { return f.B(a, b); };
    auto C = [&](const History& a, const History& b, const History& c) { return f.C(a, b, c); };
    auto D = [&](const History& a, const History& b, const History& c, const History& d) { return f.D4(a, b, c, d); };
    auto dot = CentreForms::dot;
    const History phi = CentreForms::exp(q, l), phib = phi.conj();
    const VectorXc B20 = B(phi, phi);
    const History h20 = f.solve(2.0 * l, B20), h20b = h20.conj(), h11 = f.solve(0.0, B(phi, phib));
    const VectorXc r21 = B(phib, h20) + 2.0 * B(phi, h11) + C(phi, phi, phib);
    const cplx c1 = 0.5 * dot(pv, r21);
    const History h30 = f.solve(3.0 * l, 3.0 * B(phi, h20) + C(phi, phi, phi));
    const History h21 = f.binv(l, q, pv, r21, -2.0 * c1), h21b = h21.conj();
    // h31: the particular solution of the theta-dependent equation (nmfm_genh's devlt)
    const VectorXc y20 = h20.terms.front().v;  // Delta(2 lambda)^-1 B(phi, phi)
    const VectorXc r31 = B(phib, h30) + 3.0 * B(phi, h21) + 3.0 * B(h20, h11) + 3.0 * C(phi, phib, h20) + 3.0 * C(phi, phi, h11) +
                         D(phi, phi, phi, phib);
    History h31 = f.solve(2.0 * l, r31 - 6.0 * c1 * (f.dD(2.0 * l) * y20));
    h31.terms.push_back({6.0 * c1 * y20, 2.0 * l, 1});
    const History h22 = f.solve(0.0, 2.0 * B(phib, h21) + 2.0 * B(h11, h11) + 2.0 * B(phi, h21b) + B(h20, h20b) + C(phib, phib, h20) +
                                         C(phi, phi, h20b) + 4.0 * C(phi, phib, h11) + D(phi, phi, phib, phib));
    if (!f.ok()) {
        r.message = "an inverse of the centre manifold is singular (0, 2 i omega or 3 i omega is a root too, or the pair is not simple)";
        return r;
    }
    const cplx c2 = dot(pv, 6.0 * B(h11, h21) + 3.0 * B(h21b, h20) + B(h20b, h30) + 3.0 * B(phi, h22) + 2.0 * B(phib, h31) +
                                6.0 * C(phib, h20, h11) + 6.0 * C(phi, h11, h11) + 3.0 * C(phi, h20, h20b) + 6.0 * C(phi, phib, h21) +
                                3.0 * C(phi, phi, h21b) + C(phib, phib, h30) + 6.0 * D(phi, phi, phib, h11) + 3.0 * D(phi, phib, phib, h20) +
                                D(phi, phi, phi, h20b) + f.E5(phi, phi, phi, phib, phib)) /
                    12.0;
    r.c1 = c1;
    r.c2 = c2;
    r.l1 = c1.real() / omega;
    r.l2 = c2.real() / omega;
    r.q = q;
    r.p = pv;
    if (!std::isfinite(std::abs(c1)) || !std::isfinite(std::abs(c2))) {
        r.message = "a coefficient is not finite";
        return r;
    }
    r.status = Status::Converged;
    r.message = "L2 = " + std::to_string(r.l2);
    return r;
}

}  // namespace ddemap
