// --fleet-pattern TEXT and one-car specs (MODEL:NAME=VALUE,...).
#include "fuzz_common.hpp"
#include "ddemap/traffic/fleet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string t = ddemap::fuzz::text(data, size);
    ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::fleet_from_pattern(t, 0); });
    ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::fleet_from_pattern(t, 50); });
    return ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::parse_fleet_car(t); });
}
