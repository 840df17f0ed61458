// The computable range (README "Verdicts and the computable range") refused with one check,
// require_computable, on every path: rings of mixed cars (each car), penetration studies, sweep
// windows (their corners, before any work), classifications of files and their parameter samples.
#include <doctest/doctest.h>

#include <stdexcept>

#include "ddemap/analysis/stability/classify.hpp"
#include "ddemap/analysis/stability/mixed_ring.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/study/sweep.hpp"
#include "ddemap/traffic/model.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
// OVRV with th = 1.5, k2 = 0.2, tau = 0.2: c tau = 0.2 (2.5 k1 + 0.4) is 10 at k1 = 19.84
const double kEdgeK1 = (kMaxScaledDelay / 0.2 - 0.4) / 2.5;

FleetCar ovrv_car(const std::string& label, double k1) {
    return FleetCar{label, "ovrv", {{"k1", k1}, {"k2", 0.2}, {"th", 1.5}, {"tau", 0.2}, {"eta", 10.0}}};
}
}  // namespace

TEST_CASE("computable range: a mixed ring is checked car by car, a penetration study before any ring") {
    MixedRingOptions o;
    o.speed = 20.0;
    o.roots.count = 2;
    const FleetCar ok = ovrv_car("ok", 0.2), big = ovrv_car("big", kEdgeK1 * (1.0 + 1e-6));
    CHECK_NOTHROW(require_computable(Fleet{ok, ok, ok}, o));
    CHECK_NOTHROW(require_computable(Fleet{ok, ovrv_car("edge", kEdgeK1 * (1.0 - 1e-6))}, o));
    CHECK_THROWS_WITH_AS(require_computable(Fleet{ok, big, ok}, o), doctest::Contains("car 2 (big): gains and delay outside the computable range"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(analyse_mixed_ring(Fleet{ok, ok, big}, o), doctest::Contains("car 3 (big)"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(analyse_mixed_ring(Fleet{ovrv_car("huge", 1e10), ok}, o), doctest::Contains("car 1 (huge): the gains are outside"),
                         std::invalid_argument);
    // beyond any meaning, the car itself is refused (its value and unit named)
    CHECK_THROWS_WITH_AS(analyse_mixed_ring(Fleet{ovrv_car("huge", 1e300), ok}, o), doctest::Contains("k1 = 1e+300: expected at most 1e12 [1/s^2]"),
                         std::invalid_argument);
    MixOptions m;
    m.cars = 6;
    m.fractions = {0.0, 1.0};
    m.ring = o;
    // p = 0 alone would be computable: the whole study is refused, not its last point
    CHECK_THROWS_WITH_AS(penetration_study(big, ok, m), doctest::Contains("computable range"), std::invalid_argument);
    m.fractions = {0.0};
    CHECK_NOTHROW(penetration_study(big, ok, m));  // no car of X in the only ring
}

TEST_CASE("computable range: a sweep window is checked at its corners") {
    SweepSpec s;
    s.fixed = {{"th", 1.5}, {"tau", 0.2}, {"eta", 10.0}};
    s.x = Axis{"k1", 0.1, kEdgeK1 * (1.0 - 1e-6), 3};
    s.y = Axis{"k2", 0.1, 0.2, 2};
    CHECK_NOTHROW(s.validate());
    s.x.hi = kEdgeK1 * (1.0 + 1e-6);  // only the corner (k1 hi, k2 hi) is outside
    CHECK_THROWS_WITH_AS(s.validate(), doctest::Contains("of the window: gains and delay outside the computable range"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(run_sweep(s), doctest::Contains("computable range"), std::invalid_argument);
    s.x.hi = 1.0;
    s.y = Axis{"tau", 0.1, 1e6, 2};
    s.fixed.erase("tau");
    s.fixed["k2"] = 0.2;
    CHECK_THROWS_WITH_AS(s.validate(), doctest::Contains("tau = 1000000"), std::invalid_argument);
}

TEST_CASE("computable range: classify refuses a vehicle outside it and samples outside it are undecided, not thrown") {
    CalibratedVehicle a;
    a.name = "A";
    a.parameters = {{"k1", 0.2}, {"k2", 0.2}, {"th", 1.5}, {"tau", 0.2}, {"eta", 10.0}};
    CalibratedVehicle big = a;
    big.name = "big";
    big.parameters["k1"] = kEdgeK1 * (1.0 + 1e-6);
    CHECK_THROWS_WITH_AS(classify({a, big}, 22), doctest::Contains("vehicle 'big': gains and delay outside the computable range"),
                         std::invalid_argument);
    // a centre just inside, k1 spread across the edge: about half the samples outside
    ParameterMap centre = a.parameters;
    centre["k1"] = kEdgeK1 - 0.05;
    Eigen::Matrix<double, 5, 5> cov = Eigen::Matrix<double, 5, 5>::Zero();
    cov(0, 0) = 0.1 * 0.1;
    UncertaintyOptions o;
    o.samples = 12;
    o.ring_samples = 0;
    const VerdictUncertainty u = classify_with_uncertainty(centre, cov, 22, o);
    int outside = 0;
    for (const auto& s : u.verdicts) {
        const bool beyond = s.parameters.at("k1") > kEdgeK1;
        CHECK(s.computable == !beyond);
        if (beyond) CHECK_FALSE(s.decided);
        outside += beyond ? 1 : 0;
    }
    REQUIRE(outside > 0);
    REQUIRE(outside < o.samples);
    CHECK(u.undecided == outside);
    CHECK(u.string_unstable.trials == o.samples - outside);
    CHECK(u.status != Status::Converged);
    CHECK(u.message.find(std::to_string(outside) + " samples outside the computable range") != std::string::npos);
}
