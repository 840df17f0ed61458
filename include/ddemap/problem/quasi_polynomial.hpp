#pragma once
/// \file quasi.hpp
/// Scalar characteristic functions of retarded type,
///     f(lambda) = lambda^n + sum_j P_j(lambda) e^{-lambda d_j},  deg P_j < n,
/// with complex coefficients: a ring mode (n = 2), mode 0 without its trivial root (n = 1) and
/// the plant denominator D (n = 2). Used where speed matters (sweeps, continuation): Newton on
/// f, and an exact count of the zeros right of a vertical line by the argument principle, which
/// certifies that a root found by Newton is the rightmost one.

#include <complex>
#include <vector>

#include "ddemap/core/types.hpp"

namespace ddemap {

class QuasiPolynomial {
public:
    struct Term {
        std::vector<std::complex<double>> poly;  ///< poly[k]: coefficient of lambda^k (k < n)
        double delay = 0.0;
    };
    /// f = lambda^degree + sum of terms; throws std::invalid_argument unless degree is 1 or 2
    /// and every term's polynomial has degree < n (retarded type).
    QuasiPolynomial(int degree, std::vector<Term> terms);

    int degree() const { return m_degree; }
    /// True when every coefficient is real (zeros then come in conjugate pairs).
    bool is_real() const;
    std::complex<double> operator()(std::complex<double> lambda) const;
    /// f and f' at lambda.
    void evaluate(std::complex<double> lambda, std::complex<double>& f, std::complex<double>& fp) const;
    /// Newton from `lambda` (in place); true when converged to |step| <= 4 eps max(1, |lambda|).
    bool newton(std::complex<double>& lambda, int max_iterations = 60) const;
    /// Number of zeros with Re(lambda) > sigma, by the argument principle along the line
    /// Re(lambda) = sigma closed by a half circle on which f ~ (lambda - sigma)^n; -1 when the
    /// count cannot be decided (a zero on or extremely close to the line).
    int zeros_right_of(double sigma) const;

private:
    /// f and f' at lambda with e^{-Re(lambda) d_j} given per term (`magnitudes`, in term order):
    /// on a vertical line they do not change, so a line is sampled without an exp per term.
    void evaluate(std::complex<double> lambda, const double* magnitudes, std::complex<double>& f,
                  std::complex<double>& fp) const;
    int m_degree;
    std::vector<Term> m_terms;
    double m_max_delay = 0.0;
};

}  // namespace ddemap
