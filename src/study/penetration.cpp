#include "ddemap/study/penetration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/internal/text.hpp"

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
        MixPoint& pt = out[i];
        pt.fraction = options.fractions[i];
        pt.x_cars = static_cast<int>(std::lround(pt.fraction * options.cars));
        pt.stable = true;
        for (int draw = 0; draw <= options.draws; ++draw) {
            const MixedRingResult r = analyse_mixed_ring(mixed_fleet(x, y, options.cars, pt.x_cars, draw, options.seed), options.ring);
            const double a = r.spectral_abscissa;
            if (draw == 0) {
                pt.abscissa = pt.abscissa_min = pt.abscissa_max = a;
                pt.speed = r.equilibrium.speed;
                pt.unstable_roots = r.unstable_roots;
                pt.method_used = r.roots.method_used;
            }
            pt.abscissa_min = std::min(pt.abscissa_min, a);
            pt.abscissa_max = std::max(pt.abscissa_max, a);
            pt.stable = pt.stable && r.stable;
            pt.max_residual = std::max(pt.max_residual, r.roots.max_residual);
            if (r.roots.status != Status::Converged) pt.status = r.roots.status;
            ++pt.arrangements;
        }
    }
    return out;
}

}  // namespace ddemap
