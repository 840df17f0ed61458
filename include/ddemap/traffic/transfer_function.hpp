#pragma once
/// \file transfer_function.hpp
/// Head-to-tail transfer function of a linearised car-following law:
///     Gamma(s) = N(s) / D(s),  N(s) = gap(s) + s lead(s),  D(s) = s^2 - s own(s) + gap(s)
/// (for OVRV: Gamma = (k1 + k2 s) e^{-s tau} / (s^2 + (k1 th + k2) s + k1 e^{-s tau})), and the plant
/// (one car behind a lead at constant speed), whose characteristic function is D.

#include <complex>
#include <vector>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/traffic/model.hpp"

namespace ddemap {

/// Gamma(s) and its derivative from a Linearisation.
class TransferFunction {
public:
    explicit TransferFunction(Linearisation lin);
    cplx numerator(cplx s) const;
    cplx denominator(cplx s) const;
    /// N and D together (one exponential per distinct delay).
    void evaluate(cplx s, cplx& n, cplx& d) const;
    /// N, D and their derivatives N' = gap' + lead + s lead', D' = 2 s - own - s own' + gap'
    /// (the same exponentials).
    void evaluate(cplx s, cplx& n, cplx& d, cplx& dn, cplx& dd) const;
    cplx operator()(cplx s) const {
        cplx n, d;
        evaluate(s, n, d);
        return n / d;
    }
    /// Gamma'(s) = (N' D - N D') / D^2
    cplx derivative(cplx s) const;
    /// |Gamma(i w)|^2
    double gain2(double w) const { return std::norm((*this)(cplx(0.0, w))); }
    /// d/dw |Gamma(i w)|^2 = 2 Re( conj(Gamma(i w)) i Gamma'(i w) )
    double gain2_derivative(double w) const;
    /// 1 - |Gamma(i w)|^2 = w^2 q(w) / |D(i w)|^2 without cancellation at small w:
    /// D - N = s (s - own - lead), so |D|^2 - |N|^2 = Re((D - N) conj(D + N)) = w^2 q(w) with
    ///     q(w) = Re(A) Im(B)/w - Re(B) Im(A)/w,  A = i w - own(i w) - lead(i w),  B = D + N,
    /// where Im(A)/w and Im(B)/w are formed from sin(w tau)/w (q(w) -> c2 as w -> 0). The
    /// rounding error of q is at most `q_noise` (about eps times the sizes of its terms), not
    /// eps |D|^2 / w^2 as for 1 - |N|^2/|D|^2. q and q_noise are returned when asked.
    double attenuation(double w, double* q = nullptr, double* q_noise = nullptr) const;
    const Linearisation& linearisation() const { return m_lin; }

    /// N, D, N' and D' at lambda = sigma + i s for many s on one vertical line Re lambda = sigma:
    /// the factors e^{-sigma d} of the delays are formed once, and each point costs one sin/cos per
    /// distinct nonzero delay and real arithmetic,
    ///     e^{-lambda d} = e^{-sigma d} (cos(s d) - i sin(s d)),
    ///     N = gap + lambda lead, D = lambda^2 - lambda own + gap,
    ///     N' = gap' + lead + lambda lead', D' = 2 lambda - own - lambda own' + gap'
    /// (' = d/dlambda; the same values as evaluate() up to rounding).
    class Line {
    public:
        Line(const TransferFunction& tf, double sigma);
        void operator()(double s, cplx& n, cplx& d, cplx& dn, cplx& dd) const;
        double sigma() const { return m_sigma; }

    private:
        struct Term {
            double delay, gap, own, lead;  // coefficients times e^{-sigma delay}
        };
        double m_sigma;
        double m_gap0 = 0.0, m_own0 = 0.0, m_lead0 = 0.0;  // the undelayed terms
        std::vector<Term> m_terms;                          // the delayed ones
    };

private:
    Linearisation m_lin;
    struct DelayGroup {
        double delay;
        double gap, own, lead;  // coefficients of e^{-s delay}
    };
    std::vector<DelayGroup> m_groups;
    double m_abs_own = 0.0, m_abs_lead = 0.0, m_abs_gap = 0.0;  // sums of |coefficient| over the delays
};

/// The plant: one car behind a lead car held at its equilibrium speed,
/// x = (s, v): s' = -v, v' = gap*s + own*v. Its characteristic function is D(lambda).
LinearDDE plant_dde(const Linearisation& lin);

}  // namespace ddemap
