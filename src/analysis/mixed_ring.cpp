#include "ddemap/analysis/mixed_ring.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ddemap/traffic/ring_determinant.hpp"
#include "ddemap/traffic/ring_system.hpp"

namespace ddemap {

void MixedRingOptions::validate() const {
    roots.validate();
    const bool has_speed = !std::isnan(speed), has_length = !std::isnan(length);
    if (has_speed == has_length) throw std::invalid_argument("a mixed ring needs exactly one of speed or length");
}

MixedRingResult analyse_mixed_ring(const Fleet& fleet, const MixedRingOptions& options) {
    options.validate();
    MixedRingResult out;
    out.equilibrium = std::isnan(options.length) ? ring_equilibrium_at_speed(fleet, options.speed)
                                                 : ring_equilibrium_at_length(fleet, options.length);
    // the linearisation of the nonlinear ring at its equilibrium, car by car (sparse: O(N))
    const RingSystem ring(fleet, out.equilibrium.speed);
    const std::vector<Linearisation> lins = ring.car_linearisations(ring.equilibrium(out.equilibrium.speed));
    SparseRootOptions ro = options.roots;
    ro.count = options.roots.count + 1;  // room for the trivial root
    const bool one_leader = std::all_of(lins.begin(), lins.end(), [](const Linearisation& l) { return l.leaders() == 1; });
    if (options.method == SolverMethod::Product && !one_leader)
        throw std::invalid_argument("solver 'product': every car must react only to the car ahead (this fleet has CCC cars); expected auto, dense or sparse");
    if (options.method == SolverMethod::Product && options.roots.degree > 0)
        throw std::invalid_argument("degree = " + std::to_string(options.roots.degree) +
                                    ": the product path has no collocation degree; expected 0 (or the dense or sparse solver)");
    SparseRootResult r;
    // automatic: the product path, unless a collocation degree was asked for
    if (options.method == SolverMethod::Product || (options.method == SolverMethod::Automatic && one_leader && options.roots.degree == 0)) {
        ProductRootOptions po;
        po.count = ro.count;
        po.residual_tolerance = ro.residual_tolerance;
        r = product_ring_roots(lins, po);
        out.method_used = SolverMethod::Product;
    } else {
        const SparseDDE dde = mixed_ring_dde(lins);
        constexpr int dense_limit = 16;  // system_rightmost_roots' default
        out.method_used = options.method == SolverMethod::Sparse ||
                                  (options.method == SolverMethod::Automatic && dde.a0.rows() > dense_limit)
                              ? SolverMethod::Sparse
                              : SolverMethod::Dense;
        r = system_rightmost_roots(dde, ro, options.method, dense_limit);
    }
    out.method_given = options.method;
    // the trivial root: lambda = 0 to rounding
    for (std::size_t i = 0; i < r.roots.size(); ++i) {
        if (std::abs(r.roots[i].value) <= 1e-8) {
            out.trivial_found = true;
            out.trivial_root = std::abs(r.roots[i].value);
            r.roots.erase(r.roots.begin() + static_cast<long>(i));
            if (i < r.eigenvalues.size()) r.eigenvalues.erase(r.eigenvalues.begin() + static_cast<long>(i));
            break;
        }
    }
    r.roots = detail::cut_rightmost(r.roots, options.roots.count);
    const std::size_t keep = r.roots.size();
    if (r.eigenvalues.size() > keep) r.eigenvalues.resize(keep);
    out.spectral_abscissa = r.spectral_abscissa();
    for (const auto& x : r.roots) {
        if (x.value.real() > marginal_band(x.value)) ++out.unstable_roots;
        if (x.value.real() < -marginal_band(x.value)) out.unstable_count_complete = true;
    }
    out.stable = r.status == RootStatus::Converged && !r.roots.empty() && out.unstable_roots == 0 &&
                 r.roots.front().value.real() < -marginal_band(r.roots.front().value);
    if (one_leader) {
        out.product_residual = 0.0;
        for (const auto& x : r.roots) out.product_residual = std::max(out.product_residual, ring_product_residual(lins, x.value));
    }
    out.roots = std::move(r);
    return out;
}

}  // namespace ddemap
