#pragma once
// Complex Lambert W, branch k, by Halley's iteration from the asymptotic expansion
// (Corless, Gonnet, Hare, Jeffrey, Knuth, Adv. Comput. Math. 5 (1996) 329-359).
// Independent of ddemap: used as the analytic reference for x'(t) = a x(t - tau).
#include <cmath>
#include <complex>

namespace ddemap::test {

inline std::complex<double> lambert_w(std::complex<double> z, int k) {
    using C = std::complex<double>;
    const C two_pi_i(0.0, 2.0 * M_PI * k);
    C w;
    const double branch_dist = std::abs(z + std::exp(-1.0));
    if ((k == 0 || k == -1) && branch_dist < 0.3) {
        // series about the branch point -1/e
        C p = std::sqrt(2.0 * (std::exp(1.0) * z + 1.0));
        if (k == -1) p = -p;
        if (k == -1 && z.imag() == 0.0 && z.real() < -std::exp(-1.0)) p = std::conj(p);
        w = -1.0 + p - p * p / 3.0 + 11.0 / 72.0 * p * p * p;
    } else if (k == 0 && std::abs(z) < 1.0) {
        w = z - z * z + 1.5 * z * z * z;
    } else {
        const C l1 = std::log(z) + two_pi_i;
        w = l1 - std::log(l1);
    }
    for (int it = 0; it < 100; ++it) {
        const C ew = std::exp(w);
        const C f = w * ew - z;
        const C wp1 = w + 1.0;
        const C step = f / (ew * wp1 - (w + 2.0) * f / (2.0 * wp1));
        w -= step;
        if (std::abs(step) <= 1e-16 * std::max(1.0, std::abs(w))) break;
    }
    return w;
}

}  // namespace ddemap::test
