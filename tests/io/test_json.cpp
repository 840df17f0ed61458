// The JSON writers of io/json.hpp: the one envelope, round-trip numbers, null for non-finite.
#include <doctest/doctest.h>

#include <cstdlib>
#include <limits>
#include <string>

#include "ddemap/io/json.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("JsonObject keeps the key order, writes round-trip numbers and null for non-finite ones") {
    const std::string s = JsonObject()
                              .string("b", "x \"q\"")
                              .number("a", 0.1)
                              .number("n", std::numeric_limits<double>::quiet_NaN())
                              .integer("i", 22)
                              .boolean("t", true)
                              .json("o", json_ring(0))
                              .str();
    CHECK(s == R"({"b":"x \"q\"","a":0.1,"n":null,"i":22,"t":true,"o":"inf"})");
    // numbers read back to the same double (round-trip exact), whatever their digits
    for (double v : {1.0 / 3.0, 0.1, -2.5e-300, 1.7976931348623157e308, 4.9e-324, 123456789.123456789}) {
        CAPTURE(v);
        CHECK(std::strtod(json_number(v).c_str(), nullptr) == v);
    }
    CHECK(json_array({"1", json_string("a")}) == R"([1,"a"])");
}

TEST_CASE("the envelope has the same keys for every command, solver null without a choice") {
    JsonEnvelope e;
    e.command = "string";
    e.inputs = JsonObject().string("model", "ovrv").str();
    e.result = JsonObject().boolean("string_stable", false).str();
    const std::string s = envelope_json(e);
    const auto at = [&](const char* key) { return s.find(std::string("\"") + key + "\""); };
    CHECK(at("command") < at("version"));
    CHECK(at("version") < at("inputs"));
    CHECK(at("inputs") < at("solver"));
    CHECK(at("solver") < at("status"));
    CHECK(at("status") < at("message"));
    CHECK(at("message") < at("result"));
    CHECK(s.find("\"solver\": null") != std::string::npos);
    e.has_solver = true;
    e.solver_given = "auto";
    e.solver_used = "sparse";
    CHECK(envelope_json(e).find("\"used\": \"sparse\"") != std::string::npos);
}

TEST_SUITE_END();
