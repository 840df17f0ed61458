#pragma once
/// \file expoly.hpp
/// Exponential polynomials E(s) = sum_j c_j e^{-s d_j} (real c_j, delays d_j >= 0): the
/// Laplace transforms of the delayed terms of a linearised car-following law.

#include <complex>
#include <vector>

namespace ddemap {

class ExpPoly {
public:
    struct Term {
        double coef = 0.0;
        double delay = 0.0;
    };
    ExpPoly() = default;
    /// Adds c e^{-s d}; merges equal delays, drops zero coefficients.
    ExpPoly& add(double coef, double delay);
    const std::vector<Term>& terms() const { return m_terms; }
    bool empty() const { return m_terms.empty(); }

    /// E(s) = sum c_j e^{-s d_j}
    std::complex<double> operator()(std::complex<double> s) const;
    /// E'(s) = -sum c_j d_j e^{-s d_j}
    std::complex<double> derivative(std::complex<double> s) const;
    /// Taylor coefficient at s = 0: E_n = sum_j c_j (-d_j)^n / n!
    double taylor(int n) const;
    /// sum_j |c_j| (a bound on |E(i w)| for real w)
    double abs_sum() const;
    double max_delay() const;
    /// The same terms in any order, coefficient for coefficient and delay for delay (bitwise equal
    /// doubles): used to group identical cars.
    bool operator==(const ExpPoly& other) const;
    bool operator!=(const ExpPoly& other) const { return !(*this == other); }

private:
    std::vector<Term> m_terms;
};

}  // namespace ddemap
