// calibrate DATA.csv: the trace reader.
#include "fuzz_common.hpp"
#include "ddemap/analysis/calibration/calibrate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input(
        [&] { (void)ddemap::read_trace_csv(ddemap::fuzz::text(data, size), "fuzz.csv"); });
}
