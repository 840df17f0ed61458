// roots --system FILE.json: the linear DDE reader, then the root bounds every solver starts from.
#include "fuzz_common.hpp"
#include "ddemap/io/system_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const std::string text = ddemap::fuzz::text(data, size);
        // the command line sizes the system first and refuses large ones before reading them
        // (every matrix is held dense): the same here, so that memory stays bounded
        if (ddemap::peek_linear_dde_json(text, "fuzz.json").dimension > 1000) return;
        const ddemap::LinearDDE dde = ddemap::read_linear_dde_json(text, "fuzz.json");
        (void)dde.root_bound(0.0);
    });
}
