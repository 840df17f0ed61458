#include "ddemap/study/penetration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/internal/text.hpp"
#include "ddemap/core/execution.hpp"

namespace ddemap {

void MixOptions::validate() const {
    ring.validate();
    if (cars < 2 || cars > 1000000) throw std::invalid_argument("cars = " + std::to_string(cars) + ": expected 2..1000000");
    if (fractions.empty()) throw std::invalid_argument("fractions: expected at least one p in [0, 1]");
    for (double p : fractions)
        if (!(p >= 0.0 && p <= 1.0)) throw std::invalid_argument("p = " + detail::format_number(p) + ": expected a fraction in [0, 1]");
    if (draws < 0 || draws > 10000) throw std::invalid_argument("draws = " + std::to_string(draws) + ": expected 0..10000");
}

std::vector<MixPoint> penetration_study(const FleetCar& x, const FleetCar& y, const MixOptions& options) {
    options.validate();
    // every ring of the study inside the computable range, before any root work
    for (double p : options.fractions)
        require_computable(mixed_fleet(x, y, options.cars, static_cast<int>(std::lround(p * options.cars)), 0, options.seed), options.ring);
    std::vector<MixPoint> out(options.fractions.size());
    for (std::size_t i = 0; i < options.fractions.size(); ++i) {
        out[i].fraction = options.fractions[i];
        out[i].x_cars = static_cast<int>(std::lround(out[i].fraction * options.cars));
        out[i].status = Status::Cancelled;  // until every arrangement of it is solved
    }
    const long total = static_cast<long>(options.fractions.size()) * (options.draws + 1L);
    long solved = 0;
    try {
        for (MixPoint& pt : out) {
            Status worst = Status::Converged;
            bool stable = true;
            for (int draw = 0; draw <= options.draws; ++draw) {
                const MixedRingResult r = analyse_mixed_ring(mixed_fleet(x, y, options.cars, pt.x_cars, draw, options.seed), options.ring);
                if (r.roots.status == Status::Cancelled) throw Cancelled();  // ring.roots.progress stopped the root search
                const double a = r.spectral_abscissa;
                if (draw == 0) {
                    pt.abscissa = pt.abscissa_min = pt.abscissa_max = a;
                    pt.speed = r.equilibrium.speed;
                    pt.unstable_roots = r.unstable_roots;
                    pt.method_used = r.roots.method_used;
                }
                pt.abscissa_min = std::min(pt.abscissa_min, a);
                pt.abscissa_max = std::max(pt.abscissa_max, a);
                stable = stable && r.stable;
                pt.max_residual = std::max(pt.max_residual, r.roots.max_residual);
                if (r.roots.status != Status::Converged) worst = r.roots.status;
                ++pt.arrangements;
                ++solved;
                if (draw == options.draws) {  // the point is complete before it is reported
                    pt.status = worst;
                    pt.stable = stable;
                }
                if (options.progress) options.progress(solved, total, pt.fraction);  // may throw Cancelled
            }
        }
    } catch (const Cancelled&) {
        // the points not complete keep Status::Cancelled and stable = false
    }
    return out;
}

}  // namespace ddemap
