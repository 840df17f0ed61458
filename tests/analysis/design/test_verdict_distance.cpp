#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "ddemap/analysis/design/verdict_distance.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "tolerances.hpp"

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {
const std::vector<std::string> kOver = {"k1", "k2", "th", "tau"};

/// The certified L2 string verdict of an ovrv car.
Verdict verdict(const ParameterMap& p) { return analyse_string(make_model("ovrv", p)->linearise()).string_verdict; }

/// The closed-form low-frequency coefficient of ovrv, c2 = 2 k1 B with
/// B = k1 th (th/2 - tau) + k2 (th - tau) - 1 (written out here, independent of the library), and its gradient in (k1, k2, th, tau).
double ovrv_b(const ParameterMap& p, double* grad = nullptr) {
    const double k1 = p.at("k1"), k2 = p.at("k2"), th = p.at("th"), tau = p.at("tau");
    if (grad) {
        grad[0] = th * (0.5 * th - tau);
        grad[1] = th - tau;
        grad[2] = k1 * (th - tau) + k2;
        grad[3] = -k1 * th - k2;
    }
    return k1 * th * (0.5 * th - tau) + k2 * (th - tau) - 1.0;
}

/// Points at relative distance `radius` from the car in random directions of (k1, k2, th, tau)
/// (fixed seed): how many have the verdict `v`.
int count_on_sphere(const ParameterMap& car, double radius, int n, Verdict v) {
    std::mt19937 rng(7);
    std::normal_distribution<double> g;
    int count = 0;
    for (int i = 0; i < n; ++i) {
        double z[4], norm = 0.0;
        for (double& c : z) {
            c = g(rng);
            norm += c * c;
        }
        ParameterMap p = car;
        for (int j = 0; j < 4; ++j) p[kOver[static_cast<std::size_t>(j)]] *= 1.0 + radius * z[j] / std::sqrt(norm);
        if (verdict(p) == v) ++count;
    }
    return count;
}
}  // namespace

TEST_SUITE_BEGIN("fast");

TEST_CASE("verdict distance of a string-stable car: the flip lies on the closed-form boundary B = 0, meets its KKT condition, and a smaller sphere has no flip") {
    const ParameterMap car = {{"k1", 0.2}, {"k2", 0.6}, {"th", 2.0}, {"tau", 0.2}, {"eta", 8.0}};
    REQUIRE(verdict(car) == Verdict::Stable);
    const VerdictDistance d = verdict_distance("ovrv", car);
    INFO(d.message);
    REQUIRE(d.status == Status::Converged);
    CHECK(d.from_stable);
    CHECK(d.boundary == "low-frequency");
    // the flip: unstable at the point, stable just before it on the segment
    CHECK(verdict(d.at) == Verdict::Unstable);
    ParameterMap before = car;
    for (const auto& k : kOver) before[k] = car.at(k) + (1.0 - 1e-5) * (d.at.at(k) - car.at(k));
    CHECK(verdict(before) == Verdict::Stable);
    // on the closed-form low-frequency boundary B = 0
    double gb[4];
    CHECK(std::abs(ovrv_b(d.at, gb)) < tol::verdict_flip_b);
    // nearest point of B = 0: M (x - x0) is parallel to grad B
    double dot = 0.0, n1 = 0.0, n2 = 0.0, dist2 = 0.0;
    for (int j = 0; j < 4; ++j) {
        const std::string& k = kOver[static_cast<std::size_t>(j)];
        const double r = (d.at.at(k) - car.at(k)) / (car.at(k) * car.at(k));
        dot += r * gb[j];
        n1 += r * r;
        n2 += gb[j] * gb[j];
        dist2 += std::pow((d.at.at(k) - car.at(k)) / car.at(k), 2);
    }
    CHECK(1.0 - std::abs(dot) / std::sqrt(n1 * n2) < tol::verdict_flip_kkt);
    CHECK(std::sqrt(dist2) == doctest::Approx(d.distance).epsilon(1e-12));
    // no flip at 0.95 of the distance in 300 random directions, flips at 1.5 times it in some
    CHECK(count_on_sphere(car, 0.95 * d.distance, 300, Verdict::Stable) == 300);
    CHECK(count_on_sphere(car, 1.5 * d.distance, 300, Verdict::Unstable) > 0);
}

TEST_CASE("verdict distance of a string-unstable car (C_max): stable at the flip, unstable before it, and no stable point on a smaller sphere") {
    ParameterMap car = builtin_vehicle("C_max").parameters;
    REQUIRE(verdict(car) == Verdict::Unstable);
    const VerdictDistance d = verdict_distance("ovrv", car);
    INFO(d.message);
    REQUIRE(d.status == Status::Converged);
    CHECK_FALSE(d.from_stable);
    CHECK(verdict(d.at) == Verdict::Stable);
    ParameterMap before = car;
    for (const auto& k : kOver) before[k] = car.at(k) + (1.0 - 1e-5) * (d.at.at(k) - car.at(k));
    CHECK(verdict(before) == Verdict::Unstable);
    // the search box keeps tau >= tau0 / 10 (a change of at most 90 %): sample inside it only
    CHECK(count_on_sphere(car, std::min(0.95 * d.distance, 0.85), 300, Verdict::Stable) == 0);
}

TEST_CASE("verdict distance: bad options are refused naming the parameter") {
    const ParameterMap car = builtin_vehicle("A_min").parameters;
    VerdictDistanceOptions o;
    o.over = {"k1", "k9"};
    CHECK_THROWS_WITH_AS(verdict_distance("ovrv", car, o), doctest::Contains("k9"), std::invalid_argument);
    o.over = {"k1", "k1"};
    CHECK_THROWS_WITH_AS(verdict_distance("ovrv", car, o), doctest::Contains("named twice"), std::invalid_argument);
    o.over = {};
    CHECK_THROWS_AS(verdict_distance("ovrv", car, o), std::invalid_argument);
}

TEST_SUITE_END();
