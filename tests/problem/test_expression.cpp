#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>

#include "../tolerances.hpp"
#include "ddemap/problem/expression.hpp"
#include "ddemap/problem/expression_system.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

double rel_err(double a, double b) { return std::abs(a - b) / std::max(1.0, std::abs(b)); }

/// One variable x (u[0]) and its delayed copy (u[1]); parameters a, b.
struct Case {
    const char* text;
    std::function<double(double x, double xd, double a, double b)> hand;
};

}  // namespace

TEST_CASE("parsed expressions equal the hand-written formulas at random points") {
    const Case cases[] = {
        {"x + 2*a - b/3", [](double x, double, double a, double b) { return x + 2 * a - b / 3; }},
        {"-x^2", [](double x, double, double, double) { return -(x * x); }},
        {"2^-1 * x", [](double x, double, double, double) { return 0.5 * x; }},
        {"a^b^0.5", [](double, double, double a, double b) { return std::pow(a, std::pow(b, 0.5)); }},
        {"x - x(t - 1.5) - -a", [](double x, double xd, double a, double) { return x - xd + a; }},
        {"exp(-a*x)*sin(x(t-1.5)) + cos(b) - tan(0.3*x)", [](double x, double xd, double a, double b) {
             return std::exp(-a * x) * std::sin(xd) + std::cos(b) - std::tan(0.3 * x);
         }},
        {"log(1 + x^2) + sqrt(abs(x(t - 1.5))) - tanh(a - b)", [](double x, double xd, double a, double b) {
             return std::log(1 + x * x) + std::sqrt(std::abs(xd)) - std::tanh(a - b);
         }},
        {"min(x, a) * max(x(t-1.5), b) + pow(a, x)", [](double x, double xd, double a, double b) {
             return std::min(x, a) * std::max(xd, b) + std::pow(a, x);
         }},
        {"1e-3*x/(2.5E+1 + .5*a) - 3*(x-1)^3/(1+(x-1)^3)^2", [](double x, double, double a, double) {
             return 1e-3 * x / (25.0 + 0.5 * a) - 3 * std::pow(x - 1, 3) / std::pow(1 + std::pow(x - 1, 3), 2);
         }},
    };
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> U(-2.0, 2.0), P(0.3, 3.0);
    ExpressionNames names{{"x"}, {"a", "b"}};
    for (const Case& c : cases) {
        CAPTURE(c.text);
        const ParsedEquations pe = parse_equations({c.text}, names);
        REQUIRE(pe.equations.size() == 1);
        for (int trial = 0; trial < 50; ++trial) {
            const double x = U(rng), xd = U(rng), a = P(rng), b = P(rng);
            const double u[2] = {x, xd}, p[2] = {a, b};
            const double want = c.hand(x, xd, a, b);
            const double got = pe.equations[0].evaluate<double>(u, p);
            CHECK(rel_err(got, want) < tol::expression_vs_hand);
        }
    }
}

TEST_CASE("the system of the issue: delays collected once, values and exact derivatives") {
    ExpressionSystem sys({"x1", "x2"}, {"a", "b", "d", "tau"}, {0.5, 0.6, 0.05, 2.0},
                         {"x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"});
    REQUIRE(sys.dimension() == 2);
    REQUIRE(sys.delay_count() == 1);
    CHECK(sys.delays()[0] == 2.0);
    CHECK(sys.delay_text(0) == "tau");
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> U(-1.5, 1.5);
    for (int trial = 0; trial < 20; ++trial) {
        Eigen::VectorXd u(4);
        for (int i = 0; i < 4; ++i) u[i] = U(rng);
        const Eigen::VectorXd f = sys.f(u);
        CHECK(f[0] == u[1]);
        const double want = -0.05 * u[1] - 0.5 * u[0] - u[0] * u[0] * u[0] - 0.6 * (u[0] - u[2]);
        CHECK(rel_err(f[1], want) < tol::expression_vs_hand);
        // exact Jacobian blocks against the hand derivatives
        const auto a = sys.jacobians(u);
        CHECK(a[0](1, 0) == doctest::Approx(-0.5 - 3 * u[0] * u[0] - 0.6).epsilon(1e-14));
        CHECK(a[0](1, 1) == doctest::Approx(-0.05).epsilon(1e-14));
        CHECK(a[1](1, 0) == doctest::Approx(0.6).epsilon(1e-14));
        CHECK(sys.parameter_derivative(u, "b")[1] == doctest::Approx(-(u[0] - u[2])).epsilon(1e-14));
    }
    // the same delay written twice shares a slot; another delay gets one
    ExpressionSystem two({"x"}, {"tau"}, {1.0}, {"x(t - tau) + x(t-tau) * x(t - 2*tau)"});
    CHECK(two.delay_count() == 2);
    CHECK(two.delays()[1] == 2.0);
}

TEST_CASE("AD derivatives of a parsed system against finite differences (first to third order)") {
    ExpressionSystem sys({"x", "y"}, {"k", "tau"}, {0.8, 1.3},
                         {"-x*y + k*sin(y(t - tau)) + exp(x(t - tau/2))/(2 + y^2)",
                          "tanh(x) * y(t - tau)^3 - k^y + sqrt(1 + x(t - tau/2)^2)"});
    REQUIRE(sys.has_higher_derivatives());
    const int size = 2 * 3;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    for (int trial = 0; trial < 10; ++trial) {
        Eigen::VectorXd u(size), a(size), b(size), c(size);
        for (int i = 0; i < size; ++i) u[i] = U(rng), a[i] = U(rng), b[i] = U(rng), c[i] = U(rng);
        // first order: every column against central differences of f
        const auto blocks = sys.jacobians(u);
        const double h = 1e-5;
        for (int col = 0; col < size; ++col) {
            Eigen::VectorXd up = u, um = u;
            up[col] += h;
            um[col] -= h;
            const Eigen::VectorXd fd = (sys.f(up) - sys.f(um)) / (2 * h);
            CHECK((blocks[col / 2].col(col % 2) - fd).cwiseAbs().maxCoeff() < tol::finite_difference);
        }
        // second: D^2 f[a, b] against the difference of the exact D f a along b
        auto jac_times = [&](const Eigen::VectorXd& at, const Eigen::VectorXd& dir) {
            const auto bl = sys.jacobians(at);
            Eigen::VectorXd r = Eigen::VectorXd::Zero(2);
            for (int k = 0; k < 3; ++k) r += bl[k] * dir.segment(2 * k, 2);
            return r;
        };
        const double h2 = 1e-4;
        const Eigen::VectorXd d2 = sys.second_derivative(u, a, b);
        const Eigen::VectorXd d2fd = (jac_times(u + h2 * b, a) - jac_times(u - h2 * b, a)) / (2 * h2);
        CHECK((d2 - d2fd).cwiseAbs().maxCoeff() < tol::higher_derivative_fd);
        // symmetric in its directions
        CHECK((d2 - sys.second_derivative(u, b, a)).cwiseAbs().maxCoeff() < 1e-13);
        // third: D^3 f[a, b, c] against the difference of the exact D^2 f[a, b] along c
        const Eigen::VectorXd d3 = sys.third_derivative(u, a, b, c);
        const Eigen::VectorXd d3fd = (sys.second_derivative(u + h2 * c, a, b) - sys.second_derivative(u - h2 * c, a, b)) / (2 * h2);
        CHECK((d3 - d3fd).cwiseAbs().maxCoeff() < tol::higher_derivative_fd);
    }
    // a closed form: f = x(t)^3 sin(x(t)) has f''' = (6 - 9 x^2) sin x + (18 x - x^3) cos x... along e0
    ExpressionSystem s1({"x"}, {}, {}, {"x^3*sin(x)"});
    const double x = 0.7;
    Eigen::VectorXd e = Eigen::VectorXd::Ones(1), u = Eigen::VectorXd::Constant(1, x);
    CHECK(s1.second_derivative(u, e, e)[0] ==
          doctest::Approx(6 * x * std::sin(x) + 6 * x * x * std::cos(x) - x * x * x * std::sin(x)).epsilon(1e-14));
    CHECK(s1.third_derivative(u, e, e, e)[0] ==
          doctest::Approx((6 - 9 * x * x) * std::sin(x) + (18 * x - x * x * x) * std::cos(x)).epsilon(1e-13));
}

TEST_CASE("expression errors name the equation, the character and what was expected") {
    const ExpressionNames names{{"x1", "x2"}, {"a", "tau"}};
    auto error_of = [&](const std::string& second) {
        try {
            parse_equations({"x2", second}, names);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("a*x1 +") == "equation 2 (dx2/dt), character 7: the expression ends early: expected a number, a name or '('");
    CHECK(error_of("a*y") == "equation 2 (dx2/dt), character 3: unknown name 'y': expected a variable (x1, x2), a parameter (a, tau) or a function");
    CHECK(error_of("x1(t - x2)") == "equation 2 (dx2/dt), character 8: the delay depends on the state (x2): expected an expression of parameters and numbers");
    CHECK(error_of("x1(t - tau*x1(t - 1))") ==
          "equation 2 (dx2/dt), character 12: the delay depends on the state (x1): expected an expression of parameters and numbers");
    CHECK(error_of("(x1 + 1") == "equation 2 (dx2/dt), character 8: the expression ends early: expected ')'");
    CHECK(error_of("x1 ** 2") == "equation 2 (dx2/dt), character 5: unexpected '*': expected a number, a name or '('");
    CHECK(error_of("x1 2") == "equation 2 (dx2/dt), character 4: unexpected '2': expected an operator (+ - * / ^) or the end");
    CHECK(error_of("sin(x1, 2)") == "equation 2 (dx2/dt), character 7: sin takes one argument: expected ')'");
    CHECK(error_of("max(x1)") == "equation 2 (dx2/dt), character 7: unexpected ')': expected ',' and the second argument of max");
    CHECK(error_of("a(t - 1)") == "equation 2 (dx2/dt), character 2: the parameter a is not a function: expected an operator after it");
    CHECK(error_of("x1(s - 1)") == "equation 2 (dx2/dt), character 4: a delayed value of x1 must read x1(t - DELAY): expected 't'");
    CHECK(error_of("x1(t + 1)") == "equation 2 (dx2/dt), character 6: unexpected '+': expected '-' after t (x1(t - DELAY))");
    CHECK(error_of("t*x1") == "equation 2 (dx2/dt), character 1: the time t appears outside a delayed value: expected t only in NAME(t - DELAY)");
    CHECK(error_of("1e400*x1") == "equation 2 (dx2/dt), character 1: the number 1e400 is out of range: expected a finite number");
    CHECK(error_of("2e+ * x1") == "equation 2 (dx2/dt), character 4: the exponent of the number has no digits: expected digits after 'e'");
    CHECK(error_of("  ") == "equation 2 (dx2/dt), character 3: the expression is empty: expected an expression");
    CHECK(error_of(std::string(300, '(') + "x1" + std::string(300, ')')).find("nested too deeply") != std::string::npos);
    CHECK_THROWS_WITH_AS(parse_equations({"x2"}, names), "1 equations for 2 variables: expected one equation per variable", std::invalid_argument);
    // names a system declares
    CHECK_THROWS_WITH_AS(ExpressionSystem({"x"}, {"sin"}, {1.0}, {"x"}), "parameter 'sin' is the name of a function: expected another name",
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(ExpressionSystem({"t"}, {}, {}, {"1"}), "variable 't' is the time: expected another name", std::invalid_argument);
    CHECK_THROWS_WITH_AS(ExpressionSystem({"x"}, {"x"}, {1.0}, {"x"}), "parameter 'x' is also a variable: expected distinct names", std::invalid_argument);
    CHECK_THROWS_WITH_AS(ExpressionSystem({"x"}, {"tau"}, {-1.0}, {"x(t - tau)"}), "the delay tau is -1: expected a finite delay >= 0",
                         std::invalid_argument);
}

TEST_SUITE_END();
