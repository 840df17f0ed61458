#include <doctest/doctest.h>

#include <cmath>
#include <type_traits>
#include <stdexcept>

#include "ddemap/core/dual.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/roots.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

/// Mackey-Glass: x' = beta x(t - tau) / (1 + x(t - tau)^n) - gamma x; parameters beta, gamma, n, tau.
class MackeyGlass final : public NonlinearDDEOf<MackeyGlass> {
public:
    MackeyGlass(double beta, double gamma, double n, double tau)
        : NonlinearDDEOf({"beta", "gamma", "n", "tau"}, {beta, gamma, n, tau}) {}
    int dimension() const override { return 1; }
    int delay_count() const override { return 1; }
    std::vector<double> delays(const std::vector<double>& p) const override { return {p[3]}; }
    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        const T& xd = u[1];
        out[0] = p[0] * xd / (1.0 + pow(xd, p[2])) - p[1] * u[0];
    }
};

/// x' = -x + a tanh(x(t - c a)): a delay that depends on a parameter.
class TanhFeedback final : public NonlinearDDEOf<TanhFeedback> {
public:
    TanhFeedback(double a, double c) : NonlinearDDEOf({"a", "c"}, {a, c}) {}
    int dimension() const override { return 1; }
    int delay_count() const override { return 1; }
    std::vector<double> delays(const std::vector<double>& p) const override { return {p[1] * p[0]}; }
    template <class T>
    void rhs(const T* u, const T* p, T* out) const { out[0] = -u[0] + p[0] * tanh(u[1]); }
};

/// A 2-dimensional system with two delays: x1' = -x1 x2 + k sin(x2(t - 1)), x2' = exp(x1(t - 0.5)) - x2 x1(t - 1).
class Pair final : public NonlinearDDEOf<Pair> {
public:
    Pair() : NonlinearDDEOf({"k"}, {0.7}) {}
    int dimension() const override { return 2; }
    int delay_count() const override { return 2; }
    std::vector<double> delays(const std::vector<double>&) const override { return {1.0, 0.5}; }
    template <class T>
    void rhs(const T* u, const T* p, T* out) const {
        const T* x0 = u;      // x(t)
        const T* x1 = u + 2;  // x(t - 1)
        const T* x2 = u + 4;  // x(t - 0.5)
        out[0] = -x0[0] * x0[1] + p[0] * sin(x1[1]);
        out[1] = exp(x2[0]) - x0[1] * x1[0];
    }
};

}  // namespace

TEST_CASE("dual numbers give the analytic first derivatives") {
    const double x = 0.83;
    const Dual<double> d = variable(x);
    CHECK(exp(sin(d) * d).deriv == doctest::Approx(std::exp(std::sin(x) * x) * (std::cos(x) * x + std::sin(x))).epsilon(1e-14));
    CHECK((1.0 / (1.0 + pow(d, 3.5))).deriv == doctest::Approx(-3.5 * std::pow(x, 2.5) / std::pow(1.0 + std::pow(x, 3.5), 2)).epsilon(1e-14));
    CHECK(tanh(2.0 * d - 1.0).deriv == doctest::Approx(2.0 / std::pow(std::cosh(2 * x - 1), 2)).epsilon(1e-14));
    CHECK((sqrt(d) * log(d) - d / (d * d + 2.0)).deriv ==
          doctest::Approx(std::log(x) / (2 * std::sqrt(x)) + 1 / std::sqrt(x) - (2.0 - x * x) / std::pow(x * x + 2.0, 2)).epsilon(1e-14));
    CHECK(pow(d, d).deriv == doctest::Approx(std::pow(x, x) * (std::log(x) + 1.0)).epsilon(1e-14));
    CHECK(pow(d, 4.0).value == doctest::Approx(std::pow(x, 4)).epsilon(1e-15));
    // at 0 the derivative of v^4 is 0, not NaN
    CHECK(pow(variable(0.0), 4.0).deriv == 0.0);
}

TEST_CASE("nested dual numbers give second and third derivatives") {
    // g(x) = x^3 sin(x): g'' = 6 x sin x + 6 x^2 cos x - x^3 sin x
    const double x = 1.3;
    using D2 = Dual<Dual<double>>;
    const D2 d(Dual<double>(x, 1.0), Dual<double>(1.0, 0.0));
    const D2 g = d * d * d * sin(d);
    CHECK(g.value.value == doctest::Approx(x * x * x * std::sin(x)).epsilon(1e-15));
    CHECK(g.deriv.deriv == doctest::Approx(6 * x * std::sin(x) + 6 * x * x * std::cos(x) - x * x * x * std::sin(x)).epsilon(1e-14));
    // third: exp(2x): 8 exp(2x)
    using D3 = Dual<D2>;
    const D3 e(D2(Dual<double>(x, 1.0), Dual<double>(1.0, 0.0)), D2(Dual<double>(1.0, 0.0), Dual<double>(0.0, 0.0)));
    CHECK(exp(2.0 * e).deriv.deriv.deriv == doctest::Approx(8 * std::exp(2 * x)).epsilon(1e-14));
    // fourth and fifth through a system (NonlinearDDE::Dual4, Dual5, the levels the second
    // Lyapunov coefficient needs): f = exp(2 x) tanh(x), mixed partials d^k/dx^k along x in every
    // direction, against the Leibniz sums of the closed-form derivatives
    const ExpressionSystem sys({"x"}, {}, {}, {"exp(2*x)*tanh(x)"});
    using D4 = NonlinearDDE::Dual4;
    using D5 = NonlinearDDE::Dual5;
    auto seeded = [&](auto level) {
        using T = decltype(level);
        if constexpr (std::is_same_v<T, D4>) return D4(D3(D2(Dual<double>(x, 1.0), Dual<double>(1.0, 0.0)), D2(Dual<double>(1.0, 0.0), Dual<double>(0.0, 0.0))), D3(1.0));
        else return D5(D4(D3(D2(Dual<double>(x, 1.0), Dual<double>(1.0, 0.0)), D2(Dual<double>(1.0, 0.0), Dual<double>(0.0, 0.0))), D3(1.0)), D4(1.0));
    };
    // t = tanh x: t' = 1 - t^2, t'' = -2 t t', t''' = -2 (t'^2 + t t''), t'''' = -2 (3 t' t'' + t t''')
    const double t = std::tanh(x), t1 = 1 - t * t, t2 = -2 * t * t1, t3 = -2 * (t1 * t1 + t * t2), t4 = -2 * (3 * t1 * t2 + t * t3);
    const double t5 = -2 * (3 * t2 * t2 + 4 * t1 * t3 + t * t4);
    const double ts[] = {t, t1, t2, t3, t4, t5};
    auto leibniz = [&](int k) {
        double sum = 0.0, binom = 1.0;
        for (int j = 0; j <= k; ++j) {
            sum += binom * std::pow(2.0, k - j) * std::exp(2 * x) * ts[j];
            binom = binom * (k - j) / (j + 1);
        }
        return sum;
    };
    D4 u4 = seeded(D4()), o4;
    sys.evaluate(&u4, nullptr, &o4);
    CHECK(o4.deriv.deriv.deriv.deriv == doctest::Approx(leibniz(4)).epsilon(1e-13));
    D5 u5 = seeded(D5()), o5;
    sys.evaluate(&u5, nullptr, &o5);
    CHECK(o5.deriv.deriv.deriv.deriv.deriv == doctest::Approx(leibniz(5)).epsilon(1e-13));
}

TEST_CASE("Mackey-Glass: linearisation at the positive equilibrium is the analytic one") {
    const double beta = 2.0, gamma = 1.0, n = 9.65, tau = 2.0;
    MackeyGlass mg(beta, gamma, n, tau);
    const double xs = std::pow(beta / gamma - 1.0, 1.0 / n);
    const Eigen::VectorXd eq = Eigen::VectorXd::Constant(1, xs);
    CHECK(equilibrium_residual(mg, eq) < 1e-14);
    const LinearDDE lin = linearise(mg, eq);
    const double xn = std::pow(xs, n);
    CHECK(lin.a0()(0, 0).real() == doctest::Approx(-gamma).epsilon(1e-14));
    REQUIRE(lin.delayed().size() == 1);
    CHECK(lin.delayed()[0].delay == tau);
    CHECK(lin.delayed()[0].matrix(0, 0).real() == doctest::Approx(beta * (1.0 + (1.0 - n) * xn) / ((1.0 + xn) * (1.0 + xn))).epsilon(1e-13));
    // df/dbeta = x*/(1 + x*^n), df/dn = -beta x* x*^n log x* / (1 + x*^n)^2
    const Eigen::VectorXd u = mg.stack_constant(eq);
    CHECK(mg.parameter_derivative(u, "beta")[0] == doctest::Approx(xs / (1.0 + xn)).epsilon(1e-14));
    CHECK(mg.parameter_derivative(u, "n")[0] == doctest::Approx(-beta * xs * xn * std::log(xs) / ((1.0 + xn) * (1.0 + xn))).epsilon(1e-13));
    CHECK(mg.parameter_derivative(u, "gamma")[0] == doctest::Approx(-xs).epsilon(1e-14));
    CHECK(mg.parameter_derivative(u, "tau")[0] == 0.0);
    // the delay follows its parameter
    mg.set_parameter("tau", 0.5);
    CHECK(linearise(mg, eq).delayed()[0].delay == 0.5);
    CHECK(mg.parameters().at("tau") == 0.5);
}

TEST_CASE("tanh feedback: A_0 = -1, A_1 = a at 0, and the roots are those of the scalar DDE") {
    // x' = -x + a x(t - tau) with a = -2: Hopf at w = sqrt(a^2 - 1), tau = arccos(1/a) / w
    const double a = -2.0, w = std::sqrt(a * a - 1.0), tau_h = std::acos(1.0 / a) / w;
    TanhFeedback sys(a, tau_h / a);
    const LinearDDE lin = linearise(sys, Eigen::VectorXd::Zero(1));
    CHECK(lin.a0()(0, 0).real() == -1.0);
    REQUIRE(lin.delayed().size() == 1);
    CHECK(lin.delayed()[0].matrix(0, 0).real() == a);
    CHECK(lin.delayed()[0].delay == doctest::Approx(tau_h).epsilon(1e-15));
    RootOptions ro;
    ro.count = 2;
    const RootResult r = rightmost_roots(lin, ro);
    REQUIRE(r.roots.size() >= 1);
    CHECK(std::abs(r.roots[0].value.real()) < 1e-10);
    CHECK(std::abs(std::abs(r.roots[0].value.imag()) - w) < 1e-10);
}

TEST_CASE("a two-dimensional system with two delays: every block against the hand derivative") {
    Pair sys;
    Eigen::VectorXd u(6);
    u << 0.3, -0.4, 0.2, 0.9, -0.6, 0.1;
    const std::vector<Eigen::MatrixXd> a = sys.jacobians(u);
    Eigen::MatrixXd a0(2, 2), a1(2, 2), a2(2, 2);
    a0 << -u[1], -u[0], 0.0, -u[2];
    a1 << 0.0, 0.7 * std::cos(u[3]), -u[1], 0.0;
    a2 << 0.0, 0.0, std::exp(u[4]), 0.0;
    CHECK((a[0] - a0).norm() < 1e-15);
    CHECK((a[1] - a1).norm() < 1e-15);
    CHECK((a[2] - a2).norm() < 1e-15);
    CHECK((sys.jacobian(u, 1) - a1).norm() < 1e-15);
    CHECK(sys.parameter_derivative(u, "k")[0] == std::sin(u[3]));
    // equal delays merge in the LinearDDE
    const LinearDDE lin = linearise(sys, Eigen::Vector2d(0.1, 0.2));
    CHECK(lin.delayed().size() == 2);
}

TEST_CASE("nonlinear DDE inputs are validated in API terms") {
    MackeyGlass mg(2.0, 1.0, 10.0, 1.0);
    CHECK_THROWS_WITH_AS(linearise(mg, Eigen::VectorXd::Zero(2)), "the equilibrium has 2 entries: expected the dimension 1", std::invalid_argument);
    CHECK_THROWS_WITH_AS(linearise(mg, Eigen::VectorXd::Constant(1, NAN)), "the equilibrium has a non-finite entry: expected finite values",
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(mg.f(Eigen::VectorXd::Zero(3)),
                         "the stacked argument has 3 entries: expected n (m + 1) = 2 (the state and its 1 delayed copies)", std::invalid_argument);
    CHECK_THROWS_WITH_AS(mg.set_parameter("alpha", 1.0), "parameter 'alpha' is not a parameter of this system: expected one of beta, gamma, n, tau",
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(mg.set_parameter("beta", INFINITY), "parameter 'beta': expected a finite value", std::invalid_argument);
    CHECK_THROWS_AS(mg.jacobian(mg.stack_constant(Eigen::VectorXd::Ones(1)), 2), std::invalid_argument);
}

TEST_SUITE_END();
