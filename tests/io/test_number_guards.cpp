#include <doctest/doctest.h>

#include <limits>
#include <stdexcept>

#include "ddemap/io/csv.hpp"
#include "ddemap/io/svg.hpp"

TEST_SUITE_BEGIN("fast");

using namespace ddemap;

TEST_CASE("no NaN or inf is ever written: the CSV and SVG number writers make it an internal error") {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    CHECK(format_exact(0.1) == "0.10000000000000001");
    CHECK_THROWS_AS(format_exact(nan), std::logic_error);
    CHECK_THROWS_AS(format_exact(inf), std::logic_error);
    CHECK_THROWS_AS(format_exact(-inf), std::logic_error);
    PlotOptions po;
    PlotPanel ok{"p", "x", "y", {PlotSeries{"s", {0.0, 1.0}, {0.0, 2.0}, "", false}}, {}};
    CHECK(render_line_plots_svg({ok}, po).find("nan") == std::string::npos);
    po.panel_width = inf;  // a figure size that is not finite
    CHECK_THROWS_AS(render_line_plots_svg({ok}, po), std::logic_error);
}
