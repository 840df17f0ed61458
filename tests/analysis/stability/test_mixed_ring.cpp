// Mixed rings: equilibrium, assembly, the sparse path against Fourier modes and a dense
// eigen-decomposition, order (in)variance, prod Gamma_i = 1, bad fleet input, penetration study.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>

#include "ddemap/discretize/collocation.hpp"
#include "ddemap/study/penetration.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "fleet_helpers.hpp"
#include "tolerances.hpp"
#include "numeric_helpers.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
using ddemap::test::nearest;
namespace tol = ddemap::test::tol;
using ddemap::test::linearised;
using ddemap::test::random_car;

namespace {

std::vector<cplx> eigenvalues_of(const std::vector<Root>& roots) {
    std::vector<cplx> v;
    for (const auto& r : roots) v.push_back(r.eigenvalue);
    return v;
}

std::vector<cplx> values(const std::vector<Root>& roots) {
    std::vector<cplx> v;
    for (const auto& r : roots) v.push_back(r.value);
    return v;
}

MixedRingOptions at_speed(int count, const std::string& method) {
    MixedRingOptions o;
    o.speed = 20.0;
    o.roots.count = count;
    o.roots.method = method;
    return o;
}

}  // namespace

TEST_CASE("ring equilibrium: common speed and ring length are inverse to each other") {
    const Fleet f = fleet_from_pattern("A_min,C_max*2,E_min", 9);
    REQUIRE(f.size() == 9);
    CHECK(f[0].label == "A_min");
    CHECK(f[3].label == "E_min");
    CHECK(f[4].label == "A_min");
    const RingEquilibrium e = ring_equilibrium_at_speed(f, 17.5);
    double sum = 0.0;
    for (std::size_t i = 0; i < f.size(); ++i) {
        const double gap = f[i].parameters.at("eta") + f[i].parameters.at("th") * 17.5;  // OVRV: s* = eta + th v
        CHECK(e.gaps[i] == doctest::Approx(gap).epsilon(1e-14));
        sum += gap;
    }
    CHECK(e.length == doctest::Approx(sum).epsilon(1e-14));
    const RingEquilibrium back = ring_equilibrium_at_length(f, e.length);
    CHECK(std::abs(back.speed - 17.5) < 1e-9);
    // IDM mixed in: s*(v) -> infinity as v -> v0, the bisection still brackets
    Fleet g = f;
    g[1] = parse_fleet_car("idm:th=1.2,tau=0.4,v0=30");
    const RingEquilibrium ge = ring_equilibrium_at_speed(g, 25.0);
    CHECK(std::abs(ring_equilibrium_at_length(g, ge.length).speed - 25.0) < 1e-9);
    CHECK_THROWS_WITH_AS(ring_equilibrium_at_length(f, 10.0), doctest::Contains("sum of the standstill gaps"), std::invalid_argument);
}

TEST_CASE("homogeneous ring: the sparse path equals the Fourier-mode roots (N up to 200)" * doctest::test_suite("slow")) {
    const Linearisation lin = make_model("ovrv", fleet_from_pattern("C_max", 1)[0].parameters)->linearise();
    for (int n : {12, 60, 200}) {
        CAPTURE(n);
        const MixedRingResult sparse = analyse_mixed_ring(fleet_from_pattern("C_max", n), at_speed(10, "shift_invert"));
        REQUIRE(sparse.roots.status == Status::Converged);
        RingOptions ro;
        ro.roots.count = 12;
        const RingResult modes = analyse_ring(lin, n, ro);
        std::vector<cplx> fourier;
        for (const auto& r : modes.roots) fourier.push_back(r.root.value);
        REQUIRE(sparse.roots.roots.size() >= 10);
        for (const auto& r : sparse.roots.roots) {
            CAPTURE(r.value);
            CHECK(nearest(fourier, r.value) < tol::same_root);
        }
        CHECK(std::abs(sparse.spectral_abscissa - modes.spectral_abscissa) < tol::same_root);
        CHECK(sparse.stable == modes.stable);
    }
}

namespace {

/// One random fleet of n cars (every third one CCC): the sparse path's rightmost collocation
/// eigenvalues against a dense eigen-decomposition of the same degree-M collocation matrix.
void check_sparse_against_dense(std::mt19937& rng, int n, int degree) {
    std::vector<Linearisation> lins;
    for (int i = 0; i < n; ++i) {
        lins.push_back(linearised(random_car(rng, i % 3 == 2)));
    }
    const LinearDDE dde = mixed_ring_dde(lins);
    RootOptions o;
    o.method = "shift_invert";
    o.count = 6;
    o.degree = degree;
    o.shift_invert.refine = false;
    o.shift_invert.arnoldi_tolerance = 1e-13;
    const RootResult sp = rightmost_roots(dde, o);
    REQUIRE(sp.status == Status::Converged);
    const MatrixXc a = collocation_matrix(dde.to_dense(), sp.degree);
    Eigen::EigenSolver<Eigen::MatrixXd> es(a.real(), false);
    std::vector<cplx> dense(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
    std::sort(dense.begin(), dense.end(), [](cplx x, cplx y) { return x.real() > y.real(); });
    CAPTURE(n);
    // the certificate's rectangle: Re >= floor, |Im| <= height (outside it there are no roots,
    // only collocation artefacts of large modulus, which the dense matrix also has), and the
    // degree resolves |lambda| <= covered_radius (beyond it the collocation matrix has artefacts
    // that are not roots, which the Gershgorin cells rightly skip)
    dense.erase(std::remove_if(dense.begin(), dense.end(),
                               [&](cplx z) { return std::abs(z.imag()) > sp.height || std::abs(z) > sp.covered_radius; }),
                dense.end());
    // every dense eigenvalue right of the certified floor is among the sparse ones
    int in_strip = 0;
    for (cplx z : dense) {
        if (z.real() < sp.strip_floor - tol::sparse_vs_dense) break;  // the floor is the last listed one
        ++in_strip;
        CAPTURE(z);
        CHECK(nearest(eigenvalues_of(sp.roots), z) < tol::sparse_vs_dense);
    }
    // the same set: the sparse eigenvalues inside the resolved rectangle are exactly these
    std::vector<cplx> listed;
    for (cplx z : eigenvalues_of(sp.roots))
        if (std::abs(z.imag()) <= sp.height && std::abs(z) <= sp.covered_radius) listed.push_back(z);
    CHECK(listed.size() >= 2);
    CHECK(in_strip == static_cast<int>(listed.size()));
    for (std::size_t i = 0; i < listed.size() && i < dense.size(); ++i)
        CHECK(std::abs(listed[i].real() - dense[i].real()) < tol::sparse_vs_dense);
}

}  // namespace

TEST_CASE("random mixed fleets: the sparse path finds the rightmost collocation eigenvalues of a dense decomposition, none missed" * doctest::test_suite("slow")) {
    std::mt19937 rng(20261121);
    int draws = 0;
    for (int n : {4, 5, 8, 12, 20, 20, 30}) {
        for (int rep = 0; rep < (n <= 12 ? 4 : 1); ++rep) {
            CAPTURE(rep);
            check_sparse_against_dense(rng, n, 20);  // M = 20 resolves |lambda| <= 5 / (0.7 tau_max) >= 7
            ++draws;
        }
    }
    CHECK(draws == 19);
}

TEST_CASE("random mixed fleets of 45 and 60 cars: sparse against a dense decomposition (M = 16, 1920 and 2040 states)" * doctest::test_suite("slow")) {
    std::mt19937 rng(60);
    for (int n : {45, 60}) check_sparse_against_dense(rng, n, 16);  // M = 16 resolves |lambda| <= 1 / (0.7 tau_max)
}

TEST_CASE("predecessor-only mixed ring: permuting the cars leaves the spectrum unchanged and prod Gamma_i = 1 at every root" * doctest::test_suite("slow")) {
    std::mt19937 rng(7);
    Fleet fleet;
    for (int i = 0; i < 14; ++i) fleet.push_back(random_car(rng, false));
    Fleet shuffled = fleet;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    for (const char* method : {"shift_invert", "dense", "contour"}) {
        const MixedRingResult a = analyse_mixed_ring(fleet, at_speed(8, method));
        const MixedRingResult b = analyse_mixed_ring(shuffled, at_speed(8, method));
        REQUIRE(a.roots.status == Status::Converged);
        REQUIRE(b.roots.status == Status::Converged);
        REQUIRE(a.roots.roots.size() == b.roots.roots.size());
        for (const auto& r : a.roots.roots) CHECK(nearest(values(b.roots.roots), r.value) < tol::same_root);
        CHECK(a.product_residual < tol::product_residual);
        CHECK(b.product_residual < tol::product_residual);
    }
    // the check is not vacuous: a point that is not a root is far from prod Gamma_i = 1
    const std::vector<Linearisation> lins = linearise_fleet(fleet, 20.0);
    CHECK(ring_product_residual(lins, cplx(0.01, 0.3)) > 1e-3);
}

TEST_CASE("connected cruise control: the order matters, and sparse agrees with dense") {
    std::mt19937 rng(11);
    Fleet fleet;
    for (int i = 0; i < 10; ++i) fleet.push_back(random_car(rng, i < 5));  // 5 CCC cars in a row, then 5 OVRV
    Fleet alternating;
    for (int i = 0; i < 5; ++i) {
        alternating.push_back(fleet[i]);
        alternating.push_back(fleet[5 + i]);
    }
    double abscissa[2];
    int k = 0;
    for (const Fleet* f : {&fleet, &alternating}) {
        const MixedRingResult s = analyse_mixed_ring(*f, at_speed(8, "shift_invert"));
        const MixedRingResult d = analyse_mixed_ring(*f, at_speed(8, "dense"));
        REQUIRE(s.roots.status == Status::Converged);
        REQUIRE(d.roots.status == Status::Converged);
        CHECK(std::isnan(s.product_residual));  // no transfer-function product for CCC
        for (const auto& r : d.roots.roots) CHECK(nearest(values(s.roots.roots), r.value) < tol::same_root);
        CHECK(std::abs(s.spectral_abscissa - d.spectral_abscissa) < tol::same_root);
        abscissa[k++] = s.spectral_abscissa;
    }
    CHECK(std::abs(abscissa[0] - abscissa[1]) > tol::order_matters);
}

TEST_CASE("CCC homogeneous ring: the full system equals the Fourier modes with zeta^2 for the car two ahead") {
    const auto model = make_model("ccc", {{"k1", 0.2}, {"k2", 0.4}, {"k3", 0.2}, {"th", 1.2}, {"tau", 0.4}, {"tau2", 0.25}});
    const Linearisation lin = model->linearise();
    RingOptions ro;
    ro.roots.count = 10;
    const RingResult modes = analyse_ring(lin, 9, ro);
    const RootResult full = rightmost_roots(full_ring_dde(lin, 9), [] { RootOptions o; o.count = 12; return o; }());
    std::vector<cplx> all = values(full.roots);
    for (const auto& r : modes.roots) CHECK(nearest(all, r.root.value) < tol::same_root);
    ParameterMap p = model->parameters();
    p.erase("speed");
    const MixedRingResult sparse = analyse_mixed_ring(Fleet(9, FleetCar{"c", "ccc", p}), at_speed(8, "shift_invert"));
    REQUIRE(sparse.roots.status == Status::Converged);
    std::vector<cplx> fourier;
    for (const auto& r : modes.roots) fourier.push_back(r.root.value);
    for (const auto& r : sparse.roots.roots) CHECK(nearest(fourier, r.value) < tol::same_root);
    CHECK(std::abs(sparse.spectral_abscissa - modes.spectral_abscissa) < tol::same_root);
}

TEST_CASE("fleet input: patterns and CSV files, errors name the line and the column") {
    CHECK(fleet_from_pattern("A_min , E_max*2", 0).size() == 3);
    CHECK(fleet_from_pattern("A_min,E_max*2", 7).size() == 7);
    CHECK_THROWS_WITH_AS(fleet_from_pattern("A_min,Z_max", 4), doctest::Contains("'Z_max'"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(fleet_from_pattern("A_min,,B_min", 4), doctest::Contains("empty entry"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(fleet_from_pattern("A_min*0", 4), doctest::Contains("'A_min*0'"), std::invalid_argument);

    const Fleet f = read_fleet_csv("vehicle,model,k1,k2,th,tau,k3,tau2,count\n"
                                   "A_min,,,,,,,,3\n"
                                   "E_min,,,,,0.9,,,\n"
                                   ",ccc,0.1,0.3,1.2,0.4,0.2,0.1,2\n",
                                   "f.csv");
    REQUIRE(f.size() == 6);
    CHECK(f[3].parameters.at("tau") == 0.9);  // override of the calibrated value
    CHECK(f[4].model == "ccc");
    auto bad = [](const std::string& text, const std::string& needle) {
        CAPTURE(text);
        CHECK_THROWS_WITH_AS(read_fleet_csv(text, "f.csv"), doctest::Contains(needle.c_str()), std::invalid_argument);
    };
    bad("vehicle\nA_min\nQ_max\n", "f.csv:3: column 'vehicle' = 'Q_max'");
    bad("model,k1,k2,th,tau\novrv,0.1,x,1,0.5\n", "f.csv:2: column 'k2' = 'x'");
    bad("model,k1,k2,th,tau\novrv,0.1,-2,1,0.5\n", "f.csv:2: car 'ovrv@f.csv:2': k2 = -2");
    bad("model,k1,k2,th\novrv,0.1,0.2,1\n", "f.csv:2: car 'ovrv@f.csv:2': model ovrv needs tau");
    bad("vehicle,colour\nA_min,red\n", "column 'colour'");
    bad("vehicle,speed\nA_min,20\n", "column 'speed'");
    bad("k1,k2\n0.1,0.2\n", "the header needs a 'name', 'vehicle' or 'model' column");
    bad("vehicle,model\n,\n", "f.csv:2: car 'ovrv@f.csv:2': model ovrv needs k1");  // a blank row: the paper's law, whose gains are required
    bad("vehicle,count\nA_min,2.5\n", "f.csv:2: column 'count' = '2.5'");
    bad("model,k1,k2,th,tau\nidm,0.1,0.2,1,0.5\n", "f.csv:2: car 'idm@f.csv:2': parameter 'k1' does not belong to model idm");
    bad("vehicle\n", "no cars");
    CHECK_THROWS_WITH_AS(parse_fleet_car("ccc:k1=0.1,k2"), doctest::Contains("'k2'"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(analyse_mixed_ring(fleet_from_pattern("A_min", 1), at_speed(4, "auto")),
                         doctest::Contains("at least 2 cars"), std::invalid_argument);
}

TEST_CASE("penetration study: the end points are the homogeneous rings, the spread arrangement has k X cars") {
    const FleetCar x = parse_fleet_car("E_min"), y = parse_fleet_car("A_min");
    for (int k : {0, 3, 7, 10}) {
        const Fleet f = mixed_fleet(x, y, 10, k);
        CHECK(std::count_if(f.begin(), f.end(), [](const FleetCar& c) { return c.label == "E_min"; }) == k);
    }
    MixOptions o;
    o.cars = 10;
    o.fractions = {0.0, 0.5, 1.0};
    o.ring.speed = 20.0;
    o.ring.roots.count = 4;
    const std::vector<MixPoint> pts = penetration_study(x, y, o);
    REQUIRE(pts.size() == 3);
    const RingResult ya = analyse_ring(make_model("ovrv", y.parameters)->linearise(), 10);
    const RingResult xa = analyse_ring(make_model("ovrv", x.parameters)->linearise(), 10);
    CHECK(std::abs(pts[0].abscissa - ya.spectral_abscissa) < tol::same_root);
    CHECK(std::abs(pts[2].abscissa - xa.spectral_abscissa) < tol::same_root);
    CHECK(pts[1].x_cars == 5);
    for (const auto& p : pts) CHECK(p.status == Status::Converged);
}

TEST_SUITE_END();
