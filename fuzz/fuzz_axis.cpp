// sweep --k1 LO:HI:COUNT: the range parser.
#include "fuzz_common.hpp"
#include "ddemap/study/sweep.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input(
        [&] { (void)ddemap::parse_axis("k1", ddemap::fuzz::text(data, size)); });
}
