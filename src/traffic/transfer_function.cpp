#include "ddemap/traffic/transfer_function.hpp"

#include <algorithm>
#include <cmath>
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
