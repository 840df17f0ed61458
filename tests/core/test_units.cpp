// Units in column names (core/units.hpp): the suffix of every unit the built-in models and
// writers use, spelled out independently here, and the reverse that readers use.
#include <doctest/doctest.h>

#include <string>
#include <utility>
#include <vector>

#include "ddemap/core/units.hpp"
#include "ddemap/traffic/model.hpp"

using namespace ddemap;

TEST_CASE("unit suffixes of column names and their removal") {
    const std::vector<std::pair<std::string, std::string>> table = {
        {"", ""},           {"1", ""},           {"-", ""},           {"s", "_s"},         {"m", "_m"},
        {"m/s", "_mps"},    {"m/s^2", "_mps2"},  {"1/s", "_per_s"},   {"1/s^2", "_per_s2"}, {"rad", "_rad"},
        {"rad/s", "_rad_per_s"}, {"kg m/s", "_kg_m_per_s"}};
    for (const auto& row : table) {  // no structured binding: CAPTURE's lambda may not capture one (clang 14)
        const std::string& unit = row.first;
        const std::string& suffix = row.second;
        CAPTURE(unit);
        CHECK(unit_suffix(unit) == suffix);
        CHECK(column_name("x", unit) == "x" + suffix);
        CHECK(strip_unit("x" + suffix, unit) == "x");
    }
    // only the unit's own suffix is removed, and never the whole name
    CHECK(strip_unit("k1_per_s", "1/s^2") == "k1_per_s");
    CHECK(strip_unit("_s", "s") == "_s");
    // the built-in models' parameters, as the CSV headers carry them
    CHECK(column_name("k1", parameter_unit("k1")) == "k1_per_s2");
    CHECK(column_name("k2", parameter_unit("k2")) == "k2_per_s");
    CHECK(column_name("th", parameter_unit("th")) == "th_s");
    CHECK(column_name("tau", parameter_unit("tau")) == "tau_s");
    CHECK(column_name("eta", parameter_unit("eta")) == "eta_m");
    CHECK(column_name("a", parameter_unit("a")) == "a_mps2");
    CHECK(column_name("speed", parameter_unit("speed")) == "speed_mps");
    CHECK(column_name("delta", parameter_unit("delta")) == "delta");
    CHECK(parameter_unit("no_such_parameter").empty());
    // one unit per name across the models (a column name means one thing whatever the model)
    for (const auto& m : model_names())
        for (const auto& spec : model_parameters(m)) {
            CAPTURE(m);
            CAPTURE(spec.name);
            CHECK(parameter_unit(spec.name) == spec.unit);
        }
}
