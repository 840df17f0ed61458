#include "ddemap/problem/expoly.hpp"

#include <algorithm>
#include <cmath>

namespace ddemap {

ExpPoly& ExpPoly::add(double coef, double delay) {
    if (coef == 0.0) return *this;
    for (auto& t : m_terms) {
        if (t.delay == delay) {
            t.coef += coef;
            if (t.coef == 0.0) m_terms.erase(m_terms.begin() + (&t - m_terms.data()));
            return *this;
        }
    }
    m_terms.push_back({coef, delay});
    return *this;
}

std::complex<double> ExpPoly::operator()(std::complex<double> s) const {
    std::complex<double> v = 0.0;
    for (const auto& t : m_terms) v += t.delay == 0.0 ? t.coef : t.coef * std::exp(-s * t.delay);
    return v;
}

std::complex<double> ExpPoly::derivative(std::complex<double> s) const {
    std::complex<double> v = 0.0;
    for (const auto& t : m_terms)
        if (t.delay != 0.0) v -= t.coef * t.delay * std::exp(-s * t.delay);
    return v;
}

double ExpPoly::taylor(int n) const {
    double v = 0.0;
    for (const auto& t : m_terms) {
        double p = t.coef;
        for (int k = 1; k <= n; ++k) p *= -t.delay / k;
        v += p;
    }
    return v;
}

double ExpPoly::abs_sum() const {
    double v = 0.0;
    for (const auto& t : m_terms) v += std::abs(t.coef);
    return v;
}

double ExpPoly::max_delay() const {
    double d = 0.0;
    for (const auto& t : m_terms) d = std::max(d, t.delay);
    return d;
}

bool ExpPoly::operator==(const ExpPoly& other) const {
    if (m_terms.size() != other.m_terms.size()) return false;
    // delays are distinct after merging, so each term has at most one partner, in any order
    for (const Term& t : m_terms) {
        bool found = false;
        for (const Term& u : other.m_terms) found = found || (u.delay == t.delay && u.coef == t.coef);
        if (!found) return false;
    }
    return true;
}

}  // namespace ddemap
