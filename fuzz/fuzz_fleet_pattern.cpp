// Car lists (io/cars.hpp: the --fleet, VEHICLES, --x/--y and --mark arguments of every command),
// the pattern of built-in names and one-car specs (MODEL:NAME=VALUE,...).
#include "fuzz_common.hpp"
#include "ddemap/io/cars.hpp"
#include "ddemap/traffic/fleet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string t = ddemap::fuzz::text(data, size);
    ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::fleet_from_pattern(t, 0); });
    ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::fleet_from_pattern(t, 50); });
    // no paths: a list naming a file reads it from disk (a device such as /dev/zero never ends)
    if (t.find('/') == std::string::npos && t.find(".csv") == std::string::npos && t.find(".json") == std::string::npos)
        ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::read_cars(t, 100000); });
    return ddemap::fuzz::expect_value_or_bad_input([&] { (void)ddemap::parse_fleet_car(t); });
}
