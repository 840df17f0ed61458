// roots --system FILE.json: the linear DDE reader, then the root bounds every solver starts from.
#include "fuzz_common.hpp"
#include "ddemap/io/system_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const ddemap::LinearDDE dde = ddemap::read_linear_dde_json(ddemap::fuzz::text(data, size), "fuzz.json");
        (void)dde.root_bound(0.0);
    });
}
