#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "numeric_helpers.hpp"
#include "tolerances.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/problem/expression_system.hpp"
#include "ddemap/solve/equilibrium.hpp"
#include "ddemap/traffic/ov_ring.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

namespace {

using test::bisect;
using test::pi;

struct ClosedFormHopf {
    double headway, omega;
    int mode;
};

/// The Hopf points of the ov ring (alpha, tau, v0 = h_st = 1) at the uniform flow with headway in
/// [lo, hi], from the ring modes' characteristic equation (see the case "the structural zero is
/// removed" below): mode k (theta = 2 pi k / N, k = 1..N-1; mode N - k at -i omega is the conjugate
/// of mode k at +i omega) has lambda = i omega, omega > 0, where
///     omega tau = theta / 2 - pi/2 + arctan(alpha / omega) + 2 pi m   (m = 0, 1, ...)
/// and V'(h) = omega sqrt(omega^2 + alpha^2) / (2 alpha sin(theta / 2)); V'(h) = 3 y^2 / (1 + y^3)^2
/// (y = h - 1 > 0) rises to its maximum at y^3 = 1/2 and falls after it, so each crossing value
/// is met once on either side (when inside [lo, hi]).
std::vector<ClosedFormHopf> ov_ring_hopf_closed_form(int N, double alpha, double tau, double lo, double hi) {
    auto slope = [](double h) {
        const double y = h - 1.0;
        return y > 0.0 ? 3.0 * y * y / ((1.0 + y * y * y) * (1.0 + y * y * y)) : 0.0;
    };
    const double top = 1.0 + std::cbrt(0.5);
    std::vector<ClosedFormHopf> out;
    for (int k = 1; k < N; ++k) {
        const double th = 2 * pi * k / N;
        for (int m = 0; m < 10; ++m) {
            const double w = bisect([&](double ww) { return ww * tau - th / 2 + pi / 2 - std::atan(alpha / ww) - 2 * pi * m; }, 1e-12, 1e3);
            const double f = w * std::sqrt(w * w + alpha * alpha) / (2 * alpha * std::sin(th / 2));
            if (!(f < slope(top))) break;  // larger m: larger omega and f
            for (const auto& side : {std::make_pair(1.0 + 1e-12, top), std::make_pair(top, 1e3)}) {
                const double h = bisect([&](double x) { return slope(x) - f; }, side.first, side.second);
                if (h >= lo && h <= hi) out.push_back({h, w, k});
            }
        }
    }
    std::sort(out.begin(), out.end(), [](const ClosedFormHopf& a, const ClosedFormHopf& b) { return a.headway < b.headway; });
    return out;
}

}  // namespace

TEST_CASE("x' = -a sin(x(t - 1)) + x^3: Hopf at a tau = pi/2 with omega = a") {
    // the linearisation at x = 0 is y' = -a y(t - tau): lambda = i omega needs a cos(omega tau) = 0,
    // a sin(omega tau) = omega, so omega = a and a tau = pi/2 (the first crossing)
    ExpressionSystem sys({"x"}, {"a", "tau"}, {1.0, 1.0}, {"-a*sin(x(t - tau)) + x^3"});
    EquilibriumBranchOptions o;
    o.parameter = "a";
    o.from = 0.5;
    o.to = 2.5;
    const EquilibriumBranch br = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 0.1), o);
    CHECK(br.status == Status::Converged);
    CHECK(br.stop == ContinuationStop::Bound);
    CHECK(br.points.front().stable);
    CHECK(!br.points.back().stable);
    CHECK(br.folds.empty());
    REQUIRE(br.hopf.size() == 1);
    CHECK(br.hopf[0].status == Status::Converged);
    CHECK(std::abs(br.hopf[0].par - pi / 2) < tol::special_point);
    CHECK(std::abs(br.hopf[0].omega - pi / 2) < tol::special_point);
    CHECK(std::abs(br.hopf[0].x[0]) < tol::special_point);
    // the second crossing a tau = 5 pi / 2 is outside the range
}

TEST_CASE("x' = p - x(t - 1)^2: a fold at p = 0 and a Hopf point at p = (pi/4)^2 with omega = pi/2") {
    // equilibria x = +-sqrt(p); linearisation y' = -2 x y(t - 1): Hopf where 2 x = pi/2, omega = pi/2;
    // the fold (x, p) = (0, 0) is where d/dx (p - x^2) = 0
    ExpressionSystem sys({"x"}, {"p"}, {1.0}, {"p - x(t - 1)^2"});
    EquilibriumBranchOptions o;
    o.parameter = "p";
    o.from = 0.9;
    o.to = -1.0;
    const EquilibriumBranch br = equilibrium_branch(sys, Eigen::VectorXd::Constant(1, 1.0), o);
    CHECK(br.status == Status::Converged);
    REQUIRE(br.folds.size() == 1);
    CHECK(br.folds[0].status == Status::Converged);
    CHECK(std::abs(br.folds[0].par) < tol::special_point);
    CHECK(std::abs(br.folds[0].x[0]) < tol::special_point);
    // the branch turns at the fold and comes back on x < 0 to the face p = 0.9
    CHECK(br.points.back().x[0] < 0.0);
    CHECK(br.points.back().par == doctest::Approx(0.9).epsilon(1e-12));
    CHECK(br.points.back().unstable == 1);  // a real positive root: a saddle
    REQUIRE(br.hopf.size() == 1);
    CHECK(std::abs(br.hopf[0].par - pi * pi / 16) < tol::special_point);
    CHECK(std::abs(br.hopf[0].x[0] - pi / 4) < tol::special_point);
    CHECK(std::abs(br.hopf[0].omega - pi / 2) < tol::special_point);
}

TEST_CASE("Mackey-Glass continued in the exponent n: the Hopf point of its linearisation's closed form") {
    // x' = beta x(t - tau) / (1 + x(t - tau)^n) - gamma x, positive equilibrium x*^n = beta/gamma - 1
    // (here 2: x* = 2^(1/n) moves along the branch). Linearisation y' = -gamma y + b y(t - tau) with
    // b = beta (1 + (1 - n) x*^n) / (1 + x*^n)^2 = (3 - 2 n) / 3 (beta = 3, gamma = 1). For b < -gamma a
    // pair crosses at omega = sqrt(b^2 - gamma^2), omega tau = arccos(gamma / b): solve for b at tau = 2.
    const double beta = 3.0, gamma = 1.0, tau = 2.0;
    ExpressionSystem mg({"x"}, {"beta", "gamma", "n", "tau"}, {beta, gamma, 4.0, tau},
                        {"beta*x(t - tau)/(1 + x(t - tau)^n) - gamma*x"});
    const double b = bisect([&](double bb) { return std::acos(gamma / bb) / std::sqrt(bb * bb - gamma * gamma) - tau; }, -50.0, -1.0 - 1e-9);
    const double n_hopf = (3.0 - 3.0 * b) / 2.0, omega = std::sqrt(b * b - gamma * gamma);
    EquilibriumBranchOptions o;
    o.parameter = "n";
    o.from = 2.0;
    o.to = 6.0;
    const EquilibriumBranch br = equilibrium_branch(mg, Eigen::VectorXd::Constant(1, 1.3), o);
    CHECK(br.status == Status::Converged);
    REQUIRE(br.hopf.size() == 1);
    CHECK(std::abs(br.hopf[0].par - n_hopf) < tol::special_point);
    CHECK(std::abs(br.hopf[0].omega - omega) < tol::special_point);
    CHECK(std::abs(br.hopf[0].x[0] - std::pow(2.0, 1.0 / n_hopf)) < tol::special_point);
    // every branch point is an equilibrium of the analytic family
    for (const EquilibriumPoint& p : br.points) CHECK(std::abs(p.x[0] - std::pow(2.0, 1.0 / p.par)) < 1e-10);
}

TEST_CASE("ov ring: the structural zero is removed and the Hopf points satisfy the ring modes' closed form" * doctest::test_suite("slow")) {
    // Linearising the ring at the uniform flow with f = V'(h*) and a Fourier mode v_i ~ z^i e^{lambda t},
    // z = exp(i theta_k), theta_k = 2 pi k / N, gives h_i = (z - 1) v_i / lambda and
    //     lambda^2 + alpha lambda + alpha f (1 - z) e^{-lambda tau} = 0
    // (Orosz, Wilson, Stepan, Phys. Rev. E 70, 026207 (2004), the characteristic equation of their
    // eq. (2.1) at the uniform flow). With lambda = i omega, 1 - z = 2 sin(theta/2) e^{i(theta/2 - pi/2)}:
    //     modulus  omega sqrt(omega^2 + alpha^2) = 2 alpha f sin(theta_k / 2),
    //     phase    omega tau = theta_k / 2 - pi/2 + arctan(alpha / omega)   (first crossing).
    // So each mode loses stability at f_k = omega_k sqrt(omega_k^2 + alpha^2) / (2 alpha sin(theta_k/2)).
    const int N = 5;
    const double alpha = 1.0, tau = 1.0;
    OvRing ring(N, alpha, tau, 1.0, 1.0, 1.2);
    // regular equilibrium: the Jacobian of the equilibrium equation is invertible
    const EquilibriumResult e = find_equilibrium(ring, ring.uniform_flow() + Eigen::VectorXd::Constant(2 * N - 1, 0.01));
    REQUIRE(e.status == Status::Converged);
    CHECK((e.x - ring.uniform_flow()).cwiseAbs().maxCoeff() < 1e-12);
    EquilibriumBranchOptions o;
    o.parameter = "headway";
    o.roots.count = 2;  // fewer than the unstable roots: the request must grow to count them all
    o.from = 1.2;
    o.to = 3.0;
    const EquilibriumBranch br = equilibrium_branch(ring, ring.uniform_flow(), o);
    CHECK(br.status == Status::Converged);
    CHECK(br.points.front().stable);
    CHECK(br.points.back().stable);
    CHECK(br.folds.empty());
    // Mode N - k at -i omega is the conjugate of mode k at +i omega, so the crossings with omega > 0
    // are those of k = 1..N-1. Here f_k < max V' = 3 (1/2)^(2/3) / (3/2)^2 ~ 0.84 for k = 1, 2, 3
    // (f_4 ~ 2.3): two crossings each, one on either side of the inflection of V.
    REQUIRE(br.hopf.size() == 6);
    for (const HopfPoint& h : br.hopf) {
        CHECK(h.status == Status::Converged);
        const double f = ring.optimal_velocity_slope(h.par);
        bool matched = false;
        for (int k = 1; k < N; ++k) {
            const double th = 2 * pi * k / N;
            const double w = bisect([&](double ww) { return ww * tau - th / 2 + pi / 2 - std::atan(alpha / ww); }, 1e-9, 10.0);
            const double fk = w * std::sqrt(w * w + alpha * alpha) / (2 * alpha * std::sin(th / 2));
            if (std::abs(h.omega - w) < tol::special_point && std::abs(f - fk) < tol::special_point) matched = true;
        }
        CHECK_MESSAGE(matched, "Hopf point at headway " << h.par << ", omega " << h.omega << ", V' " << f);
        // on the uniform flow
        CHECK((h.x.head(N - 1).array() - h.par).abs().maxCoeff() < 1e-10);
    }
}

TEST_CASE("ov ring of 33 cars: all 38 Hopf points of the ring modes' closed form, modes crowding near the ends of the range" *
          doctest::test_suite("slow")) {
    // Near headway 1.3 and 2.69 the Hopf points of the ring modes k = 1, 2, 3, ... lie 0.0015 to
    // 0.005 apart, closer than the steps of the branch: several modes cross in one step. Every
    // crossing must be located (the count of unstable roots at the two ends of a step is explained
    // by the points located in it, else the step is refined); before that the modes 5 and 6 near
    // 1.31 were missed without notice (36 of 38, status converged).
    const int N = 33;
    const double alpha = 1.0, tau = 1.0;
    const std::vector<ClosedFormHopf> cf = ov_ring_hopf_closed_form(N, alpha, tau, 1.2, 3.0);
    REQUIRE(cf.size() == 38);
    OvRing ring(N, alpha, tau, 1.0, 1.0, 1.2);
    EquilibriumBranchOptions o;
    o.parameter = "headway";
    o.roots.count = 2;
    o.from = 1.2;
    o.to = 3.0;
    const EquilibriumBranch br = equilibrium_branch(ring, ring.uniform_flow(), o);
    INFO(br.message);
    for (const HopfPoint& h : br.hopf) INFO("hopf " << h.par << " " << to_string(h.status));
    CHECK(br.status == Status::Converged);
    CHECK(br.hopf.size() == cf.size());
    for (const ClosedFormHopf& c : cf) {
        int matched = 0;
        for (const HopfPoint& h : br.hopf)
            if (h.status == Status::Converged && std::abs(h.par - c.headway) < tol::special_point && std::abs(h.omega - c.omega) < tol::special_point) ++matched;
        CHECK_MESSAGE(matched == 1, "mode " << c.mode << ": headway " << c.headway << ", omega " << c.omega << " located " << matched << " times");
    }
    // in the order met along the branch (here increasing headway)
    for (std::size_t i = 1; i < br.hopf.size(); ++i) CHECK(br.hopf[i].par > br.hopf[i - 1].par);
}

TEST_CASE("ov ring of 33 cars: one step over six Hopf points locates all six (the step is refined until the counts agree)" *
          doctest::test_suite("slow")) {
    // one continuation step from headway 1.29 to 1.32: the modes k = 1..6 cross in it, the number
    // of unstable roots goes from 0 to 12
    const int N = 33;
    const double alpha = 1.0, tau = 1.0;
    const std::vector<ClosedFormHopf> cf = ov_ring_hopf_closed_form(N, alpha, tau, 1.29, 1.32);
    REQUIRE(cf.size() == 6);
    OvRing ring(N, alpha, tau, 1.0, 1.0, 1.29);
    EquilibriumBranchOptions o;
    o.parameter = "headway";
    o.roots.count = 2;
    o.from = 1.29;
    o.to = 1.32;
    // the step in the unknowns (65 states and the headway; about 5.9 times the headway's change):
    // the first step ends at about 1.318, past the six crossings, the second on the bound
    o.continuation.initial_step = o.continuation.max_step = 0.165;
    const EquilibriumBranch br = equilibrium_branch(ring, ring.uniform_flow(), o);
    REQUIRE(br.points.size() >= 2);
    CHECK(br.points[1].par > cf.back().headway);
    CHECK(br.points[1].unstable - br.points[0].unstable == 12);
    CHECK(br.status == Status::Converged);
    REQUIRE(br.hopf.size() == cf.size());
    for (std::size_t i = 0; i < cf.size(); ++i) {
        CHECK(br.hopf[i].status == Status::Converged);
        CHECK(std::abs(br.hopf[i].par - cf[i].headway) < tol::special_point);
        CHECK(std::abs(br.hopf[i].omega - cf[i].omega) < tol::special_point);
    }
}

TEST_CASE("continuation in a delay: x' = -x(t - 2 c) + x^3 continued in c, Hopf at 2 c = pi/2, omega = 1") {
    // linearisation y' = -y(t - tau) with tau = 2 c: Hopf at tau = pi/2, omega = 1 (a = 1 above)
    ExpressionSystem sys({"x"}, {"c"}, {0.2}, {"-x(t - 2*c) + x^3"});
    EquilibriumBranchOptions o;
    o.parameter = "c";
    o.from = 0.2;
    o.to = 1.5;
    const EquilibriumBranch br = equilibrium_branch(sys, Eigen::VectorXd::Zero(1), o);
    CHECK(br.status == Status::Converged);
    REQUIRE(br.hopf.size() == 1);
    CHECK(std::abs(br.hopf[0].par - pi / 4) < tol::special_point);
    CHECK(std::abs(br.hopf[0].omega - 1.0) < tol::special_point);
}

TEST_CASE("ov ring: the eliminated headway against the ring written as expressions, and the structural zero of the full ring") {
    // three cars; V written out for h > h_st (every point used here has h > h_st)
    const std::string V = "vmax*(H/hs - 1)^3/(1 + (H/hs - 1)^3)";
    auto v_of = [&](const std::string& h) {
        std::string s = V;
        for (std::size_t at; (at = s.find('H')) != std::string::npos;) s.replace(at, 1, h);
        return s;
    };
    const std::vector<std::string> pars{"alpha", "tau", "vmax", "hs", "hm"};
    const std::vector<double> vals{1.3, 0.9, 1.1, 1.0, 2.1};
    // reduced: h2 = 3 hm - h0 - h1
    ExpressionSystem reduced({"h0", "h1", "u0", "u1", "u2"}, pars, vals,
                             {"u1 - u0", "u2 - u1", "alpha*(" + v_of("h0(t - tau)") + " - u0)", "alpha*(" + v_of("h1(t - tau)") + " - u1)",
                              "alpha*(" + v_of("(3*hm - h0(t - tau) - h1(t - tau))") + " - u2)"});
    OvRing ring(3, 1.3, 0.9, 1.1, 1.0, 2.1);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> U(1.5, 2.5);
    for (int trial = 0; trial < 10; ++trial) {
        Eigen::VectorXd u(10);
        for (int i = 0; i < 10; ++i) u[i] = U(rng);
        CHECK((ring.f(u) - reduced.f(u)).cwiseAbs().maxCoeff() < 1e-14);
        const auto a = ring.jacobians(u), b = reduced.jacobians(u);
        CHECK((a[0] - b[0]).cwiseAbs().maxCoeff() < 1e-14);
        CHECK((a[1] - b[1]).cwiseAbs().maxCoeff() < 1e-14);
    }
    // the full ring (three headways): its equilibria are not isolated, so Newton meets a singular
    // Jacobian and the linearisation has the root 0; the reduced ring converges
    ExpressionSystem full({"h0", "h1", "h2", "u0", "u1", "u2"}, pars, vals,
                          {"u1 - u0", "u2 - u1", "u0 - u2", "alpha*(" + v_of("h0(t - tau)") + " - u0)",
                           "alpha*(" + v_of("h1(t - tau)") + " - u1)", "alpha*(" + v_of("h2(t - tau)") + " - u2)"});
    Eigen::VectorXd xf(6);
    xf << 2.1, 2.1, 2.1, 0.0, 0.0, 0.0;
    xf.tail(3).setConstant(ring.optimal_velocity(2.1));
    CHECK(find_equilibrium(full, xf + Eigen::VectorXd::Constant(6, 0.01)).status == Status::NumericalIssue);
    const RootResult rf = rightmost_roots(linearise(full, xf));
    bool zero = false;
    for (const Root& r : rf.roots) zero = zero || std::abs(r.value) < 1e-12;
    CHECK(zero);
    CHECK(find_equilibrium(ring, ring.uniform_flow() + Eigen::VectorXd::Constant(5, 0.01)).status == Status::Converged);
    const RootResult rr = rightmost_roots(linearise(ring, ring.uniform_flow()));
    for (const Root& r : rr.roots) CHECK(std::abs(r.value) > 1e-6);
}

TEST_CASE("DDE-BIFTOOL demo 1 (neuron): the published Hopf points" * doctest::test_suite("reference")) {
    // DDE-Biftool, demos/neuron/html/demo1_hopf.html (published output of demo1_hopf.m): the
    // system of Shayer and Campbell with kappa = 0.5, beta = -1, a12 = 1, tau1 = tau2 = 0.2 at
    // the trivial equilibrium. With tau_s = 1.5 the Hopf point is at a21 = 0.80712, omega = 0.78197;
    // with a21 = 0.207 the second Hopf point (corrected in tau_s) at tau_s = 8.6341, omega = 0.91575.
    const std::vector<std::string> eqs{"-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                                       "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"};
    ExpressionSystem neuron({"x1", "x2"}, {"kappa", "beta", "a12", "a21", "tau1", "tau2", "taus"}, {0.5, -1, 1, 0.5, 0.2, 0.2, 1.5}, eqs);
    EquilibriumBranchOptions o;
    o.parameter = "a21";
    o.from = 0.3;
    o.to = 2.0;
    const EquilibriumBranch b1 = equilibrium_branch(neuron, Eigen::VectorXd::Zero(2), o);
    CHECK(b1.status == Status::Converged);
    REQUIRE(b1.hopf.size() == 1);
    CHECK(std::abs(b1.hopf[0].par / 0.80712 - 1) < tol::published_5_digits_rel);
    CHECK(std::abs(b1.hopf[0].omega / 0.78197 - 1) < tol::published_5_digits_rel);
    neuron.set_parameter("a21", 0.207);
    o.parameter = "taus";
    o.from = 5.0;
    o.to = 10.0;
    const EquilibriumBranch b2 = equilibrium_branch(neuron, Eigen::VectorXd::Zero(2), o);
    CHECK(b2.status == Status::Converged);
    bool found = false;
    for (const HopfPoint& h : b2.hopf)
        found = found || (std::abs(h.par / 8.6341 - 1) < tol::published_5_digits_rel && std::abs(h.omega / 0.91575 - 1) < tol::published_5_digits_rel);
    CHECK(found);
    // the other pair crosses close by (a double Hopf point nearby, as the demo notes): two Hopf points
    CHECK(b2.hopf.size() == 2);
}

TEST_CASE("equilibrium branch inputs and failures") {
    ExpressionSystem sys({"x"}, {"p"}, {1.0}, {"p - x^2"});
    EquilibriumBranchOptions o;
    o.parameter = "q";
    o.from = 0.5;
    o.to = 1.0;
    CHECK_THROWS_WITH_AS(equilibrium_branch(sys, Eigen::VectorXd::Ones(1), o),
                         "parameter 'q' is not a parameter of this system: expected one of p", std::invalid_argument);
    o.parameter = "p";
    o.to = 0.5;
    CHECK_THROWS_AS(equilibrium_branch(sys, Eigen::VectorXd::Ones(1), o), std::invalid_argument);
    // no equilibrium for p < 0: a status, not an exception
    o.from = -1.0;
    o.to = 1.0;
    const EquilibriumBranch br = equilibrium_branch(sys, Eigen::VectorXd::Ones(1), o);
    CHECK(br.status != Status::Converged);
    CHECK(br.points.empty());
    CHECK(br.message.find("no equilibrium at p = -1") == 0);
}

TEST_SUITE_END();

namespace {

/// Central differences of F (step 1e-5 max(1, |z_c|)) column by column.
template <class F>
Eigen::MatrixXd central_differences(F f, const Eigen::VectorXd& z) {
    Eigen::VectorXd f0;
    REQUIRE(f(z, f0));
    Eigen::MatrixXd j(f0.size(), z.size());
    for (Eigen::Index c = 0; c < z.size(); ++c) {
        const double h = 1e-5 * std::max(1.0, std::abs(z[c]));
        Eigen::VectorXd zp = z, zm = z, fp, fm;
        zp[c] += h;
        zm[c] -= h;
        REQUIRE(f(zp, fp));
        REQUIRE(f(zm, fm));
        j.col(c) = (fp - fm) / (2.0 * h);
    }
    return j;
}

/// max over entries of |exact - fd| / max(1, |exact|).
double jacobian_mismatch(const Eigen::MatrixXd& exact, const Eigen::MatrixXd& fd) {
    return ((exact - fd).array().abs() / exact.array().abs().max(1.0)).maxCoeff();
}

/// r_{k+1} <= C r_k^2 for every step that starts below 0.1 and ends above the rounding floor
/// (1e-14: |F| ~ 1 evaluated in double precision); returns the largest ratio r_{k+1} / r_k^2 and
/// counts the steps checked.
double quadratic_constant(const std::vector<double>& r, int& steps) {
    double c = 0.0;
    steps = 0;
    for (std::size_t k = 0; k + 1 < r.size(); ++k)
        if (r[k] < 1e-1 && r[k + 1] > 1e-14) {
            c = std::max(c, r[k + 1] / (r[k] * r[k]));
            ++steps;
        }
    return c;
}

}  // namespace

TEST_CASE("fold and Hopf systems: the exact Jacobian agrees with central differences of the residuals" * doctest::test_suite("fast")) {
    // two delays tau and 2 tau that move with tau, so the parameter column has the tau_k' terms;
    // every parameter in turn is the free one; z is an arbitrary point (not a solution)
    ExpressionSystem sys({"x1", "x2"}, {"a", "b", "c", "tau"}, {0.7, 1.3, 0.4, 0.9},
                         {"x2 - a*x1*x2(t - 2*tau)", "-c*x2 - a*sin(x1) - x1^3 - b*(x1 - tanh(x1(t - tau)))*exp(0.3*x2(t - 2*tau))"});
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int j = 0; j < 4; ++j) {
        CAPTURE(j);
        Eigen::VectorXd zh(3 * 2 + 2);
        for (Eigen::Index i = 0; i < zh.size(); ++i) zh[i] = u(rng);
        zh[2] = 0.5 + 0.5 * std::abs(zh[2]);     // the parameter (a delay > 0 when j = 3)
        zh[7] = 1.0 + std::abs(zh[7]);           // omega
        VectorXc q0(2);
        q0 << cplx(u(rng), u(rng)), cplx(u(rng), u(rng));
        auto fh = [&](const Eigen::VectorXd& z, Eigen::VectorXd& f) { return hopf_system(sys, j, q0, z, f); };
        Eigen::VectorXd f;
        Eigen::MatrixXd jh;
        REQUIRE(hopf_system(sys, j, q0, zh, f, &jh));
        CHECK(jacobian_mismatch(jh, central_differences(fh, zh)) < tol::finite_difference);

        Eigen::VectorXd zf(2 * 2 + 1);
        for (Eigen::Index i = 0; i < zf.size(); ++i) zf[i] = u(rng);
        zf[2] = 0.5 + 0.5 * std::abs(zf[2]);
        const Eigen::Vector2d v0(u(rng), u(rng));
        auto ff = [&](const Eigen::VectorXd& z, Eigen::VectorXd& g) { return fold_system(sys, j, v0, z, g); };
        Eigen::MatrixXd jf;
        REQUIRE(fold_system(sys, j, v0, zf, f, &jf));
        CHECK(jacobian_mismatch(jf, central_differences(ff, zf)) < tol::finite_difference);
    }
    // the ov ring (its own delay_derivatives): the delay tau and the headway as free parameters
    const OvRing ring(3, 1.0, 0.8);
    const int n = ring.dimension();
    for (int j : {1, 4}) {
        CAPTURE(j);
        Eigen::VectorXd z(3 * n + 2);
        z << ring.uniform_flow() + 0.05 * Eigen::VectorXd::LinSpaced(n, -1.0, 1.0), ring.parameter_values()[static_cast<std::size_t>(j)],
            Eigen::VectorXd::LinSpaced(n, 0.1, 0.9), Eigen::VectorXd::LinSpaced(n, -0.5, 0.3), 0.8;
        const VectorXc q0 = VectorXc::Constant(n, cplx(0.3, -0.2));
        auto fh = [&](const Eigen::VectorXd& zz, Eigen::VectorXd& f) { return hopf_system(ring, j, q0, zz, f); };
        Eigen::VectorXd f;
        Eigen::MatrixXd jh;
        REQUIRE(hopf_system(ring, j, q0, z, f, &jh));
        CHECK(jacobian_mismatch(jh, central_differences(fh, z)) < tol::finite_difference);
    }
}

TEST_CASE("fold and Hopf points: Newton with the exact Jacobian converges quadratically" * doctest::test_suite("fast")) {
    // Hopf of x' = -a sin(x(t - tau)) + x^3 in a (a = pi/2, omega = pi/2 at tau = 1), from afar
    ExpressionSystem s1({"x"}, {"a", "tau"}, {1.0, 1.0}, {"-a*sin(x(t - tau)) + x^3"});
    const HopfPoint h1 = correct_hopf(s1, 0, Eigen::VectorXd::Constant(1, 0.05), 1.3, 1.3);
    // the same in the delay: x' = -x(t - 2 c) + x^3, Hopf at 2 c = pi/2 with omega = 1
    ExpressionSystem s2({"x"}, {"c"}, {0.5}, {"-x(t - 2*c) + x^3"});
    const HopfPoint h2 = correct_hopf(s2, 0, Eigen::VectorXd::Constant(1, -0.05), 0.65, 1.2);
    // fold of x' = p + x - exp(x(t - 1)): equilibria p = exp(x) - x, the fold at (x, p) = (0, 1)
    ExpressionSystem s3({"x"}, {"p"}, {1.0}, {"p + x - exp(x(t - 1))"});
    const FoldPoint f3 = correct_fold(s3, 0, Eigen::VectorXd::Constant(1, 0.6), 1.3);
    REQUIRE(h1.status == Status::Converged);
    REQUIRE(h2.status == Status::Converged);
    REQUIRE(f3.status == Status::Converged);
    CHECK(std::abs(h1.par - pi / 2) < tol::special_point);
    CHECK(std::abs(h1.omega - pi / 2) < tol::special_point);
    CHECK(std::abs(h2.par - pi / 4) < tol::special_point);
    CHECK(std::abs(h2.omega - 1.0) < tol::special_point);
    CHECK(std::abs(f3.par - 1.0) < tol::special_point);
    CHECK(std::abs(f3.x[0]) < tol::special_point);
    for (const std::vector<double>* r : {&h1.residuals, &h2.residuals, &f3.residuals}) {
        std::string seq;
        for (double x : *r) {
            char b[32];
            std::snprintf(b, sizeof b, "%.3e ", x);
            seq += b;
        }
        CAPTURE(seq);
        int steps = 0;
        const double c = quadratic_constant(*r, steps);
        CHECK(steps >= 2);
        CHECK(c <= tol::newton_quadratic);
        CHECK(r->back() <= 1e-13);
    }
}

TEST_CASE("neuron (DDE-BIFTOOL demo): the branch point a21 = (kappa - beta)^2 / a12 is a branch point, not a Hopf point" * doctest::test_suite("fast")) {
    // Shayer and Campbell's two-neuron model at x = 0 (tanh'(0) = 1): Delta(0) = [kappa - beta, -a12;
    // -a21, kappa - beta], det Delta(0) = (kappa - beta)^2 - a12 a21: a real root crosses 0 at
    // a21 = (kappa - beta)^2 / a12 = 2.25. The unstable complex pair of the Hopf point at
    // a21 = 0.807 meets the real axis shortly before (a21 ~ 2.22): neither is a Hopf point.
    ExpressionSystem sys({"x1", "x2"}, {"kappa", "beta", "a12", "a21", "tau1", "tau2", "taus"}, {0.5, -1.0, 1.0, 0.3, 0.2, 0.2, 1.5},
                         {"-kappa*x1 + beta*tanh(x1(t - taus)) + a12*tanh(x2(t - tau2))",
                          "-kappa*x2 + beta*tanh(x2(t - taus)) + a21*tanh(x1(t - tau1))"});
    for (double from : {0.3, 2.2}) {
        CAPTURE(from);
        EquilibriumBranchOptions o;
        o.parameter = "a21";
        o.from = from;
        o.to = from < 1.0 ? 3.0 : 2.35;
        const EquilibriumBranch br = equilibrium_branch(sys, Eigen::VectorXd::Zero(2), o);
        CHECK(br.status == Status::Converged);
        REQUIRE(br.folds.size() == 1);
        CHECK(br.folds[0].kind == "branch_point");
        CHECK(br.folds[0].status == Status::Converged);
        CHECK(std::abs(br.folds[0].par - 2.25) < tol::special_point);
        CHECK(br.folds[0].x.cwiseAbs().maxCoeff() < tol::special_point);
        for (const HopfPoint& h : br.hopf) CHECK(h.omega > 0.1);
        CHECK(br.hopf.size() == (from < 1.0 ? 1u : 0u));
    }
}

namespace {

/// The branch x = 0 of a scalar system in p from `from` to `to` (o set to it, 2 roots asked),
/// converged, with its one branch point located at p = 0.
EquilibriumBranch trivial_branch_with_branch_point(const ExpressionSystem& s, double from, double to, EquilibriumBranchOptions& o) {
    o.parameter = "p";
    o.from = from;
    o.to = to;
    o.roots.count = 2;
    EquilibriumBranch b = equilibrium_branch(s, Eigen::VectorXd::Zero(1), o);
    REQUIRE(b.status == Status::Converged);
    REQUIRE(b.folds.size() == 1);
    REQUIRE(b.folds.front().kind == "branch_point");
    CHECK(std::abs(b.folds.front().par) < 1e-10);
    return b;
}

}  // namespace

TEST_CASE("branch switching: Hutchinson's x' = x (p - x(t - 1)) from x = 0 onto x = p at the branch point p = 0, its Hopf point at p = pi/2" * doctest::test_suite("fast")) {
    ExpressionSystem s({"x"}, {"p"}, {-1.0}, {"x*(p - x(t - 1))"});
    EquilibriumBranchOptions o;
    const EquilibriumBranch b = trivial_branch_with_branch_point(s, -1.0, 2.0, o);
    const FoldPoint& bp = b.folds.front();
    const EquilibriumBranch nb = equilibrium_branch_from_branch_point(s, b, bp, o);
    REQUIRE(nb.status == Status::Converged);
    REQUIRE(nb.points.size() > 5);
    CHECK(nb.points.front().par == bp.par);  // from the branch point
    CHECK(nb.points.back().par == 2.0);      // towards --to
    for (const EquilibriumPoint& p : nb.points) {
        CAPTURE(p.par);
        CHECK(std::abs(p.x[0] - p.par) < 1e-12);  // the other branch is x = p exactly
        // its linearisation lambda = -p e^{-lambda}: stable for 0 < p < pi/2, unstable above
        if (p.par > 1e-6 && p.par < pi / 2 - 1e-3) CHECK(p.stable);
        if (p.par > pi / 2 + 1e-3) CHECK(!p.stable);
    }
    REQUIRE(nb.hopf.size() == 1);
    CHECK(std::abs(nb.hopf.front().par - pi / 2) < 1e-9);
    CHECK(std::abs(nb.hopf.front().omega - pi / 2) < 1e-9);
    CHECK(nb.folds.empty());  // the branch point it starts from is not listed again
    // the other side (from and to swapped): x = p for p < 0, one real root > 0 (lambda = |p| e^{-lambda})
    EquilibriumBranchOptions back = o;
    back.from = 2.0;
    back.to = -1.0;
    const EquilibriumBranch other = equilibrium_branch_from_branch_point(s, b, bp, back);
    REQUIRE(other.status == Status::Converged);
    CHECK(other.points.back().par == -1.0);
    for (const EquilibriumPoint& p : other.points) {
        CHECK(std::abs(p.x[0] - p.par) < 1e-12);
        if (p.par < -1e-6) CHECK(p.unstable == 1);
    }
    // a fold is not a branch point
    FoldPoint fold = bp;
    fold.kind = "fold";
    CHECK_THROWS_AS(equilibrium_branch_from_branch_point(s, b, fold, o), std::invalid_argument);
}

TEST_CASE("branch switching at a pitchfork: both halves x = +-sqrt(p) of x' = x (p - x(t - 1)^2), joined through the point, each with its Hopf point" * doctest::test_suite("fast")) {
    // x = 0 loses stability at p = 0 (lambda = p), where x = +-sqrt(p) branch off towards p > 0;
    // on them lambda = -2 p e^{-lambda}: stable for p < pi/4, a Hopf point at p = pi/4, omega = pi/2
    ExpressionSystem s({"x"}, {"p"}, {-1.0}, {"x*(p - x(t - 1)^2)"});
    EquilibriumBranchOptions o;
    const EquilibriumBranch b = trivial_branch_with_branch_point(s, -1.0, 1.0, o);
    const FoldPoint& bp = b.folds.front();
    // one half only (the default): every point on one side, x = +sqrt(p) or -sqrt(p)
    const EquilibriumBranch one = equilibrium_branch_from_branch_point(s, b, bp, o);
    REQUIRE(one.status == Status::Converged);
    const double sign = one.points.back().x[0] > 0.0 ? 1.0 : -1.0;
    for (const EquilibriumPoint& p : one.points) CHECK(std::abs(p.x[0] - sign * std::sqrt(std::max(0.0, p.par))) < 1e-10);
    // swapping from and to cannot reach the other half; BranchSide::Away does
    const EquilibriumBranch away = equilibrium_branch_from_branch_point(s, b, bp, o, BranchSide::Away);
    REQUIRE(away.status == Status::Converged);
    CHECK(away.points.back().par == 1.0);
    for (const EquilibriumPoint& p : away.points) CHECK(std::abs(p.x[0] + sign * std::sqrt(std::max(0.0, p.par))) < 1e-10);
    // both: the away half reversed, the point, the default half
    const EquilibriumBranch both = equilibrium_branch_from_branch_point(s, b, bp, o, BranchSide::Both);
    REQUIRE(both.status == Status::Converged);
    REQUIRE(both.points.size() == one.points.size() + away.points.size() - 1);
    const std::size_t mid = away.points.size() - 1;
    CHECK(both.points[mid].par == bp.par);
    CHECK(both.points.front().par == 1.0);
    CHECK(both.points.back().par == 1.0);
    for (std::size_t k = 0; k < both.points.size(); ++k) {
        const EquilibriumPoint& p = both.points[k];
        CAPTURE(p.par);
        const double branch_sign = k < mid ? -sign : sign;
        if (k != mid) CHECK(std::abs(p.x[0] - branch_sign * std::sqrt(p.par)) < 1e-10);
        if (p.par > 1e-6 && p.par < pi / 4 - 1e-3) CHECK(p.stable);
        if (p.par > pi / 4 + 1e-3) CHECK(!p.stable);
    }
    // a Hopf point on each half, at p = pi/4 with omega = pi/2, between the points it lies between
    REQUIRE(both.hopf.size() == 2);
    for (const HopfPoint& h : both.hopf) {
        CHECK(std::abs(h.par - pi / 4) < 1e-9);
        CHECK(std::abs(h.omega - pi / 2) < 1e-9);
        REQUIRE((h.after >= 0 && h.after + 1 < static_cast<int>(both.points.size())));
        const double p0 = both.points[static_cast<std::size_t>(h.after)].par, p1 = both.points[static_cast<std::size_t>(h.after) + 1].par;
        CHECK((std::min(p0, p1) <= h.par && h.par <= std::max(p0, p1)));
    }
    CHECK(both.hopf[0].x[0] * both.hopf[1].x[0] < 0.0);  // one on each half
    CHECK(both.folds.empty());
}

TEST_CASE("branch switching: two lines of equilibria crossing obliquely, x = 2p and x = p of x' = (x - 2p)(x(t - 1) - p)" * doctest::test_suite("fast")) {
    ExpressionSystem s({"x"}, {"p"}, {-1.0}, {"(x - 2*p)*(x(t - 1) - p)"});
    EquilibriumBranchOptions o;
    o.parameter = "p";
    o.from = -1.0;
    o.to = 1.0;
    o.roots.count = 2;
    const EquilibriumBranch b = equilibrium_branch(s, Eigen::VectorXd::Constant(1, -2.0), o);
    REQUIRE(b.status == Status::Converged);
    for (const EquilibriumPoint& p : b.points) CHECK(std::abs(p.x[0] - 2.0 * p.par) < 1e-12);
    REQUIRE(b.folds.size() == 1);
    REQUIRE(b.folds.front().kind == "branch_point");
    const EquilibriumBranch nb = equilibrium_branch_from_branch_point(s, b, b.folds.front(), o);
    REQUIRE(nb.status == Status::Converged);
    CHECK(nb.points.back().par == 1.0);
    for (const EquilibriumPoint& p : nb.points) CHECK(std::abs(p.x[0] - p.par) < 1e-12);
}
