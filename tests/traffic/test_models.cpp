#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "ddemap/traffic/model.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
/// Partials of F by central differences at the equilibrium (s*(v), v, v).
void finite_differences(const CarModel& m, double& fs, double& fv, double& fl) {
    const double v = m.operating_speed();
    const double s = m.equilibrium_gap(v);
    const double h = 1e-5;
    fs = (m.acceleration(s + h, v, {v}) - m.acceleration(s - h, v, {v})) / (2 * h);
    fv = (m.acceleration(s, v + h, {v}) - m.acceleration(s, v - h, {v})) / (2 * h);
    fl = (m.acceleration(s, v, {v + h}) - m.acceleration(s, v, {v - h})) / (2 * h);
}
double single(const ExpPoly& e, double delay) {
    REQUIRE(e.terms().size() == 1);
    CHECK(e.terms()[0].delay == delay);
    return e.terms()[0].coef;
}
}  // namespace

TEST_CASE("linearisations match finite differences of the law at equilibrium") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
        const ParameterMap ovrv_p = {{"k1", u(rng)}, {"k2", u(rng)}, {"th", 3 * u(rng)}, {"tau", u(rng)},
                                     {"eta", 5 + 10 * u(rng)}, {"speed", 30 * u(rng)}};
        const ParameterMap idm_p = {{"a", 0.5 + u(rng)}, {"b", 1 + u(rng)}, {"v0", 30 + 5 * u(rng)},
                                    {"th", 0.5 + u(rng)}, {"tau", u(rng)}, {"eta", 1 + 3 * u(rng)},
                                    {"speed", 25 * u(rng)}};
        for (const auto& m : {make_model("ovrv", ovrv_p), make_model("idm", idm_p)}) {
            CAPTURE(m->name());
            const double v = m->operating_speed();
            CHECK(std::abs(m->acceleration(m->equilibrium_gap(v), v, {v})) < 1e-12);
            double fs, fv, fl;
            finite_differences(*m, fs, fv, fl);
            const Linearisation l = m->linearise();
            CHECK(single(l.gap, m->delay()) == doctest::Approx(fs).epsilon(tol::finite_difference));
            CHECK(single(l.own, 0.0) == doctest::Approx(fv).epsilon(tol::finite_difference));
            if (std::abs(fl) > 1e-12) CHECK(single(l.lead, m->delay()) == doctest::Approx(fl).epsilon(tol::finite_difference));
        }
    }
}

TEST_CASE("OVRV partials are the paper's: f_s = k1, f_v = -(k1 th + k2), f_l = k2") {
    const auto m = make_model("ovrv", {{"k1", 0.2}, {"k2", 0.3}, {"th", 1.5}, {"tau", 0.1}});
    const Linearisation l = m->linearise();
    CHECK(single(l.gap, 0.1) == 0.2);
    CHECK(single(l.own, 0.0) == -(0.2 * 1.5 + 0.3));
    CHECK(single(l.lead, 0.1) == 0.3);
}

TEST_CASE("model parameters are validated with a message naming the value") {
    CHECK_THROWS_WITH_AS(make_model("ovrv", {{"k1", -0.5}, {"k2", 0.2}, {"th", 1}, {"tau", 0.1}}),
                         "k1 = -0.5: expected a value >= 0 [1/s^2]", std::invalid_argument);
    CHECK_THROWS_WITH_AS(make_model("ovrv", {{"k1", 0.5}, {"k2", 0.2}, {"th", 1}}),
                         "model ovrv needs tau [s] (sensing delay)", std::invalid_argument);
    CHECK_THROWS_AS(make_model("ovrv", {{"k1", INFINITY}, {"k2", 0.2}, {"th", 1}, {"tau", 0.1}}), std::invalid_argument);
    CHECK_THROWS_AS(make_model("ovrv", {{"k1", 0.1}, {"k2", 0.2}, {"th", 1}, {"tau", 0.1}, {"v0", 3}}), std::invalid_argument);
    CHECK_THROWS_AS(make_model("idm", {{"th", 1}, {"tau", 0.1}, {"speed", 40}}), std::invalid_argument);
    CHECK_THROWS_AS(make_model("bando", {}), std::invalid_argument);
    // valid edge cases
    CHECK_NOTHROW(make_model("ovrv", {{"k1", 0.0}, {"k2", 0.2}, {"th", 1}, {"tau", 0.0}}));
}

TEST_CASE("CCC is a two-leader law: distinct speeds of the car ahead and the car two ahead") {
    const double k1 = 0.2, k2 = 0.4, k3 = 0.25, th = 1.3, tau = 0.3, tau2 = 0.15, eta = 7.0;
    const auto m = make_model("ccc", {{"k1", k1}, {"k2", k2}, {"k3", k3}, {"th", th}, {"tau", tau}, {"tau2", tau2}, {"eta", eta}});
    CHECK(m->leaders() == 2);
    CHECK(m->inputs() == 4);
    const double s = 31.0, v = 18.0, v1 = 19.5, v2 = 16.25;
    CHECK(m->acceleration(s, v, {v1, v2}) == doctest::Approx(k1 * (s - eta - th * v) + k2 * (v1 - v) + k3 * (v2 - v)).epsilon(1e-15));
    // the car two ahead matters on its own
    CHECK(m->acceleration(s, v, {v1, v1}) != m->acceleration(s, v, {v1, v2}));
    CHECK_THROWS_WITH_AS(m->acceleration(s, v, {v1}), "model ccc uses the speeds of 2 cars ahead; 1 given", std::invalid_argument);
    const std::vector<double> d = m->input_delays();
    CHECK(d == std::vector<double>{tau, 0.0, tau, tau2});
    // the exact partials at an arbitrary (non-equilibrium) point are the coefficients of the law
    const Linearisation l = m->linearise_at(s, v, {v1, v2});
    CHECK(single(l.gap, tau) == k1);
    CHECK(single(l.own, 0.0) == doctest::Approx(-(k1 * th + k2 + k3)).epsilon(1e-15));
    CHECK(single(l.lead, tau) == k2);
    REQUIRE(l.further.size() == 1);
    CHECK(single(l.further[0], tau2) == k3);
}

TEST_CASE("IDM: the dual-number partials equal the closed-form partials") {
    const double a = 1.2, b = 1.7, v0 = 33.0, delta = 4.0, th = 1.4, eta = 2.5, tau = 0.4;
    for (double v : {0.0, 5.0, 20.0, 31.0}) {
        CAPTURE(v);
        const auto m = make_model("idm", {{"a", a}, {"b", b}, {"v0", v0}, {"delta", delta}, {"th", th}, {"eta", eta}, {"tau", tau}, {"speed", v}});
        const double s = m->equilibrium_gap(v);
        const double sd = eta + th * v, sab = 2.0 * std::sqrt(a * b);
        const double f_s = 2.0 * a * sd * sd / (s * s * s);
        const double dpow = v > 0.0 ? delta * std::pow(v, delta - 1.0) / std::pow(v0, delta) : 0.0;
        const double f_v = -a * (dpow + 2.0 * sd / (s * s) * (th + v / sab));
        const double f_l = a * 2.0 * sd / (s * s) * (v / sab);
        const Linearisation l = m->linearise();
        CHECK(single(l.gap, tau) == doctest::Approx(f_s).epsilon(1e-13));
        CHECK(single(l.own, 0.0) == doctest::Approx(f_v).epsilon(1e-13));
        if (v > 0.0) CHECK(single(l.lead, tau) == doctest::Approx(f_l).epsilon(1e-13));
        else CHECK(l.lead.empty());
    }
}

TEST_SUITE_END();
