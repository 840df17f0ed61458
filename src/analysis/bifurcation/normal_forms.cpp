#include "ddemap/analysis/bifurcation/normal_forms.hpp"

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
