#include <doctest/doctest.h>

#include <cmath>

#include "ddemap/solve/integrate.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/study/growth.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {
/// Exact solution of y'(t) = -y(t - tau), y = 1 for t <= 0 (method of steps):
/// y(t) = sum_{k=0}^{floor(t/tau)+1} (-1)^k (t - (k-1) tau)^k / k!
double exact(double t, double tau) {
    double y = 0.0, fact = 1.0;
    const int m = static_cast<int>(std::floor(t / tau)) + 1;
    for (int k = 0; k <= m; ++k) {
        if (k > 0) fact *= k;
        y += ((k % 2) ? -1.0 : 1.0) * std::pow(t - (k - 1) * tau, k) / fact;
    }
    return y;
}

double solve(double tau, double h, double t_end) {
    DdeSolver s(
        1, 0.0, [](double, double* y) { y[0] = 1.0; },
        [tau](double t, const double* y, const DdeSolver& sol, double* dy) {
            (void)y;
            dy[0] = -sol.value(0, t - tau);
        });
    std::vector<double> marks;
    for (int k = 1; k * tau < t_end; ++k) marks.push_back(k * tau);
    s.integrate(t_end, h, marks);
    return s.state()[0];
}
}  // namespace

TEST_CASE("the DDE integrator converges with order 4 (y' = -y(t - tau), exact by the method of steps)") {
    for (double tau : {1.0, 0.7}) {
        const double t_end = 5.0;
        std::vector<double> errors;
        for (double h : {0.1, 0.05, 0.025, 0.0125}) errors.push_back(std::abs(solve(tau, h, t_end) - exact(t_end, tau)));
        for (std::size_t i = 1; i < errors.size(); ++i) {
            const double order = std::log2(errors[i - 1] / errors[i]);
            CAPTURE(tau);
            CAPTURE(i);
            CAPTURE(errors[i]);
            CHECK(order > 3.6);
            CHECK(order < 4.4);
        }
        CHECK(errors.back() < 1e-8);
    }
}

TEST_CASE("equilibrium stays equilibrium") {
    const auto m = std::shared_ptr<const CarModel>(make_model("ovrv", {{"k1", 0.05}, {"k2", 0.3}, {"th", 1.2}, {"tau", 0.6}, {"eta", 8}}));
    const LeadProfile lead({0.0, 100.0}, {20.0, 20.0});
    std::vector<SimCar> cars(5, SimCar{m, 0.0, "x"});
    const SimResult r = simulate_platoon(lead, cars);
    for (int i = 1; i <= 5; ++i) {
        for (std::size_t k = 0; k < r.time.size(); ++k) {
            CHECK(std::abs(r.speed[i][k] - 20.0) < 1e-12);
            CHECK(std::abs(r.gap[i][k] - (8 + 1.2 * 20)) < 1e-10);
        }
    }
    CHECK(r.events.empty());
}

TEST_CASE("a small oscillation amplifies per car at the rate |Gamma(iw)| predicts") {
    for (const char* model : {"ovrv", "idm"}) {
        CAPTURE(model);
        const ParameterMap p = std::string(model) == "ovrv"
                                   ? ParameterMap{{"k1", 0.052}, {"k2", 0.19}, {"th", 0.725}, {"tau", 0.468}}
                                   : ParameterMap{{"th", 1.2}, {"tau", 0.5}, {"speed", 20.0}, {"a", 0.8}};
        const auto m = std::shared_ptr<const CarModel>(make_model(model, p));
        const double v0 = m->operating_speed();
        const StringResult s = analyse_string(m->linearise());
        const double w = s.omega_peak > 0 ? s.omega_peak : 0.3;
        const double gain = std::abs(TransferFunction(m->linearise())(cplx(0.0, w)));
        const double eps = std::string(model) == "ovrv" ? 0.5 : 0.01;  // OVRV is affine: any amplitude
        std::vector<double> t, v;
        for (double x = 0.0; x <= 600.0; x += 0.02) {
            t.push_back(x);
            v.push_back(v0 + eps * std::sin(w * x) * (1.0 - std::exp(-x / 20.0)));
        }
        const LeadProfile lead(t, v);
        SimOptions o;
        o.t_end = 600.0;
        o.step = 0.02;
        const SimResult r = simulate_platoon(lead, std::vector<SimCar>(3, SimCar{m, 0.0, model}), o);
        // amplitude of each car over the last 100 s
        auto amplitude = [&](int car) {
            double lo = 1e300, hi = -1e300;
            for (std::size_t k = 0; k < r.time.size(); ++k)
                if (r.time[k] > 500.0) {
                    lo = std::min(lo, r.speed[car][k]);
                    hi = std::max(hi, r.speed[car][k]);
                }
            return 0.5 * (hi - lo);
        };
        for (int car = 1; car <= 3; ++car) {
            const double ratio = amplitude(car) / amplitude(car - 1);
            CAPTURE(car);
            CHECK(ratio == doctest::Approx(gain).epsilon(std::string(model) == "ovrv" ? 2e-3 : 2e-2));
        }
    }
}

TEST_CASE("the paper's dip grows through a platoon of A_min cars until the platoon fails") {
    const auto& a_min = paper_calibration_table()[0];
    SimOptions o;
    o.on_event = OnEvent::Stop;
    const SimResult r = simulate_platoon(LeadProfile::builtin("dip"), platoon_of(a_min, 15), o);
    REQUIRE(r.stopped);
    REQUIRE_FALSE(r.events.empty());
    const SimEvent& first = r.events.front();
    CHECK(first.car > 1);
    // string unstable: the speed drop grows along the platoon ahead of the first failure
    for (int i = 1; i < first.car - 1; ++i) CHECK(r.cars[i].speed_drop > r.cars[i - 1].speed_drop);
    CHECK(r.cars[0].speed_drop > 2.7);
    // the event is where the state says: a collision at zero gap or a disengagement at 11.176 m/s
    if (first.type == "collision") CHECK(first.gap == 0.0);
    else CHECK(first.speed == doctest::Approx(11.176));
}

TEST_CASE("lead profiles: exact position, validation, CSV errors") {
    const LeadProfile p({0.0, 10.0, 20.0}, {10.0, 20.0, 20.0});
    CHECK(p.position(10.0) == doctest::Approx(150.0));
    CHECK(p.position(30.0) == doctest::Approx(150.0 + 400.0));
    CHECK(p.speed(5.0) == doctest::Approx(15.0));
    CHECK_THROWS_AS(LeadProfile({0.0, 0.0}, {1.0, 1.0}), std::invalid_argument);
    CHECK_THROWS_AS(LeadProfile({0.0, 1.0}, {1.0, -1.0}), std::invalid_argument);
    CHECK_THROWS_WITH_AS(LeadProfile::from_csv("time_s,lead_speed_mps\n0,20\n1,x\n", "lead.csv"),
                         "lead.csv:3: column 'lead_speed_mps' = 'x': expected a finite number", std::invalid_argument);
    CHECK_THROWS_WITH_AS(LeadProfile::from_csv("t,v\n0,20\n", "lead.csv"), "lead.csv:1: missing column 'time_s' (expected time_s, lead_speed_mps)",
                         std::invalid_argument);
    CHECK_THROWS_AS(LeadProfile::builtin("wave"), std::invalid_argument);
    const LeadProfile dip = LeadProfile::builtin("dip");
    CHECK(dip.speed(0.0) == doctest::Approx(22.4));
    CHECK(dip.speed(30.0) == doctest::Approx(19.7));
    CHECK(dip.speed(200.0) == doctest::Approx(22.4));
}

TEST_CASE("one minimum ACC speed rule for built-in and CSV vehicles (platoon_from)") {
    // built in: the record's value (make 1: 25 mph; make 2: none)
    const auto a = platoon_from(read_cars("A_min*2,E_min"));
    REQUIRE(a.size() == 3);
    CHECK(a[0].min_speed == doctest::Approx(11.176));
    CHECK(a[1].min_speed == doctest::Approx(11.176));
    CHECK(a[2].min_speed == 0.0);
    CHECK(a[2].name == "E_min");
    // CSV: the optional min_acc_speed column, default 0
    const auto v = read_vehicles_csv("name,k1,k2,th,tau,min_acc_speed\nx,0.1,0.2,1,0.3,11.176\ny,0.1,0.2,1,0.3,\n", "v.csv");
    const auto c = platoon_from(v);
    REQUIRE(c.size() == 2);
    CHECK(c[0].min_speed == doctest::Approx(11.176));
    CHECK(c[1].min_speed == 0.0);
    CHECK(platoon_from(read_vehicles_csv("name,k1,k2,th,tau\nx,0.1,0.2,1,0.3\n", "w.csv"))[0].min_speed == 0.0);
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,min_acc_speed\nx,0.1,0.2,1,0.3,-1\n", "b.csv"),
                         "b.csv:2: min_acc_speed = -1: expected 0 to 100 m/s", std::invalid_argument);
    CHECK_THROWS_WITH_AS(builtin_vehicle("Z_min"), doctest::Contains("'Z_min'"), std::invalid_argument);
}

TEST_SUITE_END();

TEST_CASE("a diverging platoon stops with a status and the time, and outputs only finite values" * doctest::test_suite("fast")) {
    // k1 = k2 = 1000 with tau = 0.5: the delayed speed feedback alone, v' = -k2 v(t - tau), is
    // unstable for k2 tau > pi/2 (here 500), so the solution grows without bound (the speeds
    // overflow to inf within seconds). The linear analysis refuses these gains (c tau = 2250 is
    // outside its computable range); the simulation has no such range and must stop cleanly.
    const ParameterMap p{{"k1", 1000.0}, {"k2", 1000.0}, {"th", 1.5}, {"tau", 0.5}, {"eta", 10.0}};
    const auto m = std::shared_ptr<const CarModel>(make_model("ovrv", p));
    CHECK_THROWS_AS(analyse_string(m->linearise()), std::invalid_argument);
    const std::vector<SimCar> cars(2, SimCar{m, 0.0, "x"});
    const SimResult r = simulate_platoon(LeadProfile::builtin("dip"), cars);
    CHECK(r.status == Status::NumericalIssue);
    CHECK(r.diverged_at > 0.0);
    CHECK(r.t_end < r.diverged_at);
    CHECK(r.message.find("diverged at t = ") != std::string::npos);
    REQUIRE_FALSE(r.time.empty());
    CHECK(r.time.back() <= r.t_end);
    const SimOptions defaults;
    for (std::size_t c = 0; c < r.speed.size(); ++c)
        for (std::size_t k = 0; k < r.time.size(); ++k) {
            CHECK(std::isfinite(r.position[c][k]));
            CHECK(std::abs(r.speed[c][k]) <= defaults.max_speed);
            if (c > 0) CHECK(std::isfinite(r.gap[c][k]));
        }
    for (const auto& c : r.cars) CHECK((std::isfinite(c.min_speed) && std::isfinite(c.min_gap)));
}

TEST_CASE("the simulation estimate bounds the steps the run takes and counts its output samples" * doctest::test_suite("fast")) {
    const auto& a_min = paper_calibration_table()[0];
    SimOptions o;
    o.step = 0.05;
    const auto cars = platoon_of(a_min, 3);
    const LeadProfile lead = LeadProfile::builtin("dip");
    const SimEstimate e = estimate_simulation(lead, cars, o);
    const SimResult r = simulate_platoon(lead, cars, o);
    CHECK(r.status == Status::Converged);
    CHECK(e.t_end == r.t_end);
    CHECK(static_cast<double>(r.steps) <= e.steps);
    CHECK(static_cast<double>(r.steps) >= e.t_end / o.step);  // at least t_end / h steps
    CHECK(e.samples == static_cast<double>(r.time.size()));
    CHECK(e.car_steps == e.steps * 3);
    // --t-end 1e9 is sized (and can be refused) before any memory is taken
    o.t_end = 1e9;
    CHECK(estimate_simulation(lead, cars, o).memory_bytes > 1e12);
}
