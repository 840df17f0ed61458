// The step control of the continuations (solve/step_control.hpp) against sequences of steps
// derived by hand from its rules, and the continuation engine's steps on a straight line against
// the same rules applied to the arclength.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "ddemap/solve/continuation.hpp"
#include "ddemap/solve/step_control.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

/// h0 = 1/4, halved on a rejection, grown by 3/2 after an easy step up to 1/2, ended below 1/64:
/// every step is a dyadic fraction, so the sequences below are exact.
StepControlOptions dyadic() {
    StepControlOptions o;
    o.initial_step = 0.25;
    o.min_step = 1.0 / 64.0;
    o.max_step = 0.5;
    o.shrink_factor = 0.5;
    o.grow_factor = 1.5;
    o.max_jump = 3.0;
    return o;
}

}  // namespace

TEST_CASE("step control: fail, fail, then easy successes from h0 follow h0 / 4 (3/2)^k up to max_step") {
    StepControl s(dyadic());
    CHECK(s.h() == 0.25);
    CHECK(s.reject());
    CHECK(s.h() == 1.0 / 8.0);
    CHECK(s.reject());
    CHECK(s.h() == 1.0 / 16.0);
    // 1/16 (3/2)^k: 3/32, 9/64, 27/128, 81/256, 243/512; then 729/1024 > 1/2: capped at 1/2
    const double expected[] = {3.0 / 32.0, 9.0 / 64.0, 27.0 / 128.0, 81.0 / 256.0, 243.0 / 512.0, 0.5, 0.5};
    for (double e : expected) {
        s.accept(true);
        CHECK(s.h() == e);
    }
}

TEST_CASE("step control: a success that was not easy keeps h, a rejection after growth halves the grown step") {
    StepControl s(dyadic());
    s.accept(false);
    CHECK(s.h() == 0.25);
    s.accept(true);
    CHECK(s.h() == 3.0 / 8.0);
    s.accept(false);
    CHECK(s.h() == 3.0 / 8.0);
    CHECK(s.reject());
    CHECK(s.h() == 3.0 / 16.0);
}

TEST_CASE("step control: the continuation gives up when a rejection leaves h below min_step (h = min_step still steps)") {
    StepControl s(dyadic());  // 1/4 -> 1/8 -> 1/16 -> 1/32 -> 1/64 = min_step -> 1/128 < min_step
    for (int k = 0; k < 4; ++k) CHECK(s.reject());
    CHECK(s.h() == 1.0 / 64.0);
    CHECK_FALSE(s.reject());
    CHECK(s.h() == 1.0 / 128.0);
}

TEST_CASE("step control: a jump is a distance above max_jump h, with the current h") {
    StepControl s(dyadic());
    CHECK(s.jump_limit() == 0.75);
    CHECK_FALSE(s.jumped(0.75));
    CHECK(s.jumped(std::nextafter(0.75, 1.0)));
    CHECK(s.reject());
    CHECK(s.jump_limit() == 0.375);
    CHECK(s.jumped(0.5));
    StepControlOptions o = dyadic();
    o.max_jump = 2.0;
    CHECK(StepControl(o).jump_limit() == 0.5);
}

TEST_CASE("step control: other factors (1/4 on a rejection, growth 2) give their own sequences") {
    StepControlOptions o = dyadic();
    o.shrink_factor = 0.25;
    o.grow_factor = 2.0;
    StepControl s(o);
    CHECK(s.reject());
    CHECK(s.h() == 1.0 / 16.0);
    s.accept(true);
    CHECK(s.h() == 1.0 / 8.0);
    CHECK(s.reject());
    CHECK(s.h() == 1.0 / 32.0);
    CHECK_FALSE(s.reject());  // 1/128 < 1/64
}

TEST_CASE("step control: invalid options are refused with the field's name") {
    auto refused = [](StepControlOptions o, const std::string& field) {
        std::string why;
        CHECK_FALSE(o.is_valid(&why));
        CHECK(why.find(field) != std::string::npos);
        CHECK_THROWS_AS(StepControl{o}, std::invalid_argument);
    };
    StepControlOptions o = dyadic();
    CHECK(o.is_valid());
    o.min_step = 0.0;
    refused(o, "min_step");
    o = dyadic();
    o.initial_step = 1.0;  // above max_step
    refused(o, "initial_step");
    o = dyadic();
    o.max_step = INFINITY;
    o.initial_step = 0.25;
    refused(o, "max_step");
    o = dyadic();
    o.shrink_factor = 1.0;
    refused(o, "shrink_factor");
    o = dyadic();
    o.grow_factor = 0.9;
    refused(o, "grow_factor");
    o = dyadic();
    o.max_jump = 0.0;
    refused(o, "max_jump");
}

namespace {

/// The line y = x (F = y - x), not evaluable for x > x_max: the predictor lies on the line, so
/// the corrector accepts every step with x <= x_max at once and fails on every other.
class Line final : public ContinuationProblem {
public:
    double x_max = 0.3;
    int equations() const override { return 1; }
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const override {
        if (u(0) > x_max) return false;
        f.resize(1);
        f(0) = u(1) - u(0);
        return true;
    }
    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const override {
        if (u(0) > x_max) return false;
        j.resize(1, 2);
        j << -1.0, 1.0;
        return true;
    }
};

}  // namespace

TEST_CASE("step control: continue_branch on a line steps as the rules say (growth to max_step, halving at the edge, the end below min_step)") {
    Line line;
    ContinuationOptions o;
    o.initial_step = 0.01;
    o.max_step = 0.1;
    o.min_step = 1e-3;
    const ContinuationResult r = continue_branch(line, Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(1.0, 1.0), o);

    // the rules on the arclength s along the line (x = s / sqrt 2): a trial s + h beyond the
    // edge is rejected (h halved, the end when h < min_step), else accepted (h grown by 1.5 up
    // to max_step: every corrector here is easy)
    const double s_edge = line.x_max * std::sqrt(2.0);
    std::vector<double> s_points{0.0};
    int rejected = 0;
    double s = 0.0, h = o.initial_step;
    for (;;) {
        REQUIRE(std::abs(s + h - s_edge) > 1e-9);  // no trial within rounding of the edge
        if (s + h > s_edge) {
            ++rejected;
            h *= 0.5;
            if (h < o.min_step) break;
        } else {
            s += h;
            s_points.push_back(s);
            h = std::min(o.max_step, 1.5 * h);
        }
    }
    CHECK(r.stop == ContinuationStop::StepBelowMinimum);
    CHECK(r.rejected_steps == rejected);
    REQUIRE(r.points.size() == s_points.size());
    for (std::size_t k = 0; k < s_points.size(); ++k) {
        CHECK(std::abs(r.points[k](0) - s_points[k] / std::sqrt(2.0)) <= tol::line_steps);
        CHECK(std::abs(r.points[k](1) - s_points[k] / std::sqrt(2.0)) <= tol::line_steps);
    }
    CHECK(s_points.size() > 10);  // growth from 0.01 to 0.1, then the approach to the edge
    CHECK(rejected > 3);
}
