#include "ddemap/analysis/stability/mixed_ring.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/traffic/ring_determinant.hpp"
#include "ddemap/traffic/ring_system.hpp"

namespace ddemap {

void MixedRingOptions::validate() const {
    roots.validate();
    const bool has_speed = !std::isnan(speed), has_length = !std::isnan(length);
    if (has_speed == has_length) throw std::invalid_argument("a mixed ring needs exactly one of speed or length");
}

namespace {
void require_computable_cars(const Fleet& fleet, const std::vector<Linearisation>& lins) {
    for (std::size_t i = 0; i < lins.size(); ++i)
        require_computable(lins[i], "car " + std::to_string(i + 1) + (i < fleet.size() ? " (" + fleet[i].label + ")" : std::string()));
}
}  // namespace

void require_computable(const Fleet& fleet, const MixedRingOptions& options) {
    options.validate();
    const RingEquilibrium eq = std::isnan(options.length) ? ring_equilibrium_at_speed(fleet, options.speed)
                                                          : ring_equilibrium_at_length(fleet, options.length);
    const RingSystem ring(fleet, eq.speed);
    require_computable_cars(fleet, ring.car_linearisations(ring.equilibrium(eq.speed)));
}

MixedRingResult analyse_mixed_ring(const Fleet& fleet, const MixedRingOptions& options) {
    options.validate();
    MixedRingResult out;
    out.equilibrium = std::isnan(options.length) ? ring_equilibrium_at_speed(fleet, options.speed)
                                                 : ring_equilibrium_at_length(fleet, options.length);
    // the linearisation of the nonlinear ring at its equilibrium, car by car (sparse: O(N))
    const RingSystem ring(fleet, out.equilibrium.speed);
    const std::vector<Linearisation> lins = ring.car_linearisations(ring.equilibrium(out.equilibrium.speed));
    require_computable_cars(fleet, lins);
    RootOptions ro = options.roots;
    ro.count = options.roots.count + 1;  // room for the trivial root
    const RootProblem problem = ring_root_problem(lins);
    // the sparse path's size guard (estimate_root_work): a ring's roots crowd the imaginary axis
    // as it grows, the shifts grew like 1.2 sqrt(n) (measured, BENCHMARKS.md)
    if (ro.shift_invert.expected_shifts == 0.0) ro.shift_invert.expected_shifts = std::max(16.0, 1.2 * std::sqrt(static_cast<double>(problem.dde.dimension())));
    const bool one_leader = std::all_of(lins.begin(), lins.end(), [](const Linearisation& l) { return l.leaders() == 1; });
    // the facade chooses (auto: contour for one-leader rings unless a degree is asked) or checks the forced method
    RootResult r = rightmost_roots(problem, ro);
    // the trivial root: lambda = 0 to rounding
    for (std::size_t i = 0; i < r.roots.size(); ++i) {
        if (std::abs(r.roots[i].value) <= 1e-8) {
            out.trivial_found = true;
            out.trivial_root = std::abs(r.roots[i].value);
            r.roots.erase(r.roots.begin() + static_cast<long>(i));
            break;
        }
    }
    r.roots = cut_rightmost(r.roots, options.roots.count);
    out.spectral_abscissa = r.spectral_abscissa();
    for (const auto& x : r.roots) {
        if (x.value.real() > marginal_band(x.value)) ++out.unstable_roots;
        if (x.value.real() < -marginal_band(x.value)) out.unstable_count_complete = true;
    }
    out.stable = r.status == Status::Converged && !r.roots.empty() && out.unstable_roots == 0 &&
                 r.roots.front().value.real() < -marginal_band(r.roots.front().value);
    const int marginal = !r.roots.empty() && !out.stable && out.unstable_roots == 0 ? 1 : 0;
    out.verdict = r.roots.empty() && r.status == Status::Converged ? Verdict::Undecided
                                                                    : verdict_of(r.status, out.unstable_roots, marginal);
    if (one_leader) {
        out.product_residual = 0.0;
        for (const auto& x : r.roots) out.product_residual = std::max(out.product_residual, ring_product_residual(lins, x.value));
    }
    out.roots = std::move(r);
    return out;
}

}  // namespace ddemap
