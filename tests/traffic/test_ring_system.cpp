#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "ddemap/study/penetration.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/ring_system.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

/// Entrywise equality of two linear DDEs in normal form (delays sorted and merged), delayed
/// terms that vanish identically left out (a law's zero gain gives no term in ExpPoly).
void check_same_dde(const LinearDDE& a, const LinearDDE& b, double rel = 1e-12) {
    auto nonzero = [](const LinearDDE& d) {
        std::vector<DelayTerm> t;
        for (const auto& x : d.delayed())
            if (x.matrix.cwiseAbs().maxCoeff() > 0.0) t.push_back(x);
        return t;
    };
    REQUIRE(a.dimension() == b.dimension());
    double scale = std::max(1.0, a.a0().cwiseAbs().maxCoeff());
    CHECK((a.a0() - b.a0()).cwiseAbs().maxCoeff() <= rel * scale);
    const auto ta = nonzero(a), tb = nonzero(b);
    REQUIRE(ta.size() == tb.size());
    for (std::size_t k = 0; k < ta.size(); ++k) {
        CAPTURE(k);
        CHECK(ta[k].delay == tb[k].delay);
        scale = std::max(1.0, ta[k].matrix.cwiseAbs().maxCoeff());
        CHECK((ta[k].matrix - tb[k].matrix).cwiseAbs().maxCoeff() <= rel * scale);
    }
}

ParameterMap with_speed(ParameterMap p, double v) {
    p["speed"] = v;
    return p;
}

const ParameterMap ovrv_p = {{"k1", 0.23}, {"k2", 0.41}, {"th", 1.3}, {"tau", 0.35}, {"eta", 8.0}};
const ParameterMap idm_p = {{"a", 1.1}, {"b", 1.6}, {"v0", 32.0}, {"delta", 4.0}, {"th", 1.2}, {"tau", 0.3}, {"eta", 2.0}};
const ParameterMap ccc_p = {{"k1", 0.15}, {"k2", 0.35}, {"k3", 0.2}, {"th", 1.1}, {"tau", 0.4}, {"tau2", 0.25}, {"eta", 6.0}};

}  // namespace

TEST_CASE("ring system: f vanishes at the equilibrium, and its linearisation is full_ring_dde (ovrv, idm, ccc)") {
    const double v = 17.0;
    for (const auto& [model, p] : {std::make_pair(std::string("ovrv"), ovrv_p), std::make_pair(std::string("idm"), idm_p),
                                   std::make_pair(std::string("ccc"), ccc_p)}) {
        for (int n : {2, 3, 5}) {
            const std::string model_name = model;  // a plain variable: CAPTURE takes it in a lambda
            CAPTURE(model_name);
            CAPTURE(n);
            const auto m = make_model(model, with_speed(p, v));
            const RingSystem ring(*m, n);
            CHECK(ring.dimension() == 2 * n);
            const Eigen::VectorXd eq = ring.equilibrium(v);
            CHECK(equilibrium_residual(ring, eq) < 1e-12);
            check_same_dde(linearise(ring, eq), full_ring_dde(m->linearise(), n));
            check_same_dde(ring.sparse_linearise(eq).to_dense(), full_ring_dde(m->linearise(), n));
        }
    }
}

TEST_CASE("ring system of a mixed fleet: linearisation equals mixed_ring_dde, dense and sparse") {
    std::mt19937 rng(11);
    Fleet fleet;
    for (int i = 0; i < 3; ++i) fleet.push_back(test::random_car(rng, false));
    fleet.push_back(test::random_car(rng, true));
    fleet.push_back(fleet[0]);  // a repeated type
    fleet.push_back({"idm", "idm", idm_p});
    fleet.push_back(test::random_car(rng, true));
    const double v = 12.5;
    const RingSystem ring(fleet);
    CHECK(ring.cars() == 7);
    CHECK(ring.types() == 6);
    CHECK(ring.type_of(4) == ring.type_of(0));
    const Eigen::VectorXd eq = ring.equilibrium(v);
    const RingEquilibrium re = ring_equilibrium_at_speed(fleet, v);
    for (int i = 0; i < ring.cars(); ++i) CHECK(eq[2 * i] == doctest::Approx(re.gaps[i]).epsilon(1e-15));
    CHECK(equilibrium_residual(ring, eq) < 1e-12);
    const LinearDDE dense = linearise(ring, eq);
    const LinearDDE assembled = mixed_ring_dde(linearise_fleet(fleet, v));
    check_same_dde(dense, assembled.to_dense());
    check_same_dde(dense, ring.sparse_linearise(eq).to_dense());
    // away from the equilibrium the sparse path still equals the dense Jacobians
    Eigen::VectorXd x = eq;
    for (int i = 0; i < x.size(); ++i) x[i] += 0.3 * std::sin(1.7 * i);
    check_same_dde(linearise(ring, x), ring.sparse_linearise(x).to_dense());
    // named parameters per type; changing one changes that type's cars only
    CHECK(ring.parameter("k1[1]") == fleet[0].parameters.at("k1"));
    CHECK_THROWS_WITH_AS(ring.parameter("k1"), doctest::Contains("parameter 'k1' is not a parameter of this system"), std::invalid_argument);
}

TEST_CASE("ring system: rightmost roots of the linearised system equal those of the Fourier modes") {
    for (const auto& [model, p] : {std::make_pair(std::string("ovrv"), ovrv_p), std::make_pair(std::string("ccc"), ccc_p),
                                   std::make_pair(std::string("idm"), idm_p)}) {
        for (int n : {4, 6}) {
            const std::string model_name = model;  // a plain variable: CAPTURE takes it in a lambda
            CAPTURE(model_name);
            CAPTURE(n);
            const auto m = make_model(model, with_speed(p, 15.0));
            const RingSystem ring(*m, n);
            RingOptions ro;
            ro.roots.count = 6;
            const RingResult modes = analyse_ring(m->linearise(), n, ro);
            RootOptions fo;
            fo.count = 7;  // the trivial zero as well
            const RootResult full = rightmost_roots(linearise(ring, ring.equilibrium(15.0)), fo);
            REQUIRE(full.status == Status::Converged);
            std::vector<cplx> nontrivial;
            int trivial = 0;
            for (const auto& r : full.roots) {
                if (std::abs(r.value) < 1e-9) ++trivial;
                else nontrivial.push_back(r.value);
            }
            CHECK(trivial == 1);
            CHECK(nontrivial.size() >= 4);
            // the modes' rightmost roots appear in the full system, in the same order
            const std::size_t k = std::min<std::size_t>(4, nontrivial.size());
            REQUIRE(modes.roots.size() >= k);
            for (std::size_t j = 0; j < k; ++j) {
                CAPTURE(j);
                CHECK(std::abs(nontrivial[j].real() - modes.roots[j].root.value.real()) < tol::same_root);
                const auto it = std::find_if(modes.roots.begin(), modes.roots.end(),
                                             [&](const RingRoot& mr) { return std::abs(mr.root.value - nontrivial[j]) < tol::same_root; });
                CHECK(it != modes.roots.end());
            }
        }
    }
}

TEST_CASE("follower system: the linearised one-car system is the plant") {
    for (const auto& [model, p] : {std::make_pair(std::string("ovrv"), ovrv_p), std::make_pair(std::string("idm"), idm_p),
                                   std::make_pair(std::string("ccc"), ccc_p)}) {
        const std::string model_name = model;
        CAPTURE(model_name);
        const double v = 21.0;
        const auto m = make_model(model, with_speed(p, v));
        const FollowerSystem one(*m, v);
        const Eigen::VectorXd eq = one.equilibrium();
        CHECK(equilibrium_residual(one, eq) < 1e-12);
        check_same_dde(linearise(one, eq), plant_dde(m->linearise()));
        // the lead speed is a parameter: df/dv_l = (1, sum of the leader partials)
        const Eigen::VectorXd d = one.parameter_derivative(one.stack_constant(eq), "lead_speed");
        CHECK(d[0] == 1.0);
        double lead_sum = m->linearise().lead(0.0).real();
        for (const auto& f : m->linearise().further) lead_sum += f(0.0).real();
        CHECK(d[1] == doctest::Approx(lead_sum).epsilon(1e-13));
    }
}

TEST_CASE("ring system: parameter derivatives and validation") {
    const auto m = make_model("ovrv", with_speed(ovrv_p, 10.0));
    const RingSystem ring(*m, 3);
    Eigen::VectorXd x(6);
    x << 25.0, 9.0, 30.0, 11.0, 28.0, 10.5;
    const Eigen::VectorXd u = ring.stack_constant(x);
    const Eigen::VectorXd dk1 = ring.parameter_derivative(u, "k1");
    const Eigen::VectorXd dth = ring.parameter_derivative(u, "th");
    for (int i = 0; i < 3; ++i) {
        CHECK(dk1[2 * i] == 0.0);
        CHECK(dk1[2 * i + 1] == doctest::Approx(x[2 * i] - 8.0 - 1.3 * x[2 * i + 1]).epsilon(1e-15));
        CHECK(dth[2 * i + 1] == doctest::Approx(-0.23 * x[2 * i + 1]).epsilon(1e-15));
    }
    CHECK_THROWS_WITH_AS(RingSystem(*m, 1), "a ring needs at least 2 cars, got 1", std::invalid_argument);
    CHECK_THROWS_WITH_AS(ring.equilibrium(-1.0), doctest::Contains("expected a finite speed >= 0"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(linearise(ring, Eigen::VectorXd::Zero(5)), "the equilibrium has 5 entries: expected the dimension 6", std::invalid_argument);
    Fleet bad = {{"a", "ovrv", ovrv_p}, {"b", "ovrv", {{"k1", 0.1}}}};
    CHECK_THROWS_WITH_AS(RingSystem{bad}, doctest::Contains("car 2 (b): model ovrv needs k2"), std::invalid_argument);
}

TEST_SUITE_END();
