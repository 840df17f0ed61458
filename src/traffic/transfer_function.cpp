#include "ddemap/traffic/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace ddemap {

TransferFunction::TransferFunction(Linearisation lin) : m_lin(std::move(lin)) {
    require_single_leader(m_lin, "the head-to-tail transfer function");
    auto group = [&](double delay) -> DelayGroup& {
        for (auto& g : m_groups)
            if (g.delay == delay) return g;
        m_groups.push_back({delay, 0.0, 0.0, 0.0});
        return m_groups.back();
    };
    for (const auto& t : m_lin.gap.terms()) group(t.delay).gap += t.coef;
    for (const auto& t : m_lin.own.terms()) group(t.delay).own += t.coef;
    for (const auto& t : m_lin.lead.terms()) group(t.delay).lead += t.coef;
    for (const auto& g : m_groups) {
        m_abs_own += std::abs(g.own);
        m_abs_lead += std::abs(g.lead);
        m_abs_gap += std::abs(g.gap);
    }
}

void TransferFunction::evaluate(cplx s, cplx& n, cplx& d) const {
    cplx gap = 0.0, own = 0.0, lead = 0.0;
    for (const auto& g : m_groups) {
        // e^{-s d} = e^{-d Re s} (cos(d Im s) - i sin(d Im s)): no exponential on the imaginary axis
        const cplx e = g.delay == 0.0 ? cplx(1.0)
                                      : std::polar(s.real() == 0.0 ? 1.0 : std::exp(-s.real() * g.delay), -s.imag() * g.delay);
        gap += g.gap * e;
        own += g.own * e;
        lead += g.lead * e;
    }
    n = gap + s * lead;
    d = s * s - s * own + gap;
}

void TransferFunction::evaluate(cplx s, cplx& n, cplx& d, cplx& dn, cplx& dd) const {
    cplx gap = 0.0, own = 0.0, lead = 0.0, dgap = 0.0, down = 0.0, dlead = 0.0;
    for (const auto& g : m_groups) {
        // e^{-s d} = e^{-d Re s} (cos(d Im s) - i sin(d Im s)): no exponential on the imaginary axis
        const cplx e = g.delay == 0.0 ? cplx(1.0)
                                      : std::polar(s.real() == 0.0 ? 1.0 : std::exp(-s.real() * g.delay), -s.imag() * g.delay);
        gap += g.gap * e;
        own += g.own * e;
        lead += g.lead * e;
        dgap -= g.delay * g.gap * e;
        down -= g.delay * g.own * e;
        dlead -= g.delay * g.lead * e;
    }
    n = gap + s * lead;
    d = s * s - s * own + gap;
    dn = dgap + lead + s * dlead;
    dd = 2.0 * s - own - s * down + dgap;
}

TransferFunction::Line::Line(const TransferFunction& tf, double sigma) : m_sigma(sigma) {
    for (const auto& g : tf.m_groups) {
        if (g.delay == 0.0) {
            m_gap0 += g.gap;
            m_own0 += g.own;
            m_lead0 += g.lead;
        } else {
            const double f = sigma == 0.0 ? 1.0 : std::exp(-sigma * g.delay);
            m_terms.push_back({g.delay, g.gap * f, g.own * f, g.lead * f});
        }
    }
}

void TransferFunction::Line::operator()(double s, cplx& n, cplx& d, cplx& dn, cplx& dd) const {
    // sums of coefficient * e^{-lambda delay} (re, im) and of -delay * coefficient * e^{-lambda delay}
    double gr = m_gap0, gi = 0.0, orr = m_own0, oi = 0.0, lr = m_lead0, li = 0.0;
    double dgr = 0.0, dgi = 0.0, dor = 0.0, doi = 0.0, dlr = 0.0, dli = 0.0;
    for (const auto& t : m_terms) {
        const double c = std::cos(s * t.delay), sn = std::sin(s * t.delay);  // one sincos
        const double agr = t.gap * c, agi = -t.gap * sn, aor = t.own * c, aoi = -t.own * sn, alr = t.lead * c, ali = -t.lead * sn;
        gr += agr;
        gi += agi;
        orr += aor;
        oi += aoi;
        lr += alr;
        li += ali;
        dgr -= t.delay * agr;
        dgi -= t.delay * agi;
        dor -= t.delay * aor;
        doi -= t.delay * aoi;
        dlr -= t.delay * alr;
        dli -= t.delay * ali;
    }
    const double a = m_sigma, b = s;  // lambda = a + i b
    n = cplx(gr + a * lr - b * li, gi + a * li + b * lr);
    d = cplx(a * a - b * b - (a * orr - b * oi) + gr, 2.0 * a * b - (a * oi + b * orr) + gi);
    dn = cplx(dgr + lr + a * dlr - b * dli, dgi + li + a * dli + b * dlr);
    dd = cplx(2.0 * a - orr - (a * dor - b * doi) + dgr, 2.0 * b - oi - (a * doi + b * dor) + dgi);
}

cplx TransferFunction::numerator(cplx s) const {
    cplx n, d;
    evaluate(s, n, d);
    return n;
}

cplx TransferFunction::denominator(cplx s) const {
    cplx n, d;
    evaluate(s, n, d);
    return d;
}

cplx TransferFunction::derivative(cplx s) const {
    cplx n, d, np, dp;
    evaluate(s, n, d, np, dp);
    return (np * d - n * dp) / (d * d);
}

double TransferFunction::gain2_derivative(double w) const {
    // one evaluation of N, D and their derivatives (the same exponentials)
    const cplx s(0.0, w);
    cplx n, d, np, dp;
    evaluate(s, n, d, np, dp);
    const cplx gamma = n / d, derivative = (np * d - n * dp) / (d * d);
    return 2.0 * (std::conj(gamma) * cplx(0.0, 1.0) * derivative).real();
}


double TransferFunction::attenuation(double w, double* q_out, double* noise_out) const {
    // Re and Im/w of own, lead, gap at s = i w: e^{-i w d} = cos(w d) - i sin(w d); one sincos per
    // delay also gives N(i w) and D(i w) for |D|^2
    double re_own = 0.0, re_lead = 0.0, re_gap = 0.0, im_own_w = 0.0, im_lead_w = 0.0, im_gap_w = 0.0;
    double im_own = 0.0, im_gap = 0.0;  // Im of own and gap (for D)
    double mi_own = 0.0, mi_lead = 0.0, mi_gap = 0.0, mi_ol = 0.0;  // magnitudes of the Im/w terms
    const bool noise = noise_out != nullptr;  // the magnitudes only when the rounding bound is asked for
    for (const auto& g : m_groups) {
        double c = 1.0, sn = 0.0, so = 0.0;
        if (g.delay != 0.0) {
            const double x = w * g.delay;
            sn = std::sin(x);
            c = std::cos(x);
            so = std::abs(x) < 1e-4 ? g.delay * (1.0 - x * x / 6.0) : sn / w;  // sin(w d) / w, accurate for small w d
        }
        re_own += g.own * c;
        re_lead += g.lead * c;
        re_gap += g.gap * c;
        im_own -= g.own * sn;
        im_gap -= g.gap * sn;
        im_own_w -= g.own * so;
        im_lead_w -= g.lead * so;
        im_gap_w -= g.gap * so;
        if (noise) {
            mi_own += std::abs(g.own * so);
            mi_lead += std::abs(g.lead * so);
            mi_gap += std::abs(g.gap * so);
            mi_ol += std::abs((g.own + g.lead) * so);
        }
    }
    // A = i w - own - lead; B = D + N = s^2 - s own + 2 gap + s lead (s = i w, s x = i w x)
    const double re_a = -re_own - re_lead;
    const double im_a_w = 1.0 - im_own_w - im_lead_w;
    const double re_b = -w * w + w * w * im_own_w + 2.0 * re_gap - w * w * im_lead_w;
    const double im_b_w = re_lead - re_own + 2.0 * im_gap_w;
    const double q = re_a * im_b_w - re_b * im_a_w;
    if (q_out) *q_out = q;
    if (noise_out) {
        const double ma = m_abs_own + m_abs_lead, mia = 1.0 + mi_ol + mi_own + mi_lead;
        const double mb = w * w * (1.0 + mi_own + mi_lead) + 2.0 * m_abs_gap, mib = m_abs_lead + m_abs_own + 2.0 * mi_gap;
        *noise_out = 32.0 * std::numeric_limits<double>::epsilon() * (ma * mib + mb * mia);
    }
    // D(i w) = -w^2 - i w own + gap
    const double d_re = -w * w + w * im_own + re_gap, d_im = -w * re_own + im_gap;
    return w * w * q / (d_re * d_re + d_im * d_im);
}

namespace {

/// Adds the terms of `e` to the matrices of `terms` at entry (row, col), one matrix per delay.
void add_terms(std::vector<DelayTerm>& terms, MatrixXc& a0, const ExpPoly& e, int row, int col, cplx factor, int n) {
    for (const auto& t : e.terms()) {
        if (t.delay == 0.0) {
            a0(row, col) += factor * t.coef;
            continue;
        }
        auto it = std::find_if(terms.begin(), terms.end(), [&](const DelayTerm& d) { return d.delay == t.delay; });
        if (it == terms.end()) {
            terms.push_back({MatrixXc::Zero(n, n), t.delay});
            it = terms.end() - 1;
        }
        it->matrix(row, col) += factor * t.coef;
    }
}

}  // namespace

LinearDDE plant_dde(const Linearisation& lin) {
    MatrixXc a0 = MatrixXc::Zero(2, 2);
    std::vector<DelayTerm> terms;
    a0(0, 1) = -1.0;
    add_terms(terms, a0, lin.gap, 1, 0, 1.0, 2);
    add_terms(terms, a0, lin.own, 1, 1, 1.0, 2);
    return LinearDDE(a0, terms);
}

}  // namespace ddemap
