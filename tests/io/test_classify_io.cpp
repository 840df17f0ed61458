// The covariance travels from `calibrate`'s CSV to `classify`'s reader unchanged, and the
// classification outputs carry the probabilities only when a covariance was given.
#include <doctest/doctest.h>

#include <string>

#include "ddemap/io/csv.hpp"
#include "ddemap/io/json.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("calibration CSV covariance columns read back exactly by the vehicles reader") {
    CalibrationResult r;
    r.parameters = {{"k1", 0.1}, {"k2", 0.4}, {"th", 1.2}, {"tau", 0.5}, {"eta", 7.0}};
    Eigen::Matrix<double, 5, 5> m = Eigen::Matrix<double, 5, 5>::Random();
    const Eigen::Matrix<double, 5, 5> c = m * m.transpose() / 3.0;  // positive semidefinite, digits that need 17 places
    r.covariance = 0.5 * (c + c.transpose());                           // exactly symmetric
    for (int i = 0; i < 5; ++i) r.estimates[static_cast<std::size_t>(i)].standard_error = std::sqrt(r.covariance(i, i));
    r.status = "converged";
    const std::string csv = calibration_csv({"car"}, {r});
    const auto v = read_vehicles_csv(csv, "fits.csv");
    REQUIRE(v.size() == 1);
    CHECK(v[0].has_covariance);
    CHECK(v[0].covariance == r.covariance);
    CHECK(v[0].parameters.at("th") == 1.2);
    // a parameter the trace does not determine (infinite standard error): no covariance written
    r.estimates[3].standard_error = std::numeric_limits<double>::infinity();
    const auto w = read_vehicles_csv(calibration_csv({"car"}, {r}), "fits.csv");
    CHECK_FALSE(w[0].has_covariance);
    // no covariance columns: a plain vehicle table
    CHECK_FALSE(read_vehicles_csv("name,k1,k2,th,tau\nA,0.1,0.4,1.2,0.5\n", "plain.csv")[0].has_covariance);
    // some of the columns, a partly filled row, a negative variance: errors naming the problem
    CHECK_THROWS_WITH_AS(read_vehicles_csv("name,k1,k2,th,tau,cov_k1_k1\nA,0.1,0.4,1.2,0.5,1\n", "p.csv"),
                         doctest::Contains("1 of the 15 covariance columns"), std::invalid_argument);
    std::string header = "name,k1,k2,th,tau", row = "A,0.1,0.4,1.2,0.5";
    for (const auto& c : covariance_column_names()) {
        header += "," + c;
        row += c == "cov_k2_k2" ? ",-1" : ",0";
    }
    CHECK_THROWS_WITH_AS(read_vehicles_csv(header + "\n" + row + "\n", "n.csv"), doctest::Contains("cov_k2_k2"), std::invalid_argument);
    std::string partial = "A,0.1,0.4,1.2,0.5,1";
    for (int i = 1; i < 15; ++i) partial += ",";
    CHECK_THROWS_WITH_AS(read_vehicles_csv(header + "\n" + partial + "\n", "q.csv"), doctest::Contains("1 of the 15"), std::invalid_argument);
}

TEST_CASE("classification outputs: probabilities and intervals only for vehicles with a covariance") {
    CalibratedVehicle a;
    a.name = "a";
    a.parameters = {{"k1", 0.052}, {"k2", 0.338}, {"th", 0.819}, {"tau", 0.948}, {"eta", 8.0}};
    a.covariance = 1e-8 * Eigen::Matrix<double, 5, 5>::Identity();
    a.has_covariance = true;
    CalibratedVehicle b = a;
    b.name = "b";
    b.has_covariance = false;
    UncertaintyOptions o;
    o.samples = 50;
    o.ring_samples = 3;
    const auto rows = classify({a, b}, 22, o);
    const std::string json = classification_json(rows, 22, "x");
    CHECK(json.find("\"p_string_unstable\":1") != std::string::npos);
    CHECK(json.find("\"margin_intervals\"") != std::string::npos);
    const std::string csv = classification_csv(rows);
    CHECK(csv.find(",p_string_unstable,") != std::string::npos);
    // without any covariance the outputs are as before (no new columns or keys)
    const auto plain = classify({b}, 22, o);
    CHECK(classification_csv(plain).find("p_string_unstable") == std::string::npos);
    CHECK(classification_json(plain, 22, "x").find("p_string_unstable") == std::string::npos);
}
