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

/// Dual numbers nested K levels deep (K = 0: double).
template <int K> struct Nested { using type = Dual<typename Nested<K - 1>::type>; };
template <> struct Nested<0> { using type = double; };

/// u + d_0 e_1 + ... + d_{K-1} e_K: level j carries direction d_{j-1} (as d2 and d3 seed).
template <int K> typename Nested<K>::type seed(double u, const double* d) {
    if constexpr (K == 0) return u;
    else return typename Nested<K>::type(seed<K - 1>(u, d), typename Nested<K - 1>::type(d[K - 1]));
}
template <int K> double mixed_part(const typename Nested<K>::type& v) {
    if constexpr (K == 0) return v;
    else return mixed_part<K - 1>(v.deriv);
}

/// D^K f(u; p)[d_0, ..., d_{K-1}] for real stacked directions (K = 1..5), one evaluation in K
/// nested levels of dual numbers.
template <int K>
Eigen::VectorXd dk(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const Eigen::VectorXd* const* d) {
    using T = typename Nested<K>::type;
    const int n = s.dimension();
    std::vector<T> U(static_cast<std::size_t>(u.size())), P(p.size()), out(static_cast<std::size_t>(n));
    double dirs[K];
    for (Eigen::Index i = 0; i < u.size(); ++i) {
        for (int k = 0; k < K; ++k) dirs[k] = (*d[k])[i];
        U[static_cast<std::size_t>(i)] = seed<K>(u[i], dirs);
    }
    for (std::size_t i = 0; i < p.size(); ++i) P[i] = T(p[i]);
    s.evaluate(U.data(), P.data(), out.data());
    Eigen::VectorXd r(n);
    for (int i = 0; i < n; ++i) r[i] = mixed_part<K>(out[static_cast<std::size_t>(i)]);
    return r;
}

/// D^K f[a_0, ..., a_{K-1}] for complex directions (multilinear, no conjugation): the 2^K real
/// terms of the expansion a_k = Re a_k + i Im a_k, zero parts skipped.
template <int K>
VectorXc dk_complex(const NonlinearDDE& s, const Eigen::VectorXd& u, const std::vector<double>& p, const VectorXc* const* a) {
    Eigen::VectorXd parts[K][2];
    bool zero[K][2];
    for (int k = 0; k < K; ++k) {
        parts[k][0] = a[k]->real();
        parts[k][1] = a[k]->imag();
        zero[k][0] = parts[k][0].isZero(0.0);
        zero[k][1] = parts[k][1].isZero(0.0);
    }
    VectorXc r = VectorXc::Zero(s.dimension());
    for (int mask = 0; mask < (1 << K); ++mask) {
        const Eigen::VectorXd* d[K];
        int imag = 0;
        bool skip = false;
        for (int k = 0; k < K; ++k) {
            const int b = (mask >> k) & 1;
            skip = skip || zero[k][b];
            imag += b;
            d[k] = &parts[k][b];
        }
        if (skip) continue;
        static const cplx powers[4] = {cplx(1, 0), cplx(0, 1), cplx(-1, 0), cplx(0, -1)};
        r += powers[imag % 4] * dk<K>(s, u, p, d).template cast<cplx>();
    }
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
