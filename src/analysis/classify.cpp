#include "ddemap/analysis/classify.hpp"

#include <algorithm>

namespace ddemap {

std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars, const ExecutionPolicy& policy) {
    std::vector<Classification> out(vehicles.size());
    parallel_for(static_cast<long>(vehicles.size()), [&](long i) {
        const Linearisation lin = make_model("ovrv", vehicles[i].parameters)->linearise();
        out[i] = {vehicles[i], analyse_string(lin), analyse_ring(lin, cars)};
    }, policy);
    return out;
}

}  // namespace ddemap
