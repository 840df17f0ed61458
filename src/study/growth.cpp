#include "ddemap/study/growth.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace ddemap {

std::vector<GrowthResult> disturbance_growth(const std::vector<CalibratedVehicle>& vehicles, const LeadProfile& lead,
                                             int followers, const SimOptions& options,
                                             const ExecutionPolicy& policy) {
    if (followers < 1 || followers > 1000) throw std::invalid_argument("followers = " + std::to_string(followers) + ": expected 1 to 1000");
    double lead_min = lead.speed(0.0);
    for (double v : lead.speeds()) lead_min = std::min(lead_min, v);
    const double lead_drop = lead.speed(0.0) - lead_min;
    if (!(lead_drop > 0.0)) throw std::invalid_argument("the lead profile has no speed drop: expected a disturbance");
    std::vector<GrowthResult> out(vehicles.size());
    std::vector<char> simulated(vehicles.size(), 0);  // each task writes only its own entry
    auto simulate = [&](long vi) {
        const SimResult r = simulate_platoon(lead, platoon_of(vehicles[vi], followers), options);
        GrowthResult g;
        g.name = vehicles[vi].name;
        int first = 0;
        const SimEvent* ev = nullptr;
        for (const auto& c : r.cars)
            if (!c.events.empty() && (first == 0 || c.car < first)) {
                first = c.car;
                ev = &c.events.front();
            }
        for (const auto& c : r.cars) {
            if (first != 0 && c.car >= first) break;
            g.speed_drop.push_back(c.speed_drop);
            g.amplification.push_back(c.speed_drop / lead_drop);
            g.min_gap.push_back(c.min_gap);
        }
        if (r.status != Status::Converged) {  // a diverged run is no growth result: undecided
            g.status = r.status;
            g.message = r.message;
        }
        if (ev) {
            g.failed_at = first;
            g.failure = ev->type;
            g.failure_time = ev->time;
            g.failure_amplification = (r.initial_speed - ev->lowest_speed) / lead_drop;
            g.failure_gap = ev->gap;
        }
        out[vi] = g;
        simulated[vi] = 1;
    };
    try {
        parallel_for(static_cast<long>(vehicles.size()), simulate, policy);
    } catch (const Cancelled&) {
        for (std::size_t vi = 0; vi < vehicles.size(); ++vi)
            if (!simulated[vi]) {
                out[vi] = GrowthResult{};
                out[vi].name = vehicles[vi].name;
                out[vi].status = Status::Cancelled;
            }
    }
    return out;
}

}  // namespace ddemap
