// --fleet FILE.csv: the fleet reader, then the ring equilibrium at a speed.
#include "fuzz_common.hpp"
#include "ddemap/traffic/fleet.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return ddemap::fuzz::expect_value_or_bad_input([&] {
        const ddemap::Fleet fleet = ddemap::read_fleet_csv(ddemap::fuzz::text(data, size), "fuzz.csv");
        if (fleet.size() >= 2 && fleet.size() <= 1000) (void)ddemap::ring_equilibrium_at_speed(fleet, 20.0);
    });
}
