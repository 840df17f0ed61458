// One way to name cars (io/cars.hpp) and one table of cars (traffic/vehicles.hpp read_car_table):
// every syntax, repeats and counts, what calibrate writes, and bad input named.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "ddemap/io/cars.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "ddemap/traffic/vehicles.hpp"
#include "temp_dir.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace fs = std::filesystem;

namespace {

using Folder = ddemap::test::TempDir;

const std::string kTable =
    "name,k1,k2,th,tau,eta\n"
    "Sedan,0.2,0.6,2,0.2,5\n"
    "SUV,0.1,0.3,1.5,0.5,8\n"
    "Hatchback,0.15,0.4,1.2,0.3,\n";

}  // namespace

TEST_CASE("car lists: built-in names, a table, one row of it, inline cars, each with *K, in order") {
    Folder d;
    const std::string t = d.file("mycars.csv", kTable);
    const auto builtin = read_cars("A_min*2, E_max");
    REQUIRE(builtin.size() == 3);
    CHECK(builtin[0].name == "A_min");
    CHECK(builtin[1].parameters == paper_calibration_table()[0].parameters);
    CHECK(builtin[2].name == "E_max");
    CHECK(builtin[0].min_acc_speed == paper_calibration_table()[0].min_acc_speed);  // the built-in keeps its disengagement speed

    const auto table = read_cars(t);
    REQUIRE(table.size() == 3);
    CHECK(table[0].name == "Sedan");
    CHECK(table[1].parameters.at("tau") == 0.5);
    CHECK(table[2].parameters.at("eta") == 10);  // blank: the model's default
    CHECK(read_cars(t + "*2").size() == 6);      // the whole table twice
    CHECK(read_cars(t + "*2")[3].name == "Sedan");

    const auto one = read_cars(t + ":SUV*3");
    REQUIRE(one.size() == 3);
    CHECK(one[2].name == "SUV");
    CHECK(one[2].parameters.at("k2") == 0.3);

    const auto in = read_cars("ovrv:k1=0.12,k2=0.45,th=1.2,tau=0.6*2,A_min,ovrv:name=Mine,k1=0.1,k2=0.2,th=1,tau=0.1");
    REQUIRE(in.size() == 4);
    CHECK(in[0].model == "ovrv");
    CHECK(in[0].name == "ovrv:k1=0.12,k2=0.45,th=1.2,tau=0.6");  // the text names it
    CHECK(in[0].parameters.at("k2") == 0.45);
    CHECK(in[0].parameters.at("eta") == 10);
    CHECK(in[1].name == in[0].name);
    CHECK(in[2].name == "A_min");
    CHECK(in[3].name == "Mine");
    const auto idm = read_cars("idm:a=1,b=1.5,th=1.5,tau=0.3");
    REQUIRE(idm.size() == 1);
    CHECK(idm[0].model == "idm");

    // mixed, and the same list gives the same cars in every command (as a fleet)
    const auto mixed = read_cars(t + ":Sedan, A_min*2, " + t + ":SUV");
    const Fleet f = to_fleet(mixed);
    REQUIRE(f.size() == 4);
    CHECK(f[0].label == "Sedan");
    CHECK(f[1].label == "A_min");
    CHECK(f[3].label == "SUV");
    CHECK(f[3].parameters == mixed[3].parameters);
    const auto distinct = distinct_cars(mixed);
    REQUIRE(distinct.size() == 3);
    CHECK(distinct[1].name == "A_min");
}

TEST_CASE("car tables: vehicle and fleet tables are one format: name and count in both, vehicle rows, other laws") {
    const auto cars = read_car_table(
        "name,vehicle,model,k1,k2,th,tau,count\n"
        "Lead car,A_min,,,,,,2\n"
        "Custom,,ovrv,0.2,0.4,1.5,0.3,1\n"
        ",E_min,,,0.5,,,1\n",
        "platoon.csv");
    REQUIRE(cars.size() == 4);
    CHECK(cars[0].name == "Lead car");
    CHECK(cars[1].name == "Lead car");
    CHECK(cars[0].parameters == paper_calibration_table()[0].parameters);
    CHECK(cars[2].name == "Custom");
    CHECK(cars[3].name == "E_min");                   // a vehicle row without a name is named after the vehicle
    CHECK(cars[3].parameters.at("k2") == 0.5);        // its parameters overridden where given
    CHECK(cars[3].parameters.at("k1") == 0.051);
    const auto other = read_car_table("model,k1,k2,th,tau,k3,tau2\nccc,0.1,0.3,1.2,0.4,0.2,0.1\n", "c.csv");
    REQUIRE(other.size() == 1);
    CHECK(other[0].model == "ccc");
    CHECK(other[0].name == "ccc@c.csv:2");
    CHECK_THROWS_WITH_AS(read_vehicles_csv("model,k1,k2,th,tau,k3,tau2\nccc,0.1,0.3,1.2,0.4,0.2,0.1\n", "c.csv"),
                         doctest::Contains("expected cars of the ovrv law"), std::invalid_argument);
    // the fleet reader reads the same table
    const Fleet f = read_fleet_csv("name,k1,k2,th,tau,count\nSedan,0.2,0.6,2,0.2,3\n", "f.csv");
    REQUIRE(f.size() == 3);
    CHECK(f[2].label == "Sedan");
}

TEST_CASE("what calibrate writes is a car table: its CSV with covariance and bounds, its JSON") {
    const std::string csv =
        "name,k1,k2,th,tau,eta,rmse_speed,rmse_gap,train_rmse_speed,train_rmse_gap,test_rmse_speed,test_rmse_gap,naive_rmse_speed,status,"
        "cov_k1_k1,cov_k1_k2,cov_k1_th,cov_k1_tau,cov_k1_eta,cov_k2_k2,cov_k2_th,cov_k2_tau,cov_k2_eta,cov_th_th,cov_th_tau,cov_th_eta,"
        "cov_tau_tau,cov_tau_eta,cov_eta_eta,lo_k1,hi_k1,lo_k2,hi_k2,lo_th,hi_th,lo_tau,hi_tau,lo_eta,hi_eta\n"
        "fit1,0.1,0.45,0.16,0.43,15,0.05,0.13,0.05,0.13,,,0.13,converged,"
        "1e-3,0,0,0,0,4e-2,0,0,0,0.17,0,0,0.29,0,30,0,1,0,1,0,3,0,1,5,15\n";
    const auto v = read_car_table(csv, "fits.csv");
    REQUIRE(v.size() == 1);
    CHECK(v[0].has_covariance);
    CHECK(v[0].covariance(1, 1) == doctest::Approx(0.04));
    CHECK(v[0].bounds.size() == 5);
    // the same fit with units in its header (what calibrate writes since 2026-11-29) reads the same
    std::string with_units = csv;
    for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
             {"name,k1,k2,th,tau,eta,", "name,k1_per_s2,k2_per_s,th_s,tau_s,eta_m,"},
             {"rmse_speed,rmse_gap,train_rmse_speed,train_rmse_gap,test_rmse_speed,test_rmse_gap,naive_rmse_speed,",
              "rmse_speed_mps,rmse_gap_m,train_rmse_speed_mps,train_rmse_gap_m,test_rmse_speed_mps,test_rmse_gap_m,naive_rmse_speed_mps,"},
             {"lo_k1,hi_k1,lo_k2,hi_k2,lo_th,hi_th,lo_tau,hi_tau,lo_eta,hi_eta",
              "lo_k1_per_s2,hi_k1_per_s2,lo_k2_per_s,hi_k2_per_s,lo_th_s,hi_th_s,lo_tau_s,hi_tau_s,lo_eta_m,hi_eta_m"}}) {
        const auto at = with_units.find(from);
        REQUIRE(at != std::string::npos);
        with_units.replace(at, from.size(), to);
    }
    const auto u = read_car_table(with_units, "fits-units.csv");
    REQUIRE(u.size() == 1);
    CHECK(u[0].parameters == v[0].parameters);
    CHECK(u[0].covariance == v[0].covariance);
    REQUIRE(u[0].bounds.size() == v[0].bounds.size());
    for (std::size_t i = 0; i < u[0].bounds.size(); ++i) {
        CHECK(u[0].bounds[i].name == v[0].bounds[i].name);
        CHECK(u[0].bounds[i].lower == v[0].bounds[i].lower);
        CHECK(u[0].bounds[i].upper == v[0].bounds[i].upper);
    }
    // a unit that is not the parameter's is not taken for it: an unknown column, named
    CHECK_THROWS_WITH_AS(read_car_table("name,k1_per_s,k2,th,tau\nA,0.1,0.2,1,0.1\n", "c.csv"), doctest::Contains("column 'k1_per_s'"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k1_per_s2,k2,th,tau\nA,0.1,0.1,0.2,1,0.1\n", "c.csv"), doctest::Contains("appears twice"),
                         std::invalid_argument);
    const std::string json = R"({"command": "calibrate", "version": "0.1.0", "inputs": {}, "solver": null, "status": "converged", "message": "",
        "result": {"fits": [{"name": "RAV4", "k1": 0.1, "k2": 0.45, "th": 0.16, "tau": 0.43, "eta": 15, "status": "converged",
                   "covariance": [[1e-3,0,0,0,0],[0,4e-2,0,0,0],[0,0,0.17,0,0],[0,0,0,0.29,0],[0,0,0,0,30]]}],
                   "bounds": {"k1": [0, 1], "k2": [0, 1], "th": [0, 3], "tau": [0, 1], "eta": [5, 15]}}})";
    const auto j = read_calibration_json(json, "fits.json");
    REQUIRE(j.size() == 1);
    CHECK(j[0].name == "RAV4");
    CHECK(j[0].has_covariance);
    CHECK(j[0].covariance(3, 3) == 0.29);
    CHECK(j[0].bounds.size() == 5);
    CHECK(j[0].parameters.at("tau") == 0.43);
    Folder d;
    const std::string file = d.file("fits.json", json);
    CHECK(read_cars(file + ":RAV4*2").size() == 2);
    CHECK_THROWS_WITH_AS(read_calibration_json(R"({"command": "sweep", "result": {}})", "s.json"), doctest::Contains("the output of `sweep`"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_calibration_json(R"({"command": "calibrate", "result": {"fits": [{"name": "x", "k1": 0.1, "k2": 0.2, "th": 1, "tau": 0.1,
                                                  "eta": 5, "status": "max_iterations"}]}})",
                                               "f.json"),
                         doctest::Contains("expected a converged fit"), std::invalid_argument);
}

TEST_CASE("car lists and tables: bad input is named, never taken silently") {
    Folder d;
    const std::string t = d.file("mycars.csv", kTable);
    CHECK_THROWS_WITH_AS(read_cars("A_mni"), doctest::Contains("car 'A_mni': expected a setting of the paper's table"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars(t + ":Coupe"), doctest::Contains("no car named 'Coupe'"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars(t + ":Coupe"), doctest::Contains("it has Sedan, SUV, Hatchback"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars("A_min,,B_max"), doctest::Contains("an empty item"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars("A_min*0"), doctest::Contains("expected CAR*K with K an integer"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars("A_min*x"), doctest::Contains("expected CAR*K"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars(""), doctest::Contains("an empty car list"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars("ovrv:k1=0.1,k2=x,th=1,tau=0.1"), doctest::Contains("k2 = 'x': expected a finite number"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars("ovrv:k1=0.1,k2=0.2,th=1"), doctest::Contains("tau"), std::invalid_argument);  // a required parameter
    CHECK_THROWS_WITH_AS(read_cars("ovrv:k1=0.1,k2=0.2,th=1,tau=0.1,speed=3"), doctest::Contains("speed is set by"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_cars(d.path.string() + "/none.csv"), doctest::Contains("cannot open the file"), std::invalid_argument);
    CHECK_THROWS_AS(read_cars("A_min*600000,B_max*600000"), std::invalid_argument);  // more than 10^6 cars, before they are made
    CHECK_THROWS_WITH_AS(read_cars("A_min*10", 5), doctest::Contains("more than 5 cars"), std::invalid_argument);
    // an unknown column is named; a count is read (never ignored)
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k2,th,tau,colour\nx,0.1,0.2,1,0.1,red\n", "c.csv"),
                         doctest::Contains("column 'colour' is not a column of a car table"), std::invalid_argument);
    // a header in upper case or separated by semicolons gets a hint
    CHECK_THROWS_WITH_AS(read_car_table("NAME,k1,k2,th,tau\nx,0.1,0.2,1,0.1\n", "c.csv"), doctest::Contains("column names are lower case: 'name'"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_car_table("name;k1;k2;th;tau\nx;0.1;0.2;1;0.1\n", "c.csv"), doctest::Contains("the header is separated by ';'"),
                         std::invalid_argument);
    CHECK(read_car_table("name,k1,k2,th,tau,count\nx,0.1,0.2,1,0.1,3\n", "c.csv").size() == 3);
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k2,th,tau,count\nx,0.1,0.2,1,0.1,2.5\n", "c.csv"), doctest::Contains("column 'count' = '2.5'"),
                         std::invalid_argument);
    // the same name for two different cars
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k2,th,tau\nx,0.1,0.2,1,0.1\nx,0.2,0.2,1,0.1\n", "c.csv"),
                         doctest::Contains("car name 'x' is given twice with different values (first at c.csv:2)"), std::invalid_argument);
    CHECK(read_car_table("name,k1,k2,th,tau\nx,0.1,0.2,1,0.1\nx,0.1,0.2,1,0.1\n", "c.csv").size() == 2);  // the same car twice
    CHECK_THROWS_WITH_AS(read_cars("ovrv:name=A_min,k1=0.3,k2=0.2,th=1,tau=0.1,A_min"), doctest::Contains("names two different cars"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k2,th,tau,k1\nx,0.1,0.2,1,0.1,0.1\n", "c.csv"), doctest::Contains("appears twice"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_car_table("k1,k2,th,tau\n0.1,0.2,1,0.1\n", "c.csv"), doctest::Contains("needs a 'name', 'vehicle' or 'model' column"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_car_table("name,model,k1,k2,th,tau\nx,bmw,0.1,0.2,1,0.1\n", "c.csv"),
                         doctest::Contains("column 'model' = 'bmw': expected one of ovrv, idm, ccc"), std::invalid_argument);
    // control characters in a parameter's name or a car's name: refused, the message one line
    // (a fuzzer's find: "ccc:k\n1=0.1" echoed the line break)
    for (const std::string& bad : {std::string("ccc:k\n1=0.1,k6=0.2"), std::string("ovrv:name=a\x01b,k1=0.1,k2=0.2,th=1,tau=0.1")}) {
        CAPTURE(bad);
        try {
            (void)read_cars(bad);
            FAIL("taken");
        } catch (const std::invalid_argument& e) {
            CHECK(std::string(e.what()).find('\n') == std::string::npos);
            CHECK(std::string(e.what()).find("expected") != std::string::npos);
        }
    }
    CHECK_THROWS_WITH_AS(read_car_table("name,k1,k2,th,tau\na\x02,0.1,0.2,1,0.1\n", "c.csv"), doctest::Contains("'a\\x02': expected a name without control"),
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(require_ovrv(read_cars("idm:a=1,b=1.5,th=1.5,tau=0.3"), "simulate --fleet"),
                         doctest::Contains("simulate --fleet takes cars of the paper's law (ovrv); car 'idm:a=1,b=1.5,th=1.5,tau=0.3' has model idm"), std::invalid_argument);
}
