#include "ddemap/analysis/stability/ring_stability.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "ddemap/traffic/ring.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"

namespace ddemap {

namespace {

bool ring_root_first(const RingRoot& a, const RingRoot& b) {
    if (a.root.value.real() != b.root.value.real()) return a.root.value.real() > b.root.value.real();
    return a.root.value.imag() > b.root.value.imag();
}

void absorb_status(RingResult& r, const RootResult& rr) {
    r.degree = std::max(r.degree, rr.degree);
    ++r.modes_solved;
    if (rr.status != Status::Converged) {
        r.status = rr.status;
        r.reason = rr.message;
    } else if (r.reason.empty()) {
        r.reason = rr.message;
    }
}

/// Rightmost roots of one mode; with `all_unstable`, the count grows until the last root is
/// left of the axis so that every unstable root is found.
RootResult solve_mode(const LinearDDE& dde, RootOptions opts, bool all_unstable) {
    RootResult rr = rightmost_roots(dde, opts);
    while (all_unstable && rr.status == Status::Converged && static_cast<int>(rr.roots.size()) >= opts.count &&
           !rr.roots.empty() && rr.roots.back().value.real() > -marginal_band(rr.roots.back().value) &&
           opts.count < 512) {
        opts.count *= 2;
        rr = rightmost_roots(dde, opts);
    }
    return rr;
}

}  // namespace

void RingOptions::validate() const {
    roots.validate();
    if (theta_grid < 4) throw std::invalid_argument("theta_grid = " + std::to_string(theta_grid) + ": expected >= 4");
}

RingResult analyse_ring(const Linearisation& lin, int cars, const RingOptions& options) {
    options.validate();
    if (cars != 0 && cars < 2) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected N >= 2 or inf");
    require_computable(lin);
    RingResult r;
    r.cars = cars;
    const int count = options.roots.count;
    std::vector<RingRoot> all;

    if (cars > 0) {
        // Each mode first gives its two rightmost roots (more while they are unstable); then
        // any mode whose last root is still right of the count-th root overall is asked for
        // more, until the global `count` rightmost roots are certain.
        const int modes = cars / 2 + 1;
        std::vector<RootResult> per_mode(modes);
        std::vector<int> asked(modes, std::min(count, 2));
        auto solve = [&](int m) {
            const LinearDDE dde = m == 0 ? ring_mode0_dde(lin) : ring_mode_dde(lin, ring_zeta(m, cars));
            RootOptions o = options.roots;
            o.count = asked[m];
            per_mode[m] = solve_mode(dde, o, true);
            asked[m] = std::max(asked[m], static_cast<int>(per_mode[m].roots.size()));
        };
        if (options.before) {
            RootOptions o = options.roots;
            o.count = std::min(count, 2);
            const LinearDDE one = modes > 1 ? ring_mode_dde(lin, ring_zeta(1, cars)) : ring_mode0_dde(lin);
            options.before(modes, estimate_root_work(RootProblem{one, nullptr}, o));
        }
        for (int m = 0; m < modes; ++m) {
            solve(m);
            if (options.progress) options.progress(m + 1, modes);
        }
        auto weight = [&](int m) { return (m > 0 && 2 * m != cars) ? 2 : 1; };
        for (int round = 0; round < 16; ++round) {
            std::vector<double> re;
            for (int m = 0; m < modes; ++m)
                for (const auto& root : per_mode[m].roots)
                    for (int w = 0; w < weight(m); ++w) re.push_back(root.value.real());
            if (re.size() < std::size_t(count)) {
                re.clear();
            } else {
                std::nth_element(re.begin(), re.begin() + (count - 1), re.end(), std::greater<double>());
            }
            const double threshold = re.empty() ? -std::numeric_limits<double>::infinity() : re[count - 1];
            bool more = false;
            for (int m = 0; m < modes; ++m) {
                const auto& rr = per_mode[m];
                const bool exhausted = static_cast<int>(rr.roots.size()) < asked[m];  // fewer exist in the strip
                if (!exhausted && asked[m] < count && !rr.roots.empty() && rr.roots.back().value.real() >= threshold) {
                    asked[m] = std::min(count, 2 * asked[m]);
                    solve(m);
                    more = true;
                }
            }
            if (!more) break;
        }
        for (int m = 0; m < modes; ++m) {
            absorb_status(r, per_mode[m]);
            const double theta = 2.0 * M_PI * m / cars;
            const bool paired = m > 0 && 2 * m != cars;
            for (const auto& root : per_mode[m].roots) {
                all.push_back({root, m, theta});
                if (paired) {
                    Root c = root;
                    c.value = std::conj(c.value);
                    all.push_back({c, cars - m, 2.0 * M_PI * (cars - m) / cars});
                }
            }
        }
        std::sort(all.begin(), all.end(), ring_root_first);
        r.spectral_abscissa = all.empty() ? -std::numeric_limits<double>::infinity() : all.front().root.value.real();
        r.abscissa_mode = all.empty() ? 0 : all.front().mode;
        r.abscissa_theta = all.empty() ? 0.0 : all.front().theta;
        for (const auto& x : all) {
            const double band = marginal_band(x.root.value);
            if (x.root.value.real() > band) ++r.unstable_roots;
            else if (x.root.value.real() >= -band) ++r.marginal_roots;
        }
        r.verdict = verdict_of(r.status, r.unstable_roots, r.marginal_roots);
        r.stable = r.verdict == Verdict::Stable;
        r.trivial_branch_stable = r.stable;
    } else {
        // N = infinity: maximise the rightmost real part over wave numbers theta in (0, pi]
        require_single_leader(lin, "the infinite ring (N = inf)");
        RootOptions per = options.roots;
        per.count = 1;  // the abscissa needs only the rightmost root
        per.progress = nullptr;  // the scan reports wave numbers (options.progress), not steps
        // the wave number that the peak of |Gamma| drives: Gamma(i w) = e^{i theta}
        StringOptions so;
        so.roots = per;  // the plant's roots: not reported either
        so.roots.count = options.roots.count;
        const StringResult sr = analyse_string(lin, so);
        const LowFrequency& lf = sr.lowfreq;
        const bool series = lf.decisive_order > 0 && lf.gamma_prime0 != 0.0 && lf.d0 != 0.0;
        // On the branch through the trivial root, lambda ~ i theta / Gamma'(0) and
        // Re lambda ~ c_k w^k / (2 D(0)^2 Gamma'(0)) (w = Im lambda, c_k the decisive coefficient).
        // Where the computed real part is within the marginal band it is rounding noise, and this
        // exact expansion gives it instead.
        auto on_trivial_branch = [&](cplx z, double theta) {
            if (!series || std::abs(z.real()) > marginal_band(z)) return false;
            const cplx predicted(0.0, theta / lf.gamma_prime0);
            return std::abs(z - predicted) <= 0.5 * std::abs(predicted);
        };
        auto branch_real = [&](cplx z) {
            return sr.lowfreq_margin * std::pow(std::abs(z.imag()), lf.decisive_order) / (2.0 * lf.d0 * lf.d0 * lf.gamma_prime0);
        };
        bool met_marginal = false;  // a rightmost root within the band, not on the trivial branch
        // progress: one unit per wave number solved, of at most the grid + 43 (the golden section's
        // 2 + 40 and the abscissa's wave number); the bound is lowered to the exact number once
        // the golden section has ended. The search for the --count roots there (of unknown
        // length) reports its own steps through options.roots.progress.
        long solved = 0, units = 0;
        auto report = [&] {
            ++solved;
            if (options.progress) options.progress(solved, std::max(units, solved));
        };
        auto alpha = [&](double theta, RootResult* keep) {
            const RootResult rr = rightmost_roots(ring_mode_dde(lin, std::polar(1.0, -theta)), per);
            report();
            absorb_status(r, rr);
            if (keep) *keep = rr;
            if (rr.roots.empty()) return rr.spectral_abscissa();
            const cplx z = rr.roots.front().value;
            if (on_trivial_branch(z, theta)) return branch_real(z);
            if (std::abs(z.real()) <= marginal_band(z)) met_marginal = true;
            return z.real();
        };
        std::vector<double> thetas;
        for (int j = 1; j <= options.theta_grid; ++j) thetas.push_back(M_PI * j / options.theta_grid);
        for (int k = 1; k <= 12; ++k) thetas.push_back(M_PI * std::ldexp(1.0, -k) / options.theta_grid);
        if (sr.omega_peak > 0.0) {
            double th = std::arg(TransferFunction(lin)(cplx(0.0, sr.omega_peak)));
            th = std::abs(th);
            if (th > 0.0) thetas.push_back(th);
        }
        std::sort(thetas.begin(), thetas.end());
        units = static_cast<long>(thetas.size()) + 43;
        std::vector<double> values(thetas.size());
        for (std::size_t i = 0; i < thetas.size(); ++i) values[i] = alpha(thetas[i], nullptr);
        std::size_t best = 0;
        for (std::size_t i = 1; i < thetas.size(); ++i)
            if (values[i] > values[best]) best = i;
        // golden-section refinement of the maximum between the neighbouring samples
        double lo = best > 0 ? thetas[best - 1] : thetas[best] * 0.5;
        double hi = best + 1 < thetas.size() ? thetas[best + 1] : M_PI;
        double best_theta = thetas[best], best_value = values[best];
        const double g = 0.5 * (std::sqrt(5.0) - 1.0);
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        double f1 = alpha(x1, nullptr), f2 = alpha(x2, nullptr);
        for (int it = 0; it < 40 && hi - lo > 1e-9 * std::max(1.0, hi); ++it) {
            if (f1 < f2) {
                lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = alpha(x2, nullptr);
            } else {
                hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = alpha(x1, nullptr);
            }
        }
        const double xr = f1 > f2 ? x1 : x2;
        const double fr = std::max(f1, f2);
        if (fr > best_value) {
            best_value = fr;
            best_theta = xr;
        }
        units = solved + 1;
        RootResult at_best;
        alpha(best_theta, &at_best);
        if (count > 1) {  // --count roots at the wave number of the abscissa
            per.count = count;
            per.progress = options.roots.progress;
            const RootResult more = rightmost_roots(ring_mode_dde(lin, std::polar(1.0, -best_theta)), per);
            if (more.status == Status::Cancelled) throw Cancelled();  // the callback's stop reaches the caller
            if (more.status == Status::Converged) {
                absorb_status(r, more);
                at_best = more;
            } else {  // the verdict needs only the rightmost root; say why fewer are listed
                r.reason += "; only the rightmost root is listed (" + std::to_string(count) + " did not settle: " + more.message + ")";
            }
        }
        for (const auto& root : at_best.roots) all.push_back({root, -1, best_theta});
        std::sort(all.begin(), all.end(), ring_root_first);

        // the branch through the trivial root: Re lambda(theta) ~ c_k w^k / (2 D(0)^2 Gamma'(0))
        r.trivial_branch_stable = series && (sr.lowfreq_margin / lf.gamma_prime0) < 0.0;
        // the samples stop at theta ~ 1e-5, where the trivial branch is still resolved (Re ~ -theta^2)
        // or given by the expansion above; below that the analytic sign decides
        const double band = all.empty() ? marginal_band(0.0) : marginal_band(all.front().root.value);
        const bool grid_stable = best_value < 0.0 && !met_marginal;
        const int unstable = best_value > band || (series && !r.trivial_branch_stable) ? 1 : 0;
        if (best_value > band || (unstable && best_value > 0.0)) {
            r.spectral_abscissa = best_value;
            r.abscissa_is_limit = false;
            r.abscissa_theta = best_theta;
        } else {
            // sup 0: approached as theta -> 0 (or reached within the band by a marginal root)
            r.spectral_abscissa = 0.0;
            r.abscissa_is_limit = grid_stable;
            r.abscissa_theta = grid_stable ? 0.0 : best_theta;
        }
        const bool marginal = met_marginal && best_value <= band;
        r.marginal_roots = marginal ? 1 : 0;
        // no exact sign for the trivial branch (all of c2..c8 zero to rounding or D(0) = 0): the
        // roots near 0 are on the axis to rounding, a marginal case
        if (grid_stable && !series) r.marginal_roots = 1;
        r.verdict = verdict_of(r.status, unstable, r.marginal_roots);
        r.abscissa_mode = -1;
        r.unstable_roots = -1;
        r.stable = r.verdict == Verdict::Stable;
    }
    // report the `count` rightmost, plus a conjugate partner that ties with the last one
    std::size_t keep = std::min<std::size_t>(all.size(), count);
    if (keep < all.size() && keep > 0 && all[keep - 1].root.value.imag() > 0.0 &&
        all[keep].root.value == std::conj(all[keep - 1].root.value))
        ++keep;
    all.resize(keep);
    r.roots = std::move(all);
    return r;
}

}  // namespace ddemap
