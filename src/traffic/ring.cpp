#include "ddemap/traffic/ring.hpp"

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

namespace {

DelayTerm& term_for(std::vector<DelayTerm>& terms, double delay, int n) {
    auto it = std::find_if(terms.begin(), terms.end(), [&](const DelayTerm& d) { return d.delay == delay; });
    if (it != terms.end()) return *it;
    terms.push_back({MatrixXc::Zero(n, n), delay});
    return terms.back();
}

void place(std::vector<DelayTerm>& terms, MatrixXc& a0, const ExpPoly& e, int row, int col, cplx factor) {
    const int n = static_cast<int>(a0.rows());
    for (const auto& t : e.terms()) {
        if (t.delay == 0.0) {
            a0(row, col) += factor * t.coef;
        } else {
            term_for(terms, t.delay, n).matrix(row, col) += factor * t.coef;
        }
    }
}

}  // namespace

cplx ring_zeta(int m, int cars) {
    const long k = ((static_cast<long>(m) % cars) + cars) % cars;
    if (k == 0) return 1.0;
    if (4 * k == cars) return cplx(0.0, -1.0);
    if (2 * k == cars) return -1.0;
    if (4 * k == 3L * cars) return cplx(0.0, 1.0);
    return std::polar(1.0, -2.0 * M_PI * static_cast<double>(k) / cars);
}

LinearDDE ring_mode_dde(const Linearisation& lin, cplx zeta) {
    MatrixXc a0 = MatrixXc::Zero(2, 2);
    std::vector<DelayTerm> terms;
    a0(0, 1) = zeta - 1.0;
    place(terms, a0, lin.gap, 1, 0, 1.0);
    place(terms, a0, lin.own, 1, 1, 1.0);
    place(terms, a0, lin.lead, 1, 1, zeta);
    cplx power = zeta;
    for (const auto& f : lin.further) {
        power *= zeta;  // zeta^{j+2}: the car j+2 ahead
        place(terms, a0, f, 1, 1, power);
    }
    return LinearDDE(a0, terms);
}

LinearDDE ring_mode0_dde(const Linearisation& lin) {
    MatrixXc a0 = MatrixXc::Zero(1, 1);
    std::vector<DelayTerm> terms;
    place(terms, a0, lin.own, 0, 0, 1.0);
    place(terms, a0, lin.lead, 0, 0, 1.0);
    for (const auto& f : lin.further) place(terms, a0, f, 0, 0, 1.0);
    return LinearDDE(a0, terms);
}

LinearDDE full_ring_dde(const Linearisation& lin, int cars) {
    if (cars < 2) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected N >= 2");
    const int n = 2 * cars;
    MatrixXc a0 = MatrixXc::Zero(n, n);
    std::vector<DelayTerm> terms;
    for (int i = 0; i < cars; ++i) {
        const int ahead = (i + cars - 1) % cars;
        const int s = 2 * i, v = 2 * i + 1, va = 2 * ahead + 1;
        a0(s, va) += 1.0;
        a0(s, v) -= 1.0;
        place(terms, a0, lin.gap, v, s, 1.0);
        place(terms, a0, lin.own, v, v, 1.0);
        place(terms, a0, lin.lead, v, va, 1.0);
        for (std::size_t j = 0; j < lin.further.size(); ++j) {
            const int far = ((i - 2 - static_cast<int>(j)) % cars + cars) % cars;
            place(terms, a0, lin.further[j], v, 2 * far + 1, 1.0);
        }
    }
    return LinearDDE(a0, terms);
}

namespace {

void add_quasi_term(std::vector<QuasiPolynomial::Term>& terms, double delay, int power, cplx coef) {
    if (coef == cplx(0.0)) return;
    auto it = std::find_if(terms.begin(), terms.end(), [&](const QuasiPolynomial::Term& t) { return t.delay == delay; });
    if (it == terms.end()) {
        terms.push_back({{}, delay});
        it = terms.end() - 1;
    }
    if (static_cast<int>(it->poly.size()) <= power) it->poly.resize(power + 1, cplx(0.0));
    it->poly[power] += coef;
}

}  // namespace

QuasiPolynomial ring_mode_characteristic(const Linearisation& lin, cplx zeta) {
    std::vector<QuasiPolynomial::Term> terms;
    for (const auto& t : lin.own.terms()) add_quasi_term(terms, t.delay, 1, -t.coef);
    for (const auto& t : lin.gap.terms()) add_quasi_term(terms, t.delay, 0, t.coef * (1.0 - zeta));
    for (const auto& t : lin.lead.terms()) add_quasi_term(terms, t.delay, 1, -zeta * t.coef);
    cplx power = zeta;
    for (const auto& f : lin.further) {
        power *= zeta;  // zeta^{j+2} for the car j+2 ahead
        for (const auto& t : f.terms()) add_quasi_term(terms, t.delay, 1, -power * t.coef);
    }
    return QuasiPolynomial(2, std::move(terms));
}

QuasiPolynomial ring_mode0_characteristic(const Linearisation& lin) {
    std::vector<QuasiPolynomial::Term> terms;
    for (const auto& t : lin.own.terms()) add_quasi_term(terms, t.delay, 0, -t.coef);
    for (const auto& t : lin.lead.terms()) add_quasi_term(terms, t.delay, 0, -t.coef);
    for (const auto& f : lin.further)
        for (const auto& t : f.terms()) add_quasi_term(terms, t.delay, 0, -t.coef);
    return QuasiPolynomial(1, std::move(terms));
}

QuasiPolynomial plant_characteristic(const Linearisation& lin) { return ring_mode_characteristic(lin, cplx(0.0)); }


}  // namespace ddemap
