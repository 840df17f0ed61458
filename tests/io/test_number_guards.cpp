#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <stdexcept>

#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("no NaN or inf is ever written: the CSV and SVG number writers make it an internal error") {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    CHECK(format_exact(0.1) == "0.1");
    CHECK_THROWS_AS(format_exact(nan), std::logic_error);
    CHECK_THROWS_AS(format_exact(inf), std::logic_error);
    CHECK_THROWS_AS(format_exact(-inf), std::logic_error);
    PlotOptions po;
    PlotPanel ok{"p", "x", "y", {PlotSeries{"s", {0.0, 1.0}, {0.0, 2.0}, "", false}}, {}};
    CHECK(render_line_plots_svg({ok}, po).find("nan") == std::string::npos);
    po.panel_width = inf;  // a figure size that is not finite
    CHECK_THROWS_AS(render_line_plots_svg({ok}, po), std::logic_error);
}

TEST_CASE("CSV numbers: the shortest decimal that reads back to the same double") {
    // checked against strtod (an independent parser) and against %.17g, which always reads back
    CHECK(format_exact(0.45) == "0.45");
    CHECK(format_exact(-0.0) == "0");
    CHECK(format_exact(1e300) == "1e+300");
    CHECK(format_exact(5e-324) == "5e-324");
    std::mt19937_64 gen(7);
    for (int i = 0; i < 20000; ++i) {
        double x;
        const std::uint64_t bits = gen();
        std::memcpy(&x, &bits, sizeof x);
        if (!std::isfinite(x)) continue;
        const std::string s = format_exact(x);
        CHECK_MESSAGE(std::strtod(s.c_str(), nullptr) == x, s);
        char b[40];
        std::snprintf(b, sizeof b, "%.17g", x);
        CHECK(s.size() <= std::string(b).size());
    }
}

TEST_CASE("a y floor keeps the padding of a gap axis at 0 and is ignored when data lie below it") {
    PlotOptions po;
    PlotPanel gap{"gap", "x", "gap [m]", {PlotSeries{"s", {1.0, 2.0, 3.0}, {0.0, 20.0, 55.0}, "", false}}, {}};
    // without a floor the 4 % padding below 0 rounds the axis to a negative tick
    CHECK(render_line_plots_svg({gap}, po).find("text-anchor=\"end\">-") != std::string::npos);
    gap.y_floor = 0.0;
    CHECK(render_line_plots_svg({gap}, po).find("text-anchor=\"end\">-") == std::string::npos);
    gap.series[0].y[0] = -5.0;  // data below the floor: the axis shows them
    CHECK(render_line_plots_svg({gap}, po).find("text-anchor=\"end\">-") != std::string::npos);
}
