// atlas SPEC.toml: the atlas-spec reader (with the spec's validation at the grid's corners) and
// the chunking it implies.
#include "fuzz_common.hpp"
#include "ddemap/io/atlas.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const ddemap::AtlasFile file = ddemap::parse_atlas_spec(ddemap::fuzz::text(data, size), "fuzz.toml");
        const ddemap::AtlasSpec& spec = file.spec;
        long covered = 0;
        for (long c = 0; c < spec.chunks() && c < 1000; ++c) covered += spec.chunk_end(c) - spec.chunk_begin(c);
        if (spec.chunks() <= 1000 && covered != spec.points()) __builtin_trap();  // every point in one chunk
    });
}
