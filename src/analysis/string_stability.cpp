#include "ddemap/analysis/string_stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ddemap {

LowFrequency low_frequency_expansion(const Linearisation& lin) {
    require_single_leader(lin, "the low-frequency string condition");
    constexpr int K = 8;
    double dn[K + 1], nn[K + 1];
    for (int n = 0; n <= K; ++n) {
        dn[n] = (n == 2 ? 1.0 : 0.0) + lin.gap.taylor(n) - (n >= 1 ? lin.own.taylor(n - 1) : 0.0);
        nn[n] = lin.gap.taylor(n) + (n >= 1 ? lin.lead.taylor(n - 1) : 0.0);
    }
    // F(i w) = sum F_n i^n w^n = R(w) + i I(w); |F|^2 coefficients by convolution
    auto split = [](const double* f, double* r, double* i) {
        for (int n = 0; n <= K; ++n) {
            const int q = n % 4;
            const double sign = (q == 0 || q == 1) ? 1.0 : -1.0;  // i^n = 1, i, -1, -i
            r[n] = (n % 2 == 0) ? sign * f[n] : 0.0;
            i[n] = (n % 2 == 1) ? sign * f[n] : 0.0;
        }
    };
    double dr[K + 1], di[K + 1], nr[K + 1], ni[K + 1];
    split(dn, dr, di);
    split(nn, nr, ni);
    double p[K + 1] = {0}, scale[K + 1] = {0};
    for (int k = 0; k <= K; ++k) {
        for (int a = 0; a <= k; ++a) {
            const int b = k - a;
            const double d2 = dr[a] * dr[b] + di[a] * di[b];
            const double n2 = nr[a] * nr[b] + ni[a] * ni[b];
            p[k] += d2 - n2;
            scale[k] += std::abs(dr[a] * dr[b]) + std::abs(di[a] * di[b]) + std::abs(nr[a] * nr[b]) +
                        std::abs(ni[a] * ni[b]);
        }
    }
    LowFrequency lf;
    lf.c2 = p[2];
    lf.c4 = p[4];
    lf.c6 = p[6];
    lf.c8 = p[8];
    for (int k = 2; k <= K; k += 2) {
        if (std::abs(p[k]) > 64.0 * std::numeric_limits<double>::epsilon() * scale[k]) {
            lf.decisive_order = k;
            lf.attenuates = p[k] > 0.0;
            break;
        }
        if (k == 2) lf.c2 = 0.0;  // zero to rounding
        if (k == 4) lf.c4 = 0.0;
        if (k == 6) lf.c6 = 0.0;
        if (k == 8) lf.c8 = 0.0;
    }
    lf.d0 = dn[0];
    if (dn[0] != 0.0) lf.gamma_prime0 = (nn[1] * dn[0] - nn[0] * dn[1]) / (dn[0] * dn[0]);
    return lf;
}

namespace {
double coefficient_sum(const Linearisation& lin) {
    double c = lin.gap.abs_sum() + lin.own.abs_sum() + lin.lead.abs_sum();
    for (const auto& f : lin.further) c += f.abs_sum();
    return c;
}
}  // namespace

double scaled_delay(const Linearisation& lin) {
    const double c = coefficient_sum(lin), tau = lin.max_delay();
    return tau > 0.0 ? c * tau : c;
}

bool is_computable(const Linearisation& lin) {
    const double c = coefficient_sum(lin);
    return c <= kMaxCoefficientSum && c * lin.max_delay() <= kMaxScaledDelay;
}

void require_computable(const Linearisation& lin, const std::string& what) {
    const double c = coefficient_sum(lin);
    const double tau = lin.max_delay();
    std::ostringstream os;
    os.precision(4);
    if (!what.empty()) os << what << ": ";
    if (!(c <= kMaxCoefficientSum)) {
        os << "the gains are outside the computable range: the sum of the absolute coefficients (OVRV: k1 (1 + th) + 2 k2) is "
           << c << ": expected <= " << kMaxCoefficientSum;
        throw std::invalid_argument(os.str());
    }
    if (!(c * tau <= kMaxScaledDelay)) {
        os << "gains and delay outside the computable range: tau_max times the sum of the absolute coefficients (OVRV: tau (k1 (1 + th) + 2 k2)) is "
           << c * tau << ": expected <= " << kMaxScaledDelay << " (the collocation degree grows with |lambda| tau)";
        throw std::invalid_argument(os.str());
    }
}

void StringOptions::validate() const {
    roots.validate();
    if (plant_roots < 1) throw std::invalid_argument("plant_roots = " + std::to_string(plant_roots) + ": expected >= 1");
    if (grid_points < 16) throw std::invalid_argument("grid_points = " + std::to_string(grid_points) + ": expected >= 16");
}

namespace {

/// Smallest w such that for all larger w the bound (a + l w) / (w^2 - h w - a) < target.
double omega_beyond(double a, double h, double l, double target) {
    const double b = h + l / target;
    const double c = a * (1.0 + 1.0 / target);
    return 0.5 * (b + std::sqrt(b * b + 4.0 * c));
}

/// Maximiser of |Gamma(i w)|^2 in [lo, hi] bracketing a local maximum.
double refine_peak(const TransferFunction& tf, double lo, double hi, int& evals) {
    double dlo = tf.gain2_derivative(lo), dhi = tf.gain2_derivative(hi);
    evals += 2;
    if (dlo > 0.0 && dhi < 0.0) {
        // Illinois false position on the derivative, safeguarded by bisection
        for (int it = 0; it < 200 && hi - lo > 4.0 * std::numeric_limits<double>::epsilon() * hi; ++it) {
            double x = (it % 3 == 2) ? 0.5 * (lo + hi) : lo - dlo * (hi - lo) / (dhi - dlo);
            if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
            const double dx = tf.gain2_derivative(x);
            ++evals;
            if (dx == 0.0) return x;
            if (dx > 0.0) {
                lo = x;
                dlo = dx;
            } else {
                hi = x;
                dhi = dx;
            }
        }
        return tf.gain2(lo) >= tf.gain2(hi) ? lo : hi;
    }
    // golden section on the gain itself
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = tf.gain2(x1), f2 = tf.gain2(x2);
    evals += 2;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        if (f1 < f2) {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = tf.gain2(x2);
        } else {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = tf.gain2(x1);
        }
        ++evals;
    }
    return f1 > f2 ? x1 : x2;
}

}  // namespace

StringResult analyse_string(const Linearisation& lin, const StringOptions& options) {
    options.validate();
    require_computable(lin);
    // The rightmost plant roots decide plant stability; the last one found also bounds the width
    // of every resonance peak of roots further left (see the grid step below).
    RootOptions ro = options.roots;
    ro.count = options.plant_roots;
    return analyse_string(lin, rightmost_roots(plant_dde(lin), ro), options);
}

StringResult analyse_string(const Linearisation& lin, RootResult plant, const StringOptions& options) {
    options.validate();
    StringResult r;
    r.plant_roots = std::move(plant);
    r.plant_abscissa = r.plant_roots.spectral_abscissa();
    r.plant_stable = r.plant_roots.status == Status::Converged && !r.plant_roots.roots.empty() &&
                     r.plant_abscissa < -marginal_band(r.plant_roots.roots.front().value);
    if (r.plant_roots.status != Status::Converged || r.plant_roots.roots.empty()) {
        r.plant_verdict = Verdict::Undecided;
    } else {
        const double band = marginal_band(r.plant_roots.roots.front().value);
        r.plant_verdict = r.plant_abscissa > band ? Verdict::Unstable : r.plant_stable ? Verdict::Stable : Verdict::Marginal;
    }

    r.lowfreq = low_frequency_expansion(lin);
    switch (r.lowfreq.decisive_order) {
        case 2: r.lowfreq_margin = r.lowfreq.c2; break;
        case 4: r.lowfreq_margin = r.lowfreq.c4; break;
        case 6: r.lowfreq_margin = r.lowfreq.c6; break;
        case 8: r.lowfreq_margin = r.lowfreq.c8; break;
        default: r.lowfreq_margin = 0.0;
    }

    const TransferFunction tf(lin);
    const double a = lin.gap.abs_sum(), h = lin.own.abs_sum(), l = lin.lead.abs_sum();
    double w_hi = omega_beyond(a, h, l, 1.0) * 1.01;
    if (!(w_hi > 0.0)) w_hi = 1.0;
    r.omega_search_max = w_hi;
    const double tau = lin.max_delay();

    std::vector<double> grid;
    const int np = options.grid_points;
    const double w_lo = w_hi * 1e-6;
    grid.reserve(static_cast<std::size_t>(np) + 256);
    {
        // geometric: w_lo rho^i, rho = (w_hi / w_lo)^(1 / (np - 1)), by products (one pow)
        const double rho = std::pow(w_hi / w_lo, 1.0 / (np - 1));
        double w = w_lo;
        for (int i = 0; i < np; ++i, w *= rho) grid.push_back(w);
    }
    const std::size_t geometric = grid.size();
    double step = w_hi / np;
    if (tau > 0.0) step = std::min(step, M_PI / (8.0 * tau));
    // roots of D left of those computed have Re <= the last computed one: their peaks are at
    // least that wide, so a step below half of it resolves them
    if (!r.plant_roots.roots.empty()) {
        const double last = std::abs(r.plant_roots.roots.back().value.real());
        if (last > 0.0) step = std::min(step, 0.5 * last);
    }
    step = std::max(step, w_hi / 50000.0);
    for (double w = step; w < w_hi; w += step) grid.push_back(w);
    // each piece of the grid is sorted: merged in, not sorted
    std::inplace_merge(grid.begin(), grid.begin() + static_cast<std::ptrdiff_t>(geometric), grid.end());
    auto merge_from = [&](std::size_t start) {
        std::inplace_merge(grid.begin(), grid.begin() + static_cast<std::ptrdiff_t>(start), grid.end());
    };
    for (const auto& root : r.plant_roots.roots) {
        const double wp = root.value.imag();
        if (wp <= 0.0 || wp >= w_hi) continue;
        const double width = std::max(std::abs(root.value.real()), 1e-12 * wp);
        const std::size_t start = grid.size();
        for (int j = -6; j <= 6; ++j) {
            const double w = wp + j * 0.5 * width;
            if (w > 0.0 && w < w_hi) grid.push_back(w);
        }
        merge_from(start);
    }
    if (!r.lowfreq.attenuates && r.lowfreq.decisive_order == 2 && r.lowfreq.c4 > 0.0) {
        const double wc = std::sqrt(-r.lowfreq.c2 / (2.0 * r.lowfreq.c4));
        const std::size_t start = grid.size();
        // wc 10^(-2 + 3 i / 60), i = 0..60, by products (one pow)
        const double rho = std::pow(10.0, 3.0 / 60.0);
        double w = wc * 1e-2;
        for (int i = 0; i <= 60; ++i, w *= rho)
            if (w < w_hi) grid.push_back(w);
        merge_from(start);
    }
    grid.erase(std::unique(grid.begin(), grid.end()), grid.end());

    // 1 - |Gamma|^2 in its cancellation-free form (TransferFunction::attenuation); where its
    // sign is lost in rounding at small w, the low-frequency series decides (exact there).
    const double coef = std::max({1.0, tau, a + h + l});
    const double w_series = 1e-2 / coef;
    auto loss = [&](double w) {
        double q = 0.0, noise = 0.0;
        // the rounding bound of q matters only where the series may take over
        const bool series = w <= w_series && r.lowfreq.decisive_order > 0;
        double att = tf.attenuation(w, &q, series ? &noise : nullptr);
        if (series && std::abs(q) <= noise) {
            const double w2 = w * w;
            q = r.lowfreq.c2 + w2 * (r.lowfreq.c4 + w2 * (r.lowfreq.c6 + w2 * r.lowfreq.c8));
            cplx n, d;
            tf.evaluate(cplx(0.0, w), n, d);
            att = w2 * q / std::norm(d);
        }
        ++r.evaluations;
        return att;
    };
    std::vector<double> g(grid.size());
    for (std::size_t i = 0; i < grid.size(); ++i) g[i] = loss(grid[i]);

    // local minima of the loss are the peaks of |Gamma|; a minimum at the first sample when low
    // frequencies amplify: move the bracket towards 0
    std::vector<std::pair<std::size_t, std::pair<double, double>>> brackets;
    if (grid.size() >= 2 && g[0] < g[1] && g[0] < 0.0) brackets.push_back({0, {0.0, grid[1]}});
    for (std::size_t i = 1; i + 1 < grid.size(); ++i) {
        if (g[i] <= g[i - 1] && g[i] < g[i + 1]) brackets.push_back({i, {grid[i - 1], grid[i + 1]}});
    }
    double lowest = 0.0;  // the limit w -> 0
    double best_w = 0.0;
    double lowest_peak = 2.0;
    for (const auto& [i, br] : brackets) {
        const auto [lo, hi] = br;
        double w = refine_peak(tf, lo > 0.0 ? lo : hi * 1e-9, hi, r.evaluations);
        double lw = loss(w);
        if (!(lw <= g[i])) {  // the refinement may not beat its sample (flat peak, rounding)
            w = grid[i];
            lw = g[i];
        }
        if (!std::isfinite(lw)) continue;
        r.peaks.push_back({w, std::sqrt(1.0 - lw)});
        lowest_peak = std::min(lowest_peak, lw);
        if (lw < lowest) {
            lowest = lw;
            best_w = w;
        }
    }
    std::sort(r.peaks.begin(), r.peaks.end(), [](const GainPeak& x, const GainPeak& y) { return x.omega < y.omega; });
    r.sup_gamma = std::sqrt(1.0 - lowest);
    r.omega_peak = best_w;
    // 1 - sqrt(1 - loss) without cancellation
    r.peak_margin = lowest_peak > 1.0 ? 1.0 : lowest_peak / (1.0 + std::sqrt(1.0 - lowest_peak));
    r.string_stable = r.plant_stable && r.lowfreq.attenuates && lowest_peak >= 0.0;
    if (r.plant_verdict == Verdict::Undecided) {
        r.string_verdict = Verdict::Undecided;
    } else if (r.plant_verdict == Verdict::Unstable || lowest_peak < 0.0 || (r.lowfreq.decisive_order > 0 && !r.lowfreq.attenuates)) {
        r.string_verdict = Verdict::Unstable;
    } else {
        r.string_verdict = r.string_stable ? Verdict::Stable : Verdict::Marginal;
    }
    return r;
}

}  // namespace ddemap
