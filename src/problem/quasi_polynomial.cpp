#include "ddemap/problem/quasi_polynomial.hpp"

#include "ddemap/core/phase_tracking.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ddemap/core/newton.hpp"

namespace ddemap {

using cplx = std::complex<double>;


QuasiPolynomial::QuasiPolynomial(int degree, std::vector<Term> terms) : m_degree(degree), m_terms(std::move(terms)) {
    if (degree != 1 && degree != 2) throw std::invalid_argument("quasi-polynomial degree must be 1 or 2");
    for (const auto& t : m_terms) {
        if (static_cast<int>(t.poly.size()) > degree) throw std::invalid_argument("quasi-polynomial term of degree >= n: not of retarded type");
        if (!(t.delay >= 0.0) || !std::isfinite(t.delay)) throw std::invalid_argument("quasi-polynomial delay must be finite and >= 0");
        m_max_delay = std::max(m_max_delay, t.delay);
    }
}

namespace {

/// e^{-x d_j} for every term (1 for d_j = 0), without a heap allocation for up to 8 terms.
class Magnitudes {
public:
    Magnitudes(const std::vector<QuasiPolynomial::Term>& terms, double x) {
        double* out = m_small;
        if (terms.size() > 8) {
            m_large.resize(terms.size());
            out = m_large.data();
        }
        for (std::size_t j = 0; j < terms.size(); ++j) out[j] = terms[j].delay == 0.0 ? 1.0 : std::exp(-x * terms[j].delay);
    }
    const double* data() const { return m_large.empty() ? m_small : m_large.data(); }

private:
    double m_small[8];
    std::vector<double> m_large;
};

}  // namespace

void QuasiPolynomial::evaluate(cplx lambda, cplx& f, cplx& fp) const {
    const Magnitudes mags(m_terms, lambda.real());
    evaluate(lambda, mags.data(), f, fp);
}

void QuasiPolynomial::evaluate(cplx lambda, const double* magnitudes, cplx& f, cplx& fp) const {
    if (m_degree == 2) {
        f = lambda * lambda;
        fp = 2.0 * lambda;
    } else {
        f = lambda;
        fp = 1.0;
    }
    for (std::size_t j = 0; j < m_terms.size(); ++j) {
        const Term& t = m_terms[j];
        cplx p = 0.0, dp = 0.0;
        for (int k = static_cast<int>(t.poly.size()) - 1; k >= 0; --k) {
            dp = dp * lambda + p;
            p = p * lambda + t.poly[k];
        }
        if (t.delay == 0.0) {
            f += p;
            fp += dp;
        } else {
            const cplx e = std::polar(magnitudes[j], -lambda.imag() * t.delay);
            f += p * e;
            fp += (dp - t.delay * p) * e;
        }
    }
}

bool QuasiPolynomial::is_real() const {
    for (const auto& t : m_terms)
        for (cplx c : t.poly)
            if (c.imag() != 0.0) return false;
    return true;
}

cplx QuasiPolynomial::operator()(cplx lambda) const {
    cplx f = m_degree == 2 ? lambda * lambda : lambda;
    for (const auto& t : m_terms) {
        cplx p = 0.0;
        for (int k = static_cast<int>(t.poly.size()) - 1; k >= 0; --k) p = p * lambda + t.poly[k];
        f += t.delay == 0.0 ? p : p * std::polar(std::exp(-lambda.real() * t.delay), -lambda.imag() * t.delay);
    }
    return f;
}

bool QuasiPolynomial::newton(cplx& lambda, int max_iterations) const {
    NewtonOptions o;
    o.max_iterations = max_iterations;  // step tolerance 4 eps
    const NewtonSummary s = ddemap::newton(
        lambda,
        [&](const cplx& z, cplx& dz) {
            cplx f, fp;
            evaluate(z, f, fp);
            if (f == cplx(0.0)) return NewtonStep::Exact;
            if (fp == cplx(0.0)) return NewtonStep::Singular;
            dz = f / fp;
            return NewtonStep::Ok;
        },
        o);
    return s.status == Status::Converged;
}

namespace {

/// arg(b / a) without a complex division
double arg_ratio(cplx b, cplx a) { return std::arg(b * std::conj(a)); }

/// Samples f on the line Re(lambda) = sigma for the shared phase tracker; eval(w, f, f')
/// evaluates at sigma + i w.
template <class Evaluate>
struct LineSampler {
    Evaluate& eval;
    bool failed = false;
    int budget = 20000;
    PhaseSample operator()(double w) {
        cplx v, d;
        eval(w, v, d);
        if (v == cplx(0.0)) {
            failed = true;
            return {w, cplx(1.0), 0.0};
        }
        return {w, v, std::norm(d) / std::norm(v)};
    }
};

}  // namespace

int QuasiPolynomial::zeros_right_of(double sigma) const {
    // radius r of the half circle |lambda - sigma| = r, Re >= sigma, on which
    // |f - (lambda - sigma)^n| <= r^n / 2, so that arg f follows arg (lambda - sigma)^n there
    const double s = std::abs(sigma);
    // |f - (lambda - sigma)^n| <= c0 + c1 |lambda| (+ 2 s |lambda| + s^2 for n = 2), |lambda| <= r + s
    double c0 = m_degree == 2 ? s * s : s, c1 = m_degree == 2 ? 2.0 * s : 0.0;
    for (const auto& t : m_terms) {
        const double e = t.delay == 0.0 ? 1.0 : std::exp(-sigma * t.delay);
        if (!t.poly.empty()) c0 += e * std::abs(t.poly[0]);
        if (t.poly.size() > 1) c1 += e * std::abs(t.poly[1]);
    }
    auto bound = [&](double r) { return c0 + c1 * (r + s); };
    auto enough = [&](double r) { return bound(r) < 0.5 * (m_degree == 2 ? r * r : r); };
    double r = 1.0;
    for (int i = 0; i < 400 && !enough(r); ++i) r *= 1.25;
    if (!enough(r)) return -1;

    // the line from sigma - i r to sigma + i r, sampled at least every pi / (4 tau_max); for real
    // coefficients f(conj lambda) = conj f(lambda), so the change of arg f along the lower half
    // equals the change along the upper half: only [0, r] is sampled (half the work)
    const bool real = is_real();
    int pieces = real ? 4 : 8;
    // (capped in double before the conversion: r times the delay is not bounded)
    if (m_max_delay > 0.0)
        pieces = std::max(pieces, static_cast<int>(std::min(real ? 2048.0 : 4096.0, std::ceil((real ? 1.0 : 2.0) * r * m_max_delay * 4.0 / M_PI))));
    pieces = std::min(pieces, real ? 2048 : 4096);
    // e^{-sigma d_j} is the same at every sample of the line: computed once per term
    const Magnitudes mags(m_terms, sigma);
    auto eval = [&](double w, cplx& v, cplx& d) { evaluate(cplx(sigma, w), mags.data(), v, d); };
    LineSampler<decltype(eval)> line{eval};
    double total = 0.0;
    const double start = real ? 0.0 : -r, length = real ? r : 2.0 * r;
    PhaseSample a = line(start);
    if (line.failed) return -1;
    const cplx first = a.f;
    for (int i = 1; i <= pieces; ++i) {
        const PhaseSample b = line(start + length * i / pieces);
        if (line.failed) return -1;
        total += bisect_phase(line, a, b);
        if (line.failed) return -1;
        a = b;
    }
    const cplx fa = a.f;
    const cplx last = fa;
    // along the half circle (counter-clockwise, bottom to top) arg f changes by
    // n pi + arg h(top) - arg h(bottom), h = f / (lambda - sigma)^n (principal args: |h - 1| < 1/2);
    // for real coefficients h(bottom) = conj h(top) and the line's change is twice the upper half's
    const cplx top = cplx(0.0, r), bottom = cplx(0.0, -r);
    double arc = 0.0;
    if (real) {
        arc = m_degree * M_PI + 2.0 * arg_ratio(last, std::pow(top, m_degree));
        total *= 2.0;
    } else {
        arc = m_degree * M_PI + arg_ratio(last, std::pow(top, m_degree)) - arg_ratio(first, std::pow(bottom, m_degree));
    }
    const double z = (arc - total) / (2.0 * M_PI);
    const double zr = std::round(z);
    if (std::abs(z - zr) > 0.05 || zr < 0) return -1;
    return static_cast<int>(zr);
}

}  // namespace ddemap
