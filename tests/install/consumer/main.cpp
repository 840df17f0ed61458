// Uses an installed ddemap: the rightmost characteristic roots of the scalar DDE
//     x'(t) = a x(t - tau),  a = -1, tau = 1,
// whose roots are lambda_k = W_k(a tau) / tau (Lambert W). The rightmost pair comes from the
// principal branch: W_0(-1) = -0.318131505204764 +- 1.337235701430689 i (tabulated). Exit 0
// when ddemap finds that pair, converged, each root solving lambda + exp(-lambda) = 0
// (tolerance tol::root_abs of tests/tolerances.hpp).
#include <cmath>
#include <complex>
#include <cstdio>

#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/roots.hpp"
#include "tolerances.hpp"

int main() {
    using ddemap::cplx;
    ddemap::MatrixXc a0 = ddemap::MatrixXc::Zero(1, 1), a1(1, 1);
    a1(0, 0) = -1.0;
    const ddemap::LinearDDE dde(a0, {ddemap::DelayTerm{a1, 1.0}});
    ddemap::RootOptions options;
    options.count = 4;
    const ddemap::RootResult r = ddemap::rightmost_roots(dde, options);
    if (r.status != ddemap::Status::Converged || r.roots.size() < 2) {
        std::printf("not converged: %s\n", r.message.c_str());
        return 1;
    }
    const cplx w0(-0.318131505204764, 1.337235701430689);
    int bad = 0;
    for (int i = 0; i < 2; ++i) {
        const cplx l = r.roots[static_cast<std::size_t>(i)].value;
        const double to_closed_form = std::min(std::abs(l - w0), std::abs(l - std::conj(w0)));
        const double residual = std::abs(l + std::exp(-l));
        std::printf("root %d: %.15f %+.15fi  |lambda - W_0(-1)| = %.1e  |lambda + exp(-lambda)| = %.1e\n", i + 1, l.real(), l.imag(),
                    to_closed_form, residual);
        if (!(to_closed_form < ddemap::test::tol::root_abs && residual < ddemap::test::tol::root_abs)) ++bad;
    }
    std::printf("spectral abscissa %.15f (method %s, degree %d)\n", r.spectral_abscissa(), r.method_used.c_str(), r.degree);
    return bad == 0 && std::abs(r.spectral_abscissa() - w0.real()) < ddemap::test::tol::root_abs ? 0 : 1;
}
