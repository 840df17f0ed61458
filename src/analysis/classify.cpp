#include "ddemap/analysis/classify.hpp"

#include <algorithm>

namespace ddemap {

std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars) {
    std::vector<Classification> out(vehicles.size());
#ifdef DDEMAP_WITH_OPENMP
#pragma omp parallel for schedule(dynamic, 1)
#endif
    for (std::size_t i = 0; i < vehicles.size(); ++i) {
        const Linearisation lin = make_model("ovrv", vehicles[i].parameters)->linearise();
        out[i] = {vehicles[i], analyse_string(lin), analyse_ring(lin, cars)};
    }
    return out;
}

}  // namespace ddemap
