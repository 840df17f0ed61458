// simulate --lead FILE.csv: the lead-profile reader, then the profile's speed and position.
#include "fuzz_common.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const auto lead = ddemap::LeadProfile::from_csv(ddemap::fuzz::text(data, size), "fuzz.csv");
        (void)lead.position(lead.duration());
        (void)lead.speed(0.5 * lead.duration());
    });
}
