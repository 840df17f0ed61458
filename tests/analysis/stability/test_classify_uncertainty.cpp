#include <doctest/doctest.h>

#include <cmath>

#include "ddemap/analysis/stability/classify.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
using Cov = Eigen::Matrix<double, 5, 5>;
ParameterMap setting(double k1, double k2, double th, double tau) {
    return {{"k1", k1}, {"k2", k2}, {"th", th}, {"tau", tau}, {"eta", 10.0}};
}
double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }
/// 97.5 % quantile of the standard normal (tables; not computed by the code under test).
constexpr double z975 = 1.959963984540054;
}  // namespace

TEST_CASE("probability estimate: p, its standard error and the Wilson interval in closed form") {
    // k = 0 and k = n: the Wilson bounds reduce to z^2 / (n + z^2) and n / (n + z^2)
    const ProbabilityEstimate none = probability_estimate(0, 4000, 0.95);
    CHECK(none.p == 0.0);
    CHECK(none.standard_error == 0.0);
    CHECK(none.lower == 0.0);
    CHECK(none.upper == doctest::Approx(z975 * z975 / (4000 + z975 * z975)).epsilon(tol::coefficient_rel));
    const ProbabilityEstimate all = probability_estimate(4000, 4000, 0.95);
    CHECK(all.upper == 1.0);
    CHECK(all.lower == doctest::Approx(4000 / (4000 + z975 * z975)).epsilon(tol::coefficient_rel));
    CHECK(all.lower > 0.999);  // what "p > 0.999" rests on with the default 4000 samples
    // 30 of 100: the textbook example (Wilson 1927 / Agresti & Coull 1998) [0.2189, 0.3958]
    const ProbabilityEstimate mid = probability_estimate(30, 100, 0.95);
    CHECK(mid.p == doctest::Approx(0.3));
    CHECK(mid.standard_error == doctest::Approx(std::sqrt(0.3 * 0.7 / 100)));
    CHECK(mid.lower == doctest::Approx(0.2189).epsilon(2e-4));
    CHECK(mid.upper == doctest::Approx(0.3958).epsilon(2e-4));
    CHECK_THROWS_AS(probability_estimate(3, 2), std::invalid_argument);
    CHECK_THROWS_AS(probability_estimate(0, 0), std::invalid_argument);
    CHECK_THROWS_AS(probability_estimate(1, 2, 1.0), std::invalid_argument);
}

TEST_CASE("verdicts under a tiny covariance are the nominal verdicts (p = 0 or 1)") {
    UncertaintyOptions o;
    o.samples = 300;
    o.ring_samples = 20;
    const Cov tiny = 1e-14 * Cov::Identity();
    for (const auto& p : {setting(0.052, 0.338, 0.819, 0.948), setting(0.2, 0.9, 1.5, 0.3)}) {
        const Linearisation lin = make_model("ovrv", p)->linearise();
        const StringResult nominal = analyse_string(lin);
        const RingResult ring = analyse_ring(lin, 22);
        const VerdictUncertainty u = classify_with_uncertainty(p, tiny, 22, o);
        CHECK(u.status == Status::Converged);
        CHECK(u.samples == 300);
        CHECK(u.ring_samples == 20);
        CHECK(u.undecided == 0);
        CHECK(u.string_unstable.p == (nominal.string_stable ? 0.0 : 1.0));
        CHECK(u.ring_unstable.p == (ring.stable ? 0.0 : 1.0));
        CHECK(u.ring_unstable.trials == 20);
        // the intervals shrink onto the nominal margins (a shift of 1e-7 in the parameters)
        CHECK(u.c2.lower <= u.c2.median);
        CHECK(u.c2.median <= u.c2.upper);
        CHECK(std::abs(u.c2.median - nominal.lowfreq.c2) < 1e-5);
        CHECK(std::abs(u.sup_gamma_excess.median - (nominal.sup_gamma - 1.0)) < 1e-5);
        CHECK(std::abs(u.ring_abscissa.median - ring.spectral_abscissa) < 1e-5);
    }
}

TEST_CASE("p follows the normal CDF where the verdict is the sign of c2, linear in k2" * doctest::test_suite("slow")) {
    // OVRV: c2 = 2 k1 [k1 th^2/2 - 1 - tau k1 th + k2 (th - tau)], linear in k2. At k1 = 0.2,
    // th = 1.5, tau = 0.3 the string boundary near k2 = 0.72 is the low-frequency one (c2 = 0),
    // so with only k2 uncertain, P(string unstable) = P(c2 < 0) = Phi(-mean(c2) / sd(c2)).
    const double k1 = 0.2, th = 1.5, tau = 0.3, k2 = 0.74, sd = 0.02;
    Cov C = Cov::Zero();
    C(1, 1) = sd * sd;
    UncertaintyOptions o;
    o.ring_samples = 0;
    const VerdictUncertainty u = classify_with_uncertainty(setting(k1, k2, th, tau), C, 22, o);
    REQUIRE(u.status == Status::Converged);
    REQUIRE(u.samples == o.samples);
    const double a = k1 * th * th / 2.0 - 1.0 - tau * k1 * th;
    const double c2_mean = 2.0 * k1 * (a + k2 * (th - tau)), c2_sd = 2.0 * k1 * (th - tau) * sd;
    const double p_exact = normal_cdf(-c2_mean / c2_sd);
    // each sample's verdict is the sign of its c2 here (what makes the formula exact)
    int mismatches = 0;
    for (const auto& s : u.verdicts) {
        mismatches += (s.string_stable != (s.c2 > 0.0)) ? 1 : 0;
        CHECK(s.parameters.at("k1") == k1);  // the other parameters stay at their values
        CHECK(s.parameters.at("tau") == tau);
    }
    CHECK(mismatches == 0);
    const double se_exact = std::sqrt(p_exact * (1.0 - p_exact) / u.samples);
    CHECK(std::abs(u.string_unstable.p - p_exact) <= tol::monte_carlo_sigmas * se_exact);
    CHECK(u.string_unstable.standard_error == doctest::Approx(se_exact).epsilon(0.1));
    CHECK(u.string_unstable.lower < p_exact);
    CHECK(u.string_unstable.upper > p_exact);
    // the interval of c2: its normal quantiles mean -+ z sd; the Monte Carlo standard error of
    // a 2.5 % quantile of n samples is sqrt(q (1 - q) / n) / phi(z) sd
    const double q_se = std::sqrt(0.025 * 0.975 / u.samples) / (std::exp(-0.5 * z975 * z975) / std::sqrt(2.0 * M_PI)) * c2_sd;
    CHECK(std::abs(u.c2.lower - (c2_mean - z975 * c2_sd)) <= tol::monte_carlo_sigmas * q_se);
    CHECK(std::abs(u.c2.upper - (c2_mean + z975 * c2_sd)) <= tol::monte_carlo_sigmas * q_se);
    CHECK(u.ring_samples == 0);
    CHECK(u.ring_unstable.trials == 0);
}

TEST_CASE("the Wilson interval covers the exact p at its nominal rate over seeds" * doctest::test_suite("slow")) {
    const double k1 = 0.2, th = 1.5, tau = 0.3, k2 = 0.73, sd = 0.02;
    Cov C = Cov::Zero();
    C(1, 1) = sd * sd;
    const double a = k1 * th * th / 2.0 - 1.0 - tau * k1 * th;
    const double p_exact = normal_cdf(-(a + k2 * (th - tau)) / ((th - tau) * sd));
    UncertaintyOptions o;
    o.samples = 200;
    o.ring_samples = 0;
    const int seeds = 20;
    int covered = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
        o.seed = static_cast<unsigned long long>(seed);
        const ProbabilityEstimate e = classify_with_uncertainty(setting(k1, k2, th, tau), C, 22, o).string_unstable;
        covered += (e.lower <= p_exact && p_exact <= e.upper) ? 1 : 0;
    }
    CHECK(covered >= tol::wilson_coverage_min * seeds);
}

TEST_CASE("uncertainty sampling: fixed seed, thread count, domain and bad covariances") {
    Cov C = Cov::Zero();
    C(1, 1) = 1e-4;
    C(3, 3) = 0.01;  // tau = 0.05 -+ 0.1: about a third of the draws fall below 0
    C(1, 3) = C(3, 1) = 0.0005;
    UncertaintyOptions o;
    o.samples = 200;
    o.ring_samples = 10;
    const ParameterMap p = setting(0.2, 0.6, 1.5, 0.05);
    const VerdictUncertainty one = classify_with_uncertainty(p, C, 22, o, ExecutionPolicy{1, {}});
    const VerdictUncertainty two = classify_with_uncertainty(p, C, 22, o, ExecutionPolicy{2, {}});
    REQUIRE(one.verdicts.size() == two.verdicts.size());
    for (std::size_t j = 0; j < one.verdicts.size(); ++j) {
        CHECK(one.verdicts[j].parameters == two.verdicts[j].parameters);
        CHECK(one.verdicts[j].string_stable == two.verdicts[j].string_stable);
        CHECK(one.verdicts[j].ring_abscissa == two.verdicts[j].ring_abscissa);
        CHECK(one.verdicts[j].parameters.at("tau") >= 0.0);
    }
    CHECK(one.samples == 200);
    CHECK(one.draws > one.samples);  // draws with tau < 0 were rejected
    CHECK(one.string_unstable.successes == two.string_unstable.successes);
    // tau centred on 0: half the draws fall outside; with one draw allowed per sample the
    // shortfall is reported (not clamped onto tau = 0)
    Cov half = Cov::Zero();
    half(3, 3) = 0.01;
    UncertaintyOptions strict;
    strict.samples = 100;
    strict.ring_samples = 0;
    strict.max_draws_per_sample = 1;
    const VerdictUncertainty out = classify_with_uncertainty(setting(0.2, 0.6, 1.5, 0.0), half, 22, strict);
    CHECK(out.status == Status::BudgetExhausted);
    CHECK(out.draws == 100);
    CHECK(out.samples < 75);
    CHECK(out.samples > 25);
    for (const auto& v : out.verdicts) CHECK(v.parameters.at("tau") > 0.0);
    Cov neg = Cov::Zero();
    neg(0, 0) = -1e-4;
    CHECK_THROWS_AS(classify_with_uncertainty(p, neg, 22, o), std::invalid_argument);
    Cov nan = C;
    nan(2, 2) = std::nan("");
    CHECK_THROWS_AS(classify_with_uncertainty(p, nan, 22, o), std::invalid_argument);
    Cov asym = C;
    asym(0, 1) = 1e-3;
    CHECK_THROWS_AS(classify_with_uncertainty(p, asym, 22, o), std::invalid_argument);
    UncertaintyOptions bad;
    bad.samples = 0;
    CHECK_FALSE(bad.is_valid());
    CHECK_THROWS_AS(classify_with_uncertainty(p, C, 22, bad), std::invalid_argument);
}

TEST_CASE("classify: vehicles with a covariance get probabilities, the others not") {
    CalibratedVehicle with, without;
    with.name = "with";
    with.parameters = setting(0.052, 0.338, 0.819, 0.948);
    with.covariance = 1e-6 * Cov::Identity();
    with.has_covariance = true;
    without.name = "without";
    without.parameters = setting(0.2, 0.9, 1.5, 0.3);
    UncertaintyOptions o;
    o.samples = 100;
    o.ring_samples = 5;
    const auto rows = classify({with, without}, 22, o);
    REQUIRE(rows.size() == 2);
    CHECK(rows[0].has_uncertainty);
    CHECK(rows[0].uncertainty.samples == 100);
    CHECK(rows[0].uncertainty.string_unstable.p == 1.0);
    CHECK_FALSE(rows[1].has_uncertainty);
    CHECK(rows[1].string.string_stable);
}
