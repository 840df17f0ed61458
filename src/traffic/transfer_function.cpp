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
}

void TransferFunction::evaluate(cplx s, cplx& n, cplx& d) const {
    cplx gap = 0.0, own = 0.0, lead = 0.0;
    for (const auto& g : m_groups) {
        const cplx e = g.delay == 0.0 ? cplx(1.0) : std::exp(-s * g.delay);
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
        const cplx e = g.delay == 0.0 ? cplx(1.0) : std::exp(-s * g.delay);
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
    const cplx s(0.0, w);
    return 2.0 * (std::conj((*this)(s)) * cplx(0.0, 1.0) * derivative(s)).real();
}

namespace {

/// sin(w d) / w (d for w = 0), accurate for small w d.
double sin_over(double w, double d) {
    const double x = w * d;
    if (std::abs(x) < 1e-4) return d * (1.0 - x * x / 6.0);
    return std::sin(x) / w;
}

}  // namespace

double TransferFunction::attenuation(double w, double* q_out, double* noise_out) const {
    // Re and Im/w of own, lead, gap at s = i w: e^{-i w d} = cos(w d) - i sin(w d)
    double re_own = 0.0, re_lead = 0.0, re_gap = 0.0, im_own_w = 0.0, im_lead_w = 0.0, im_gap_w = 0.0;
    double m_own = 0.0, m_lead = 0.0, m_gap = 0.0, mi_own = 0.0, mi_lead = 0.0, mi_gap = 0.0;  // magnitudes
    double mi_ol = 0.0;
    for (const auto& g : m_groups) {
        const double c = g.delay == 0.0 ? 1.0 : std::cos(w * g.delay);
        const double so = g.delay == 0.0 ? 0.0 : sin_over(w, g.delay);
        re_own += g.own * c;
        re_lead += g.lead * c;
        re_gap += g.gap * c;
        im_own_w -= g.own * so;
        im_lead_w -= g.lead * so;
        im_gap_w -= g.gap * so;
        m_own += std::abs(g.own);
        m_lead += std::abs(g.lead);
        m_gap += std::abs(g.gap);
        mi_own += std::abs(g.own * so);
        mi_lead += std::abs(g.lead * so);
        mi_gap += std::abs(g.gap * so);
        mi_ol += std::abs((g.own + g.lead) * so);
    }
    // A = i w - own - lead; B = D + N = s^2 - s own + 2 gap + s lead (s = i w, s x = i w x)
    const double re_a = -re_own - re_lead;
    const double im_a_w = 1.0 - im_own_w - im_lead_w;
    const double re_b = -w * w + w * w * im_own_w + 2.0 * re_gap - w * w * im_lead_w;
    const double im_b_w = re_lead - re_own + 2.0 * im_gap_w;
    const double q = re_a * im_b_w - re_b * im_a_w;
    if (q_out) *q_out = q;
    if (noise_out) {
        const double ma = m_own + m_lead, mia = 1.0 + mi_ol + mi_own + mi_lead;
        const double mb = w * w * (1.0 + mi_own + mi_lead) + 2.0 * m_gap, mib = m_lead + m_own + 2.0 * mi_gap;
        *noise_out = 32.0 * std::numeric_limits<double>::epsilon() * (ma * mib + mb * mia);
    }
    cplx n, d;
    evaluate(cplx(0.0, w), n, d);
    return w * w * q / std::norm(d);
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
