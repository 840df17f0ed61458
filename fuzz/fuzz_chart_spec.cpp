// chart SPEC.toml: the chart-spec reader and every panel's sweep specification.
#include "fuzz_common.hpp"
#include "ddemap/io/chart_spec.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const ddemap::ChartSpec spec = ddemap::parse_chart_spec(ddemap::fuzz::text(data, size), "fuzz.toml");
        for (std::size_t i = 0; i < spec.panels.size(); ++i) ddemap::panel_sweep(spec, i).validate();
    });
}
