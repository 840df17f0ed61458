// The pseudo-arclength continuation engine against curves known in closed form.
#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <functional>
#include <stdexcept>
#include <string>

#include "ddemap/solve/continuation.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using Eigen::VectorXd;

namespace {

/// F(x, y) = x^2 + y^2 - 1 with its exact Jacobian; optionally undefined for x > x_max, and
/// the domain optionally y > y_min.
class Circle final : public ContinuationProblem {
public:
    double x_max = std::numeric_limits<double>::infinity();
    double y_min = -std::numeric_limits<double>::infinity();
    bool in_domain(const VectorXd& u) const override { return u(1) > y_min; }
    int equations() const override { return 1; }
    bool residual(const VectorXd& u, VectorXd& f) const override {
        if (u(0) > x_max) return false;
        f.resize(1);
        f(0) = u(0) * u(0) + u(1) * u(1) - 1.0;
        return true;
    }
    bool jacobian(const VectorXd& u, Eigen::MatrixXd& j) const override {
        if (u(0) > x_max) return false;
        j.resize(1, 2);
        j << 2.0 * u(0), 2.0 * u(1);
        return true;
    }
};

/// F(x, y) = x - (y^3 - y): a branch in the parameter x with folds at y = -+1/sqrt(3).
class Cubic final : public ContinuationProblem {
public:
    int equations() const override { return 1; }
    bool residual(const VectorXd& u, VectorXd& f) const override {
        f.resize(1);
        f(0) = u(0) - (u(1) * u(1) * u(1) - u(1));
        return true;
    }
    bool jacobian(const VectorXd& u, Eigen::MatrixXd& j) const override {
        j.resize(1, 2);
        j << 1.0, -(3.0 * u(1) * u(1) - 1.0);
        return true;
    }
};

/// The sphere |u|^2 = 4 cut by the plane u_0 + u_1 + u_2 = 1 (2 equations, 3 unknowns); the
/// Jacobian by the central-difference helper.
class SpherePlane final : public ContinuationProblem {
public:
    int equations() const override { return 2; }
    bool residual(const VectorXd& u, VectorXd& f) const override {
        f.resize(2);
        f << u.squaredNorm() - 4.0, u.sum() - 1.0;
        return true;
    }
    bool jacobian(const VectorXd& u, Eigen::MatrixXd& j) const override { return central_difference_jacobian(*this, u, j); }
};

VectorXd vec(std::initializer_list<double> v) {
    VectorXd out(static_cast<Eigen::Index>(v.size()));
    Eigen::Index i = 0;
    for (double x : v) out(i++) = x;
    return out;
}

/// Points a closed loop of radius R traced with a constant step h should have: each step turns
/// by phi = asin(h / R) (the arclength constraint projects the chord on the tangent), and the
/// branch closes at the first step k > 8 that ends within 0.75 h of the start.
int loop_points(double radius, double h) {
    const double pi = std::acos(-1.0), phi = std::asin(h / radius);
    for (int k = 9;; ++k)
        if (2.0 * radius * std::abs(std::sin((2.0 * pi - k * phi) / 2.0)) < 0.75 * h) return k + 1;
}

ContinuationOptions fixed_step(double h) {
    ContinuationOptions o;
    o.initial_step = o.max_step = h;
    return o;
}

}  // namespace

TEST_CASE("continuation: the unit circle closes on itself with the expected number of points") {
    const Circle circle;
    const double h = 0.05;
    const ContinuationResult r = continue_branch(circle, vec({1.0, 0.0}), vec({0.0, 1.0}), fixed_step(h));
    CHECK(r.stop == ContinuationStop::ClosedLoop);
    CHECK(r.status == Status::Converged);
    CHECK(r.rejected_steps == 0);
    CHECK(static_cast<int>(r.points.size()) == loop_points(1.0, h));
    CHECK(r.max_residual < 1e-13);
    REQUIRE(r.tangents.size() == r.points.size());
    for (std::size_t i = 0; i < r.points.size(); ++i) {
        const VectorXd& p = r.points[i];
        const VectorXd& t = r.tangents[i];
        CHECK(std::abs(p.squaredNorm() - 1.0) < 1e-13);
        CHECK(std::abs(t.norm() - 1.0) < 1e-14);
        CHECK(std::abs(t.dot(p)) < 1e-12);            // tangent to the circle
        CHECK(t(1) * p(0) - t(0) * p(1) > 0.999);     // counter-clockwise throughout
    }
    // the other way round: the mirror image
    const ContinuationResult back = continue_branch(circle, vec({1.0, 0.0}), vec({0.0, -1.0}), fixed_step(h));
    REQUIRE(back.points.size() == r.points.size());
    for (std::size_t i = 0; i < r.points.size(); ++i) {
        CHECK(std::abs(back.points[i](0) - r.points[i](0)) < 1e-12);
        CHECK(std::abs(back.points[i](1) + r.points[i](1)) < 1e-12);
    }
}

TEST_CASE("continuation: the folds of x = y^3 - y are the zeros of the tangent's x component") {
    const Cubic cubic;
    const double yf = 1.0 / std::sqrt(3.0), xf = 2.0 / (3.0 * std::sqrt(3.0));
    const TestFunction fold{"fold", [](const VectorXd&, const VectorXd& t) { return t(0); }, false};
    for (const VectorXd& scale : {VectorXd(), vec({4.0, 0.5})}) {
        CAPTURE(scale.size());
        ContinuationOptions o;
        o.initial_step = 0.01;
        o.max_step = 0.1;
        o.lower = vec({-1e3, -3.0});
        o.upper = vec({1e3, 2.0});
        o.scale = scale;
        const ContinuationResult r = continue_branch(cubic, vec({-6.0, -2.0}), vec({0.0, 1.0}), o, {fold});
        CAPTURE(r.message);
    CAPTURE(r.points.size());
    CHECK(r.stop == ContinuationStop::Bound);
        CHECK(r.status == Status::Converged);
        // the branch ends exactly on the face y = 2, where x = 8 - 2
        CHECK(r.points.back()(1) == 2.0);
        CHECK(std::abs(r.points.back()(0) - 6.0) < 1e-12);
        REQUIRE(r.events.size() == 3);
        // the folds: (2 / (3 sqrt 3), -1/sqrt 3), then (-2 / (3 sqrt 3), 1/sqrt 3)
        const double ys[2] = {-yf, yf}, xs[2] = {xf, -xf};
        for (int k = 0; k < 2; ++k) {
            const ContinuationEvent& e = r.events[static_cast<std::size_t>(k)];
            CHECK(e.kind == ContinuationEvent::Kind::Test);
            CHECK(e.index == 0);
            CHECK(e.located);
            CHECK(std::abs(e.u(1) - ys[k]) < 1e-8);
            CHECK(std::abs(e.u(0) - xs[k]) < 1e-8);
            CHECK(std::abs(e.t(0)) < 1e-8);
            CHECK(e.after >= 0);
            CHECK(r.points[static_cast<std::size_t>(e.after)](1) < e.u(1));
        }
        CHECK(r.events[0].after < r.events[1].after);
        CHECK(r.events[2].kind == ContinuationEvent::Kind::Bound);
        CHECK(r.events[2].index == 1);
        for (const auto& p : r.points) CHECK(std::abs(p(0) - (p(1) * p(1) * p(1) - p(1))) < 1e-12);
    }
}

TEST_CASE("continuation: an event g(u) = u_0 - c is located on the curve at the analytic crossing") {
    const Circle circle;
    const double c = 0.3, y = std::sqrt(1.0 - c * c);
    TestFunction g{"x = c", [c](const VectorXd& u, const VectorXd&) { return u(0) - c; }, false};
    const ContinuationResult r = continue_branch(circle, vec({1.0, 0.0}), vec({0.0, 1.0}), fixed_step(0.07), {g});
    CHECK(r.stop == ContinuationStop::ClosedLoop);
    REQUIRE(r.events.size() == 2);  // x = c at y > 0 going left, at y < 0 coming back
    for (int k = 0; k < 2; ++k) {
        const ContinuationEvent& e = r.events[static_cast<std::size_t>(k)];
        CHECK(e.located);
        CHECK(e.residual < 1e-13);
        CHECK(std::abs(e.u(0) - c) < 1e-10);
        CHECK(std::abs(e.u(1) - (k == 0 ? y : -y)) < 1e-10);
    }
    // terminal: the branch ends on the zero
    g.terminal = true;
    const ContinuationResult t = continue_branch(circle, vec({1.0, 0.0}), vec({0.0, 1.0}), fixed_step(0.07), {g});
    CHECK(t.stop == ContinuationStop::TerminalEvent);
    CHECK(t.status == Status::Converged);
    REQUIRE(t.events.size() == 1);
    CHECK(std::abs(t.points.back()(0) - c) < 1e-10);
    CHECK(std::abs(t.points.back()(1) - y) < 1e-10);
    CHECK(t.max_residual < 1e-13);
}

TEST_CASE("continuation: the circle where a sphere meets a plane (2 equations, 3 unknowns)") {
    const SpherePlane problem;
    const VectorXd centre = VectorXd::Constant(3, 1.0 / 3.0);
    const double radius = std::sqrt(4.0 - 1.0 / 3.0), h = 0.1;
    const VectorXd e1 = vec({1.0, -1.0, 0.0}) / std::sqrt(2.0), e2 = vec({1.0, 1.0, -2.0}) / std::sqrt(6.0);
    const ContinuationResult r = continue_branch(problem, centre + radius * e1, e2, fixed_step(h));
    CHECK(r.stop == ContinuationStop::ClosedLoop);
    CHECK(r.rejected_steps == 0);
    CHECK(static_cast<int>(r.points.size()) == loop_points(radius, h));
    CHECK(r.max_residual < 1e-12);
    for (std::size_t i = 0; i < r.points.size(); ++i) {
        const VectorXd& p = r.points[i];
        CHECK(std::abs((p - centre).norm() - radius) < 1e-12);
        CHECK(std::abs(p.sum() - 1.0) < 1e-12);
        CHECK(std::abs(r.tangents[i].sum()) < 1e-7);  // in the plane
    }
}

TEST_CASE("continuation: the ends of a branch (domain, step below minimum, max points)") {
    Circle circle;
    circle.x_max = 0.5;  // F cannot be evaluated beyond: the corrector fails, the step shrinks
    const ContinuationResult r = continue_branch(circle, vec({0.0, 1.0}), vec({1.0, 0.0}), fixed_step(0.05));
    CHECK(r.stop == ContinuationStop::StepBelowMinimum);
    CHECK(r.status != Status::Converged);
    CHECK(r.rejected_steps > 10);
    CHECK(r.points.back()(0) <= 0.5);
    CHECK(r.points.back()(0) > 0.5 - 1e-6);

    Circle half;
    half.y_min = -0.5;  // the branch ends before its first point with y <= -0.5
    const ContinuationResult d = continue_branch(half, vec({1.0, 0.0}), vec({0.0, 1.0}), fixed_step(0.05));
    CHECK(d.stop == ContinuationStop::LeftDomain);
    CHECK(d.status == Status::Converged);
    CHECK(d.points.back()(1) > -0.5);
    CHECK(d.points.back()(1) < -0.5 + 0.05);
    CHECK(d.points.back()(0) < 0.0);

    ContinuationOptions few = fixed_step(0.05);
    few.max_points = 7;
    const ContinuationResult m = continue_branch(Circle(), vec({1.0, 0.0}), vec({0.0, 1.0}), few);
    CHECK(m.stop == ContinuationStop::MaxPoints);
    CHECK(m.status == Status::BudgetExhausted);
    CHECK(m.points.size() == 7);
}

TEST_CASE("continuation: invalid options are refused with the field's name") {
    auto message = [](const std::function<void(ContinuationOptions&)>& change) {
        ContinuationOptions o;
        change(o);
        std::string why;
        CHECK_FALSE(o.is_valid(&why));
        try {
            continue_branch(Circle(), vec({1.0, 0.0}), vec({0.0, 1.0}), o);
        } catch (const std::invalid_argument& e) {
            CHECK(std::string(e.what()) == why);
            return why;
        }
        FAIL("no exception");
        return std::string();
    };
    CHECK(message([](auto& o) { o.max_step = -1.0; }).rfind("max_step:", 0) == 0);
    CHECK(message([](auto& o) { o.min_step = 0.0; }).rfind("min_step:", 0) == 0);
    CHECK(message([](auto& o) { o.initial_step = 1.0; }).rfind("initial_step:", 0) == 0);
    CHECK(message([](auto& o) { o.max_points = 1; }).rfind("max_points:", 0) == 0);
    CHECK(message([](auto& o) { o.max_angle = 2.0; }).rfind("max_angle:", 0) == 0);
    CHECK(message([](auto& o) { o.newton.max_iterations = 0; }).rfind("newton.max_iterations:", 0) == 0);
    CHECK(message([](auto& o) { o.scale = vec({1.0, -1.0}); }).rfind("scale:", 0) == 0);
    CHECK(message([](auto& o) { o.lower = vec({1.0, 1.0}), o.upper = vec({0.0, 2.0}); }).rfind("lower:", 0) == 0);
    CHECK(ContinuationOptions().is_valid());
    // sizes that do not fit the problem
    ContinuationOptions o;
    o.lower = vec({0.0, 0.0, 0.0});
    CHECK_THROWS_WITH_AS(continue_branch(Circle(), vec({1.0, 0.0}), vec({0.0, 1.0}), o),
                         "lower: expected 2 entries (the unknowns)", std::invalid_argument);
    CHECK_THROWS_WITH_AS(continue_branch(Circle(), vec({1.0, 0.0, 0.0}), vec({0.0, 1.0}), ContinuationOptions()),
                         "u0: expected 2 entries (the unknowns)", std::invalid_argument);
}

TEST_SUITE_END();

namespace {

/// F(x, y) = y - x^2, defined only for x >= 0 (like a gain that cannot be negative); the
/// Jacobian by central_difference_jacobian.
class HalfParabola final : public ContinuationProblem {
public:
    int equations() const override { return 1; }
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const override {
        if (u(0) < 0.0) return false;
        f.resize(1);
        f(0) = u(1) - u(0) * u(0);
        return true;
    }
    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const override { return central_difference_jacobian(*this, u, j); }
};

}  // namespace

TEST_CASE("continuation: a branch reaches a face of the box where the problem ends (one-sided differences)" * doctest::test_suite("fast")) {
    const HalfParabola p;
    // within h = 1e-7 of x = 0 the central difference would evaluate F at x < 0
    Eigen::MatrixXd j;
    for (const double x : {0.0, 1e-9, 5e-8}) {
        CAPTURE(x);
        REQUIRE(central_difference_jacobian(p, vec({x, x * x}), j));
        CHECK(std::abs(j(0, 0) - (-2.0 * x)) <= ddemap::test::tol::finite_difference);
        CHECK(std::abs(j(0, 1) - 1.0) <= ddemap::test::tol::finite_difference);
    }
    CHECK_FALSE(central_difference_jacobian(p, vec({-1.0, 1.0}), j));
    // from (0.5, 0.25) towards x = 0 in the box [0, 1] x [-1, 1]: the branch ends exactly on the face x = 0
    ContinuationOptions o;
    o.initial_step = 0.05;
    o.max_step = 0.1;
    o.lower = vec({0.0, -1.0});  // y = x^2 touches y = 0 only at the corner
    o.upper = vec({1.0, 1.0});
    const VectorXd t = vec({-1.0, -1.0}).normalized();
    const ContinuationResult r = continue_branch(p, vec({0.5, 0.25}), t, o);
    CAPTURE(r.message);
    CAPTURE(r.points.size());
    CHECK(r.stop == ContinuationStop::Bound);
    REQUIRE(!r.points.empty());
    CHECK(r.points.back()(0) == 0.0);
    CHECK(std::abs(r.points.back()(1)) <= ddemap::test::tol::boundary_closed_form);
}
