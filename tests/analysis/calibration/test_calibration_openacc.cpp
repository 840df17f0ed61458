// Calibration on the 12 measured OpenACC traces (data/openacc of the repository, or the folder
// named by the environment variable DDEMAP_ACC_DATA): every fit converges, other design seeds find the
// same minimum, every fit reports intervals and its warnings.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "ddemap/analysis/calibration/calibrate.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("real OpenACC traces: converged fits, repeatable over design seeds, intervals and warnings, the model beats the naive predictor, th(L) > th(S)" * doctest::test_suite("reference")) {
    const char* env = std::getenv("DDEMAP_ACC_DATA");
    const std::string dir = env ? std::string(env) : std::string(DDEMAP_REPO_DATA) + "/openacc";
    REQUIRE_MESSAGE(std::filesystem::is_directory(dir), "the OpenACC traces are missing: " << dir);
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        if (e.path().extension() == ".csv" && e.path().filename().string().rfind("openacc_", 0) == 0)
            files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    REQUIRE(files.size() == 12);
    std::vector<Trace> traces;
    for (const auto& f : files) {
        std::ifstream in(f);
        std::stringstream ss;
        ss << in.rdbuf();
        traces.push_back(read_trace_csv(ss.str(), f));
    }
    CalibrationOptions other;
    other.seed = 7;
    const std::vector<CalibrationResult> a = calibrate_many(traces, CalibrationOptions{});
    const std::vector<CalibrationResult> b = calibrate_many(traces, other);
    for (std::size_t i = 0; i < files.size(); ++i) {
        CAPTURE(files[i]);
        CHECK(a[i].status_code == Status::Converged);
        CHECK(b[i].objective == doctest::Approx(a[i].objective).epsilon(1e-4));
        // the fit is never worse than the objective at the other seed's parameters
        CHECK(a[i].objective <= calibration_objective(traces[i], b[i].parameters) * (1.0 + 1e-4));
        for (const auto& e : a[i].estimates) {
            CHECK(!(e.lower95 > e.value));
            CHECK(!(e.upper95 < e.value));
            const bool warned = std::any_of(a[i].warnings.begin(), a[i].warnings.end(),
                                            [&](const std::string& w) { return w.rfind(e.name + " ", 0) == 0; });
            if (e.at_bound) CHECK(warned);
        }
        CHECK((a[i].rmse_speed >= a[i].naive_rmse_speed) ==
              std::any_of(a[i].warnings.begin(), a[i].warnings.end(), [](const std::string& w) { return w.find("naive predictor") != std::string::npos; }));
    }
    // the model beats the naive delayed-lead predictor on (nearly) every file
    int better = 0;
    for (std::size_t i = 0; i < files.size(); ++i) better += a[i].all.rmse_speed < a[i].naive.rmse_speed;
    CHECK(better >= 10);
    auto th = [&](const std::string& key) {
        for (std::size_t i = 0; i < files.size(); ++i)
            if (files[i].find(key) != std::string::npos) return a[i].parameters.at("th");
        FAIL("no file " << key);
        return 0.0;
    };
    // the same follower (Tesla Model 3 behind a Tesla Model X), short and long setting, same track
    CHECK(th("dynamic_p18_L_v08-v09") > th("dynamic_p04_S_v05-v06"));
    CHECK(th("handling_p47_L_v02-v03") > th("handling_p02_S_v08-v09"));
}

TEST_SUITE_END();
