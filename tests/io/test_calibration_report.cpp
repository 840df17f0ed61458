// The calibration report: test errors pooled per test type over a car's test runs (RMSE over
// all their samples), the held-out part of a windowed fit, and the three formats' shape.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "ddemap/io/calibration_report.hpp"
#include "ddemap/io/csv.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

namespace {

CarCalibration car(const std::string& name) {
    CarCalibration c;
    c.car = name;
    c.train_sources = {"data/" + name + "_train.csv"};
    const double v[5] = {0.05, 0.3, 1.2, 0.43, 15};
    for (int i = 0; i < 5; ++i) {
        ParameterEstimate& e = c.fit.estimates[static_cast<std::size_t>(i)];
        e.name = calibration_parameter_names()[static_cast<std::size_t>(i)];
        e.value = v[i];
        e.standard_error = 0.01;
        e.lower95 = v[i] - 0.02;
        e.upper95 = v[i] + 0.02;
        c.fit.parameters[e.name] = v[i];
    }
    c.fit.estimates[4].at_bound = true;
    c.fit.train = {0.1, 1.0, 100};
    c.fit.status = "converged";
    return c;
}

TestRun run(const std::string& type, double rv, double rg, double naive, int n) {
    TestRun t;
    t.source = type + ".csv";
    t.type = type;
    t.evaluation.errors = {rv, rg, n};
    t.evaluation.naive = {naive, 0.0, n};
    return t;
}

}  // namespace

TEST_CASE("calibration report: test errors pooled per type, held-out parts, CSV/JSON/Markdown") {
    std::vector<CarCalibration> cars = {car("a"), car("b")};
    cars[0].tests = {run("dips", 0.3, 2.0, 0.5, 100), run("low", 0.2, 1.0, 0.4, 50), run("dips", 0.6, 4.0, 0.5, 300)};
    cars[1].fit.test = {0.25, 1.5, 80};  // no test runs: the held-out window of its file
    const CalibrationReport rep = calibration_report(cars);
    REQUIRE(rep.test_types == std::vector<std::string>{"dips", "low", "held out"});
    REQUIRE(rep.rows.size() == 2);
    // RMSE over all 400 samples of the two dips runs
    const FitErrors& d = rep.rows[0].test[0];
    CHECK(d.samples == 400);
    CHECK(d.rmse_speed == doctest::Approx(std::sqrt((100 * 0.09 + 300 * 0.36) / 400.0)).epsilon(test::tol::regrouped_sum));
    CHECK(d.rmse_gap == doctest::Approx(std::sqrt((100 * 4.0 + 300 * 16.0) / 400.0)).epsilon(test::tol::regrouped_sum));
    CHECK(rep.rows[0].naive_test[0].rmse_speed == doctest::Approx(0.5).epsilon(test::tol::regrouped_sum));
    CHECK(rep.rows[0].test[2].samples == 0);
    CHECK(rep.rows[1].test[0].samples == 0);
    CHECK(rep.rows[1].test[2].rmse_speed == doctest::Approx(0.25).epsilon(test::tol::regrouped_sum));

    const std::string csv = calibration_report_csv(rep);
    std::istringstream lines(csv);
    std::string header, row_a, row_b;
    std::getline(lines, header);
    std::getline(lines, row_a);
    std::getline(lines, row_b);
    CHECK(header.rfind("car,train_runs,k1_per_s2,k1_lo_per_s2,k1_hi_per_s2,k2_per_s,", 0) == 0);
    CHECK(header.find(",dips_rmse_speed_mps,dips_rmse_gap_m,dips_naive_rmse_speed_mps,dips_samples,low_rmse_speed_mps,") != std::string::npos);
    CHECK(header.find(",held out_rmse_speed_mps,") != std::string::npos);
    CHECK(row_a.rfind("a,data/a_train.csv," + format_exact(0.05) + ",", 0) == 0);
    CHECK(row_b.find(",,,,0,") != std::string::npos);  // car b has no dips run
    CHECK(std::count(header.begin(), header.end(), ',') == std::count(row_a.begin(), row_a.end(), ','));
    CHECK(std::count(header.begin(), header.end(), ',') == std::count(row_b.begin(), row_b.end(), ','));

    const std::string json = calibration_report_json(rep);
    CHECK(json.find("\"test_types\"") != std::string::npos);
    CHECK(json.find("\"held out\"") != std::string::npos);

    const std::string md = calibration_report_markdown(rep, CalibrationOptions{});
    CHECK(md.find("| a | a_train |") != std::string::npos);  // the common start "data/" is not a file-name prefix: kept out by base_name
    CHECK(md.find("**15**") != std::string::npos);           // eta on its bound
    CHECK(md.find("| speed dips / naive | speed low / naive | speed held out / naive |") != std::string::npos);
}

TEST_CASE("run lists: roles, default type, errors name the line") {
    const auto runs = read_run_list_csv("car,file,role,type\nx,a.csv,train,\nx,b.csv,test,dips\nx,c.csv,test,\n", "runs.csv");
    REQUIRE(runs.size() == 3);
    CHECK(runs[0].role == "train");
    CHECK(runs[1].type == "dips");
    CHECK(runs[2].type == "test");
    CHECK_THROWS_WITH_AS(read_run_list_csv("car,file,role\nx,a.csv,fit\n", "runs.csv"), doctest::Contains("runs.csv:2"), std::invalid_argument);
    CHECK_THROWS_AS(read_run_list_csv("car,file\nx,a.csv\n", "runs.csv"), std::invalid_argument);
    CHECK_THROWS_AS(read_run_list_csv("car,file,role\n", "runs.csv"), std::invalid_argument);
}

TEST_SUITE_END();
