#pragma once
// Internal: the multilinear forms of a nonlinear DDE at an equilibrium for complex directions,
// and the characteristic matrix, shared by the Hopf analysis (hopf.cpp) and the normal forms of
// codimension-two points (normal_forms.cpp).
#include <vector>

#include <Eigen/Core>

#include "ddemap/core/dual.hpp"
#include "ddemap/core/types.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"

namespace ddemap::detail::multilinear {

using D1 = Dual<double>;
using D2 = NonlinearDDE::Dual2;
using D3 = NonlinearDDE::Dual3;
inline const cplx I1(0.0, 1.0);

inline double entry(const Eigen::VectorXd& v, Eigen::Index i) { return v.size() == 0 ? 0.0 : v[i]; }

/// D^2 f(u; p)[(a, 0), (b, bp)] (bp: a direction of the parameters, empty = 0), one evaluation
/// in Dual<Dual<double>> seeded u + a e1 + b e2, p + bp e2.
inline Eigen::VectorXd d2(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const Eigen::VectorXd& a,
                   const Eigen::VectorXd& b, const Eigen::VectorXd& bp = {}) {
    const int n = s.dimension();
    std::vector<D2> U(static_cast<std::size_t>(u.size())), P(p.size()), out(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < u.size(); ++i) U[static_cast<std::size_t>(i)] = D2(D1(u[i], a[i]), D1(b[i], 0.0));
    for (std::size_t i = 0; i < p.size(); ++i) P[i] = D2(D1(p[i], 0.0), D1(entry(bp, static_cast<Eigen::Index>(i)), 0.0));
    s.evaluate(U.data(), P.data(), out.data());
    Eigen::VectorXd r(n);
    for (int i = 0; i < n; ++i) r[i] = out[static_cast<std::size_t>(i)].deriv.deriv;
    return r;
}

/// D^3 f(u; p)[a, b, c]: u + a e1 + b e2 + c e3 in three nested levels.
inline Eigen::VectorXd d3(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const Eigen::VectorXd& a,
                   const Eigen::VectorXd& b, const Eigen::VectorXd& c) {
    const int n = s.dimension();
    std::vector<D3> U(static_cast<std::size_t>(u.size())), P(p.size()), out(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < u.size(); ++i)
        U[static_cast<std::size_t>(i)] = D3(D2(D1(u[i], a[i]), D1(b[i], 0.0)), D2(D1(c[i], 0.0), D1(0.0, 0.0)));
    for (std::size_t i = 0; i < p.size(); ++i) P[i] = D3(p[i]);
    s.evaluate(U.data(), P.data(), out.data());
    Eigen::VectorXd r(n);
    for (int i = 0; i < n; ++i) r[i] = out[static_cast<std::size_t>(i)].deriv.deriv.deriv;
    return r;
}

/// B(a, b) for complex stacked directions (bilinear, not sesquilinear).
inline VectorXc b_complex(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const VectorXc& a, const VectorXc& b) {
    const Eigen::VectorXd ar = a.real(), ai = a.imag(), br = b.real(), bi = b.imag();
    return (d2(s, u, p, ar, br) - d2(s, u, p, ai, bi)).cast<cplx>() + I1 * (d2(s, u, p, ar, bi) + d2(s, u, p, ai, br)).cast<cplx>();
}

/// C(a, b, c) for complex directions: the 8 real terms of the trilinear expansion.
inline VectorXc c_complex(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const VectorXc& a, const VectorXc& b,
                   const VectorXc& c) {
    VectorXc r = VectorXc::Zero(s.dimension());
    const Eigen::VectorXd parts[3][2] = {{a.real(), a.imag()}, {b.real(), b.imag()}, {c.real(), c.imag()}};
    for (int mask = 0; mask < 8; ++mask) {
        const int ia = mask & 1, ib = (mask >> 1) & 1, ic = (mask >> 2) & 1;
        const Eigen::VectorXd& va = parts[0][ia];
        const Eigen::VectorXd& vb = parts[1][ib];
        const Eigen::VectorXd& vc = parts[2][ic];
        if (va.isZero(0.0) || vb.isZero(0.0) || vc.isZero(0.0)) continue;
        cplx factor(1.0, 0.0);
        for (int k = 0; k < ia + ib + ic; ++k) factor *= I1;
        r += factor * d3(s, u, p, va, vb, vc).cast<cplx>();
    }
    return r;
}

/// (v e^{-lambda tau_k})_k, tau_0 = 0.
inline VectorXc stack(const VectorXc& v, cplx lambda, const std::vector<double>& tau) {
    const Eigen::Index n = v.size();
    VectorXc r(n * static_cast<Eigen::Index>(tau.size()));
    for (std::size_t k = 0; k < tau.size(); ++k) r.segment(static_cast<Eigen::Index>(k) * n, n) = v * std::exp(-lambda * tau[k]);
    return r;
}

/// Delta(lambda) = lambda I - sum_k A_k e^{-lambda tau_k}, or with derivative = true
/// Delta'(lambda) = I + sum_k tau_k A_k e^{-lambda tau_k}.
inline MatrixXc delta(const std::vector<Eigen::MatrixXd>& a, const std::vector<double>& tau, cplx lambda, bool derivative = false) {
    const Eigen::Index n = a[0].rows();
    MatrixXc m = MatrixXc::Identity(n, n) * (derivative ? cplx(1.0, 0.0) : lambda);
    for (std::size_t k = 0; k < a.size(); ++k) {
        const cplx e = std::exp(-lambda * tau[k]);
        m += (derivative ? tau[k] * e : -e) * a[k].cast<cplx>();
    }
    return m;
}

}  // namespace ddemap::detail::multilinear
