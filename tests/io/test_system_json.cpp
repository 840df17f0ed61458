// General linear DDEs from JSON: two delays and complex coefficients against Lambert W.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "ddemap/solve/roots.hpp"
#include "ddemap/io/system_json.hpp"
#include "lambert_w.hpp"
#include "tolerances.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;
namespace tol = ddemap::test::tol;

TEST_CASE("a JSON system with two delays has the union of the blocks' Lambert W roots") {
    // x1' = -x1(t - 1) and x2' = (0.5 i) x2(t - 0.3), decoupled: roots W_k(a tau) / tau of each
    const std::string text = R"({"dimension": 2, "delays": [1.0, 0.3],
        "A0": [[0, 0], [0, 0]],
        "A": [{"triplets": [[0, 0, -1]]}, [[0, 0], [0, [0, 0.5]]]]})";
    const LinearDDE dde = read_linear_dde_json(text, "sys.json");
    CHECK(dde.dimension() == 2);
    CHECK_FALSE(dde.is_real());
    RootOptions o;
    o.count = 6;
    const RootResult r = rightmost_roots(dde, o);
    REQUIRE(r.status == Status::Converged);
    std::vector<cplx> ref;
    for (int k = -6; k <= 6; ++k) {
        ref.push_back(ddemap::test::lambert_w(cplx(-1.0, 0.0), k) / 1.0);
        ref.push_back(ddemap::test::lambert_w(cplx(0.0, 0.5 * 0.3), k) / 0.3);
    }
    for (const auto& root : r.roots) {
        double nearest = 1e300;
        for (cplx z : ref) nearest = std::min(nearest, std::abs(z - root.value));
        CAPTURE(root.value);
        CHECK(nearest < tol::root_abs * std::max(1.0, std::abs(root.value)));
    }
    // the rightmost is W_0(0.15 i) / 0.3 (right of W_0(-1))
    CHECK(std::abs(r.roots.front().value - ddemap::test::lambert_w(cplx(0.0, 0.15), 0) / 0.3) < tol::root_abs);
}

TEST_CASE("bad system files name the field") {
    CHECK_THROWS_WITH_AS(read_linear_dde_json("{", "s.json"), doctest::Contains("s.json: not valid JSON"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 0})", "s.json"), "s.json: dimension: expected an integer from 1 to 20000",
                         std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 2, "delays": [-1], "A": [[[0,0],[0,0]]]})", "s.json"),
                         "s.json: delays[0]: -1: expected a finite delay >= 0", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 2, "delays": [1], "A": []})", "s.json"),
                         "s.json: A: expected an array of 1 matrices, one per delay", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 2, "A0": [[1, 2], [3]]})", "s.json"),
                         "s.json: A0[1]: expected 2 entries", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 2, "delays": [1], "A": [{"triplets": [[2, 0, 1]]}]})", "s.json"),
                         "s.json: A[0].triplets[0]: index (2, 0) outside 0..1", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 1, "A0": [["x"]]})", "s.json"),
                         "s.json: A0[0][0]: expected a number or [re, im]", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 1, "B": 1})", "s.json"),
                         "s.json: B: unknown field (expected dimension, delays, A0, A, comment)", std::invalid_argument);
}


TEST_CASE("system coefficients outside 1e-100..1e100 in magnitude are bad input (the Schur decomposition once failed on them)") {
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 2, "delays": [1], "A0": [[1e300, 1e-300], [1e-300, -1e300]], "A": [[[0,0],[0,1]]]})", "s.json"),
                         "s.json: A0[0][0]: 1e+300: expected 0 or a finite magnitude from 1e-100 to 1e100", std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 1, "delays": [1], "A0": [[-1]], "A": [{"triplets": [[0, 0, [1, 1e-300]]]}]})", "s.json"),
                         doctest::Contains("A[0].triplets[0][1]: 1e-300"), std::invalid_argument);
    CHECK_THROWS_WITH_AS(read_linear_dde_json(R"({"dimension": 1, "delays": [1e200], "A0": [[-1]], "A": [[[0]]]})", "s.json"),
                         doctest::Contains("at most 1e100"), std::invalid_argument);
    // the edges of the range are accepted, and 0 is
    CHECK(read_linear_dde_json(R"({"dimension": 1, "delays": [1], "A0": [[-1e100]], "A": [[[1e-100]]]})", "s.json").dimension() == 1);
    // the shape is read without the matrices
    const LinearDdeShape shape = peek_linear_dde_json(R"({"dimension": 20000, "delays": [1, 2], "A0": {"triplets": []}})", "s.json");
    CHECK(shape.dimension == 20000);
    CHECK(shape.delays == 2);
    CHECK_THROWS_WITH_AS(peek_linear_dde_json(R"({"dimension": 1e400})", "s.json"), doctest::Contains("outside the range of doubles"), std::invalid_argument);
}

TEST_SUITE_END();

TEST_CASE("a nonlinear system file: expressions, parameter order, equilibrium guess, errors naming the file and field" * doctest::test_suite("fast")) {
    const std::string text = R"J({ "variables": ["x1", "x2"],
      "parameters": {"tau": 2.0, "a": 0.5, "b": 0.6, "d": 0.05},
      "equations": ["x2", "-d*x2 - a*x1 - x1^3 - b*(x1 - x1(t - tau))"],
      "equilibrium": [0.1, -0.2] })J";
    REQUIRE(ddemap::is_nonlinear_system_json(text));
    const ddemap::NonlinearSystemFile f = ddemap::read_nonlinear_system_json(text, "f.json");
    CHECK(f.system->dimension() == 2);
    CHECK(f.system->parameter_names() == std::vector<std::string>{"tau", "a", "b", "d"});  // the file's order
    CHECK(f.equilibrium_given);
    CHECK(f.equilibrium[1] == -0.2);
    CHECK(f.system->delays()[0] == 2.0);
    // a linear file is not nonlinear, and invalid JSON neither (the linear reader reports it)
    CHECK(!ddemap::is_nonlinear_system_json(R"J({"dimension": 1, "A0": [[-1]]})J"));
    CHECK(!ddemap::is_nonlinear_system_json("{"));
    auto error_of = [](const std::string& t) {
        try {
            ddemap::read_nonlinear_system_json(t, "f.json");
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of(R"J({"variables": ["x"], "parameters": {"a": 1}, "equations": ["-a*x(t - b)"]})J") ==
          "f.json: equation 1 (dx/dt), character 10: unknown name 'b': expected a parameter (a) or a function");
    CHECK(error_of(R"J({"variables": ["x"], "parameters": {"a": 1}, "equations": ["-a*x(t - x)"]})J") ==
          "f.json: equation 1 (dx/dt), character 10: the delay depends on the state (x): expected an expression of parameters and numbers");
    CHECK(error_of(R"J({"variables": ["x"], "equations": ["-x", "1"]})J") == "f.json: equations: 2 equations for 1 variables: expected one equation per variable");
    CHECK(error_of(R"J({"variables": ["x"], "equations": ["-x"], "equilibrium": [1, 2]})J") ==
          "f.json: equilibrium: expected an array of 1 numbers (one per variable)");
    CHECK(error_of(R"J({"variables": ["x"], "parameters": {"a": "1"}, "equations": ["-x"]})J") == "f.json: parameters.a: expected a number");
    CHECK(error_of(R"J({"variables": ["x"], "equations": ["-x"], "A0": 1})J") ==
          "f.json: A0: unknown field (expected variables, parameters, equations, equilibrium, comment)");
    CHECK(error_of(R"J({"variables": [1], "equations": ["-x"]})J") == "f.json: variables[0]: expected a string");
}
