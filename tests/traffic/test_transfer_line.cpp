// TransferFunction::Line (N, D and their derivatives along one vertical line, as the winding
// tables sample them) against TransferFunction::evaluate at random points.
#include <doctest/doctest.h>

#include "tolerances.hpp"

#include <cmath>
#include <random>

#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace tol = ddemap::test::tol;

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

/// A law with several delays in every part (and undelayed terms), to exercise the grouping.
Linearisation several_delays() {
    Linearisation lin;
    lin.gap.add(0.3, 0.0).add(0.4, 0.5).add(-0.1, 1.3);
    lin.own.add(-0.9, 0.0).add(-0.2, 0.5).add(0.05, 2.0);
    lin.lead.add(0.6, 0.5).add(0.1, 1.3).add(0.2, 0.0);
    return lin;
}

}  // namespace

TEST_CASE("TransferFunction::Line equals TransferFunction::evaluate on vertical lines (random lines and points, several delays)") {
    std::vector<Linearisation> lins{several_delays(),
                                    make_model("ovrv", {{"k1", 0.6}, {"k2", 0.3}, {"th", 1.5}, {"tau", 0.5}})->linearise(),
                                    make_model("ovrv", {{"k1", 0.2}, {"k2", 0.9}, {"th", 0.5}, {"tau", 0.8}})->linearise(),
                                    make_model("idm", {{"a", 1.0}, {"b", 1.5}, {"v0", 32.0}, {"th", 1.2}, {"tau", 0.6}, {"eta", 2.0}, {"speed", 15.0}})->linearise()};
    std::mt19937 rng(1213);
    std::uniform_real_distribution<double> sig(-1.0, 1.0), im(0.0, 30.0);
    int checked = 0;
    for (const auto& lin : lins) {
        const TransferFunction tf(lin);
        double sizes = 0.0;
        for (const auto* e : {&lin.gap, &lin.own, &lin.lead})
            for (const auto& t : e->terms()) sizes += std::abs(t.coef) * (1.0 + t.delay);
        for (int line = 0; line < 12; ++line) {
            const double sigma = line == 0 ? 0.0 : sig(rng);  // the imaginary axis among them
            const TransferFunction::Line on(tf, sigma);
            CHECK(on.sigma() == sigma);
            for (int k = 0; k < 40; ++k) {
                const double s = k == 0 ? 0.0 : im(rng);
                const cplx lambda(sigma, s);
                cplx n, d, dn, dd, n2, d2, dn2, dd2;
                on(s, n, d, dn, dd);
                tf.evaluate(lambda, n2, d2, dn2, dd2);
                // the sizes of the terms, with e^{-sigma d} <= e^{|sigma| d_max}
                const double al = std::abs(lambda);
                const double scale = (1.0 + al) * (1.0 + al) * (1.0 + sizes) * std::exp(std::abs(sigma) * lin.max_delay());
                CAPTURE(sigma);
                CAPTURE(s);
                CHECK(std::abs(n - n2) <= tol::line_vs_evaluate * scale);
                CHECK(std::abs(d - d2) <= tol::line_vs_evaluate * scale);
                CHECK(std::abs(dn - dn2) <= tol::line_vs_evaluate * scale);
                CHECK(std::abs(dd - dd2) <= tol::line_vs_evaluate * scale);
                if (s == 0.0) {  // real coefficients: real on the real axis, exactly
                    CHECK(n.imag() == 0.0);
                    CHECK(d.imag() == 0.0);
                }
                ++checked;
            }
        }
    }
    CHECK(checked == 4 * 12 * 40);
}

TEST_SUITE_END();
