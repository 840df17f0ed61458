#include "ddemap/analysis/stability/string_stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ddemap {

LowFrequency low_frequency_expansion(const Linearisation& lin) {
    require_single_leader(lin, "the low-frequency string condition");
    constexpr int K = 8;
    // every Taylor coefficient of gap, own, lead in one pass over the terms: the same products
    // and sums, in the same order, as ExpPoly::taylor(n) for each n
    auto taylor = [](const ExpPoly& e, double* out) {
        for (int n = 0; n <= K; ++n) out[n] = 0.0;
        for (const auto& t : e.terms()) {
            double p = t.coef;
            out[0] += p;
            for (int k = 1; k <= K; ++k) {
                p *= -t.delay / k;
                out[k] += p;
            }
        }
    };
    double tg[K + 1], to[K + 1], tl[K + 1];
    taylor(lin.gap, tg);
    taylor(lin.own, to);
    taylor(lin.lead, tl);
    double dn[K + 1], nn[K + 1];
    for (int n = 0; n <= K; ++n) {
        dn[n] = (n == 2 ? 1.0 : 0.0) + tg[n] - (n >= 1 ? to[n - 1] : 0.0);
        nn[n] = tg[n] + (n >= 1 ? tl[n - 1] : 0.0);
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
    if (peak) peak_options.validate();
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

namespace {

/// The plant's verdict, the low-frequency series and the search range of analyse_string.
StringResult string_preamble(const Linearisation& lin, const RootResult& plant) {
    StringResult r;
    r.plant_roots = plant;
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
    const double a = lin.gap.abs_sum(), h = lin.own.abs_sum(), l = lin.lead.abs_sum();
    double w_hi = omega_beyond(a, h, l, 1.0) * 1.01;
    if (!(w_hi > 0.0)) w_hi = 1.0;
    r.omega_search_max = w_hi;
    return r;
}

/// Below this frequency the sign of 1 - |Gamma(i w)|^2 may be decided by the low-frequency series.
double series_range(const Linearisation& lin) {
    const double coef = std::max({1.0, lin.max_delay(), lin.gap.abs_sum() + lin.own.abs_sum() + lin.lead.abs_sum()});
    return 1e-2 / coef;
}

/// sup |Gamma|, its frequency, the peak margin and the verdicts from the lowest loss 1 - |Gamma|^2
/// (0 for the limit w -> 0) and the lowest loss over the local maxima (2 when there is none).
void finish_string(StringResult& r, double lowest, double best_w, double lowest_peak) {
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
}

}  // namespace

namespace {
StringResult analyse_string_l2(const Linearisation& lin, RootResult plant, const StringOptions& options);
}  // namespace

StringResult analyse_string(const Linearisation& lin, RootResult plant, const StringOptions& options) {
    options.validate();
    StringResult r = analyse_string_l2(lin, std::move(plant), options);
    if (options.peak) {
        if (r.plant_verdict == Verdict::Undecided) {
            PeakResult p;
            p.status = r.plant_roots.status;
            p.message = "the plant is undecided: no peak verdict";
            r.peak = p;
        } else {
            // an L2 string-unstable car is peak unstable whatever ||h||_1 is: its norm is
            // computed for information with at most kInformativePeakSteps steps (a slowly
            // settling plant would otherwise take seconds for a verdict already known)
            PeakOptions po = options.peak_options;
            if (r.string_verdict == Verdict::Unstable && r.plant_verdict == Verdict::Stable)
                po.max_steps = std::min(po.max_steps, kInformativePeakSteps);
            r.peak = peak_string_stability(lin, r.plant_abscissa, po);
            // |Gamma(i w)| <= ||h||_1 for every w: a certified L2 amplification decides the peak
            // verdict even where ||h||_1 itself could not be computed (its value stays unknown)
            if (r.peak->verdict == Verdict::Undecided && r.string_verdict == Verdict::Unstable && r.plant_verdict == Verdict::Stable) {
                PeakResult p;
                p.status = Status::Converged;
                p.verdict = Verdict::Unstable;
                p.finite = false;
                p.message = "||h||_1 >= sup |Gamma(i w)| > 1 (the car is L2 string unstable); ||h||_1 itself was not computed: " + r.peak->message;
                r.peak = p;
            }
        }
    }
    return r;
}

namespace {
StringResult analyse_string_l2(const Linearisation& lin, RootResult plant, const StringOptions& options) {
    StringResult r = string_preamble(lin, plant);
    const TransferFunction tf(lin);
    const double w_hi = r.omega_search_max;
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
    const double w_series = series_range(lin);
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
    finish_string(r, lowest, best_w, lowest_peak);
    return r;
}
}  // namespace

namespace {

/// One term c s^p e^{-s d} of D or N (p = 0, 1, 2).
struct AxisTerm {
    double c = 0.0;
    int p = 0;
    double d = 0.0;
};

/// D(s) = s^2 - s own(s) + gap(s) and N(s) = gap(s) + s lead(s) as lists of terms, and the bounds
/// sup_{0 <= w <= b} |d^k/dw^k D(i w)| <= sum_j bound_den[k][j] b^j (k = 0..3; the same for N), the
/// sums over the terms of term_bound below written as polynomials in b.
struct AxisTerms {
    std::vector<AxisTerm> den, num;
    std::vector<double> delays;  // the distinct delays
    double bound_den[4][3] = {}, bound_num[4][3] = {};
};

AxisTerms axis_terms(const Linearisation& lin) {
    AxisTerms t;
    t.den.push_back({1.0, 2, 0.0});
    for (const auto& e : lin.own.terms()) t.den.push_back({-e.coef, 1, e.delay});
    for (const auto& e : lin.gap.terms()) {
        t.den.push_back({e.coef, 0, e.delay});
        t.num.push_back({e.coef, 0, e.delay});
    }
    for (const auto& e : lin.lead.terms()) t.num.push_back({e.coef, 1, e.delay});
    for (const auto* list : {&t.den, &t.num})
        for (const auto& e : *list)
            if (std::find(t.delays.begin(), t.delays.end(), e.d) == t.delays.end()) t.delays.push_back(e.d);
    // |c| C(k, j) p! / (p - j)! |d|^{k - j} b^{p - j} for every term (see power_derivative)
    static constexpr double binom[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    auto fill = [](const std::vector<AxisTerm>& terms, double (*poly)[3]) {
        for (const auto& e : terms)
            for (int k = 0; k < 4; ++k) {
                double fall = 1.0;
                for (int j = 0; j <= std::min(k, e.p); ++j) {
                    poly[k][e.p - j] += std::abs(e.c) * binom[k][j] * fall * std::pow(std::abs(e.d), k - j);
                    fall *= (e.p - j);
                }
            }
    };
    fill(t.den, t.bound_den);
    fill(t.num, t.bound_num);
    return t;
}

/// Sums over the terms of the bounds of AxisTerms at b: sup over 0 <= w <= b of |d^k/dw^k D(i w)| (or N), k = 0..3.
struct Bounds {
    double v[4] = {0, 0, 0, 0};
};
Bounds bounds(const double (*poly)[3], double b) {
    Bounds out;
    for (int k = 0; k < 4; ++k) out.v[k] = poly[k][0] + b * (poly[k][1] + b * poly[k][2]);
    return out;
}

/// D, N and their first two s-derivatives at s = i w, with the sizes of their terms.
struct AxisSample {
    double w = 0.0;
    cplx d[3], n[3];
    double size_d[2] = {0, 0}, size_n[2] = {0, 0};  // sums of |terms| of D, D' (N, N')
};

/// d^k/ds^k (s^p e^{-s d}) = e^{-s d} (s^p, p s^{p-1} - d s^p, p (p-1) s^{p-2} - 2 p d s^{p-1} + d^2 s^p), k = 0, 1, 2.
AxisSample axis_sample(const AxisTerms& t, double w) {
    AxisSample x;
    x.w = w;
    const cplx sp[3] = {cplx(1.0), cplx(0.0, w), cplx(-w * w, 0.0)};  // (i w)^n
    cplx e[8];
    const std::size_t nd = std::min<std::size_t>(t.delays.size(), 8);
    for (std::size_t i = 0; i < nd; ++i) e[i] = t.delays[i] == 0.0 ? cplx(1.0) : std::polar(1.0, -w * t.delays[i]);
    auto expo = [&](double d) {
        for (std::size_t i = 0; i < nd; ++i)
            if (t.delays[i] == d) return e[i];
        return std::polar(1.0, -w * d);
    };
    auto add = [&](const std::vector<AxisTerm>& terms, cplx* out) {
        for (const auto& term : terms) {
            const cplx f = term.c * expo(term.d);
            const int p = term.p;
            const double d = term.d;
            const cplx s0 = sp[p], s1 = p >= 1 ? double(p) * sp[p - 1] : cplx(0.0),
                       s2 = p >= 2 ? double(p * (p - 1)) * sp[p - 2] : cplx(0.0);
            out[0] += f * s0;
            out[1] += f * (s1 - d * s0);
            out[2] += f * (s2 - 2.0 * d * s1 + d * d * s0);
        }
    };
    add(t.den, x.d);
    add(t.num, x.n);
    // the sizes of the terms (rounding allowances): the bounds at w
    const Bounds bd = bounds(t.bound_den, w), bn = bounds(t.bound_num, w);
    x.size_d[0] = bd.v[0];
    x.size_d[1] = bd.v[1];
    x.size_n[0] = bn.v[0];
    x.size_n[1] = bn.v[1];
    return x;
}

/// phi = A |D|^2 - |N|^2 and phi' (d/dw = i d/ds) at a sample, with rounding allowances.
struct PhiSample {
    double w = 0.0;
    double phi = 0.0, phi1 = 0.0, tol0 = 0.0, tol1 = 0.0;
    double abs_d = 0.0, abs_d1 = 0.0, abs_n = 0.0, abs_n1 = 0.0;
};

PhiSample phi_sample(const AxisSample& x, double A) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    PhiSample p;
    p.w = x.w;
    p.phi = A * std::norm(x.d[0]) - std::norm(x.n[0]);
    // Re(D_w conj D) = Re(i D_s conj D) = -Im(D_s conj D)
    p.phi1 = -2.0 * A * std::imag(x.d[1] * std::conj(x.d[0])) + 2.0 * std::imag(x.n[1] * std::conj(x.n[0]));
    p.tol0 = 64.0 * eps * (A * x.size_d[0] * x.size_d[0] + x.size_n[0] * x.size_n[0]);
    p.tol1 = 64.0 * eps * 2.0 * (A * x.size_d[0] * x.size_d[1] + x.size_n[0] * x.size_n[1]);
    p.abs_d = std::sqrt(std::norm(x.d[0]));
    p.abs_d1 = std::sqrt(std::norm(x.d[1]));
    p.abs_n = std::sqrt(std::norm(x.n[0]));
    p.abs_n1 = std::sqrt(std::norm(x.n[1]));
    return p;
}

}  // namespace

std::optional<StringResult> analyse_string_continued(const Linearisation& lin, const RootResult& plant,
                                                     const StringGuess& guess, int budget) {
    if (!guess.have || !(guess.omega > 0.0) || !std::isfinite(guess.omega)) return std::nullopt;
    if (!lin.further.empty()) return std::nullopt;
    StringResult r = string_preamble(lin, plant);
    const TransferFunction tf(lin);
    const double w_hi = r.omega_search_max;
    const double w_series = series_range(lin);
    const AxisTerms terms = axis_terms(lin);
    double w = guess.omega;
    for (int restart = 0; restart <= 4; ++restart) {
        // Newton on psi = d/dw log |Gamma(i w)|^2 = 0
        bool converged = false;
        for (int it = 0; it < 16; ++it) {
            if (!(w > 0.0 && w < w_hi)) return std::nullopt;
            const AxisSample x = axis_sample(terms, w);
            ++r.evaluations;
            if (x.d[0] == cplx(0.0) || x.n[0] == cplx(0.0)) return std::nullopt;
            const cplx i(0.0, 1.0);
            const cplx r1 = i * x.n[1] / x.n[0], r2 = i * x.d[1] / x.d[0];
            const double psi = 2.0 * std::real(r1 - r2);
            const double dpsi = 2.0 * std::real(-x.n[2] / x.n[0] - r1 * r1 + x.d[2] / x.d[0] + r2 * r2);
            if (!(dpsi < 0.0) || !std::isfinite(psi)) return std::nullopt;  // not near a maximum
            double step = -psi / dpsi;
            step = std::max(-0.5 * w, std::min(0.5 * w, step));
            w += step;
            if (std::abs(step) <= 4.0 * std::numeric_limits<double>::epsilon() * w) {
                converged = true;
                break;
            }
        }
        if (!converged || !(w > w_series && w < w_hi)) return std::nullopt;
        const double lw = tf.attenuation(w);
        ++r.evaluations;
        if (!(lw <= 0.0) || !std::isfinite(lw)) return std::nullopt;  // the highest peak must be the sup
        const double g = 1.0 - lw;
        const double A = g * (1.0 + kStringExclusionSlack);

        // the neighbourhood of w*: phi(w* + t) >= phi0 + phi1 t + phi2 t^2 / 2 - M3 |t|^3 / 6
        const AxisSample xs = axis_sample(terms, w);
        ++r.evaluations;
        const PhiSample ps = phi_sample(xs, A);
        constexpr double eps = std::numeric_limits<double>::epsilon();
        const double phi2 = 2.0 * A * (-std::real(xs.d[2] * std::conj(xs.d[0])) + std::norm(xs.d[1])) -
                            2.0 * (-std::real(xs.n[2] * std::conj(xs.n[0])) + std::norm(xs.n[1]));
        const double tol2 = 64.0 * eps * 2.0 * (A * (xs.size_d[0] * xs.size_d[0] + xs.size_d[1] * xs.size_d[1] * 4.0) +
                                                 xs.size_n[0] * xs.size_n[0] + xs.size_n[1] * xs.size_n[1] * 4.0 +
                                                 A * std::abs(xs.d[2]) * xs.size_d[0] + std::abs(xs.n[2]) * xs.size_n[0]);
        double rho = 0.25 * std::min(w, w_hi - w);
        bool near_ok = false;
        const double p2 = phi2 - tol2;
        if (p2 > 0.0) {
            for (int k = 0; k < 60; ++k) {
                const Bounds bd = bounds(terms.bound_den, w + rho), bn = bounds(terms.bound_num, w + rho);
                const double d0 = std::min(bd.v[0], ps.abs_d + rho * bd.v[1]), d1 = std::min(bd.v[1], ps.abs_d1 + rho * bd.v[2]);
                const double n0 = std::min(bn.v[0], ps.abs_n + rho * bn.v[1]), n1 = std::min(bn.v[1], ps.abs_n1 + rho * bn.v[2]);
                const double m3 = 2.0 * A * (bd.v[3] * d0 + 3.0 * bd.v[2] * d1) + 2.0 * (bn.v[3] * n0 + 3.0 * bn.v[2] * n1);
                const double c2 = 0.5 * p2 - m3 * rho / 6.0;
                if (c2 > 0.125 * p2) {
                    const double a1 = std::abs(ps.phi1) + ps.tol1;
                    near_ok = ps.phi - ps.tol0 - a1 * a1 / (4.0 * c2) > 0.0;
                    break;
                }
                rho *= 0.5;
            }
        }
        if (!near_ok) return std::nullopt;

        // the rest of [0, w_hi] by quadratic Taylor bounds from both ends of each piece
        std::optional<double> higher;
        auto sample = [&](double x) {
            ++r.evaluations;
            return phi_sample(axis_sample(terms, x), A);
        };
        auto piece_ok = [&](const PhiSample& a, const PhiSample& b) {
            const double h = b.w - a.w;
            const Bounds bd = bounds(terms.bound_den, b.w), bn = bounds(terms.bound_num, b.w);
            const double d1 = std::min(bd.v[1], 0.5 * (a.abs_d1 + b.abs_d1 + h * bd.v[2]));
            const double d0 = std::min(bd.v[0], 0.5 * (a.abs_d + b.abs_d + h * d1));
            const double n1 = std::min(bn.v[1], 0.5 * (a.abs_n1 + b.abs_n1 + h * bn.v[2]));
            const double n0 = std::min(bn.v[0], 0.5 * (a.abs_n + b.abs_n + h * n1));
            const double m2 = 2.0 * A * (bd.v[2] * d0 + d1 * d1) + 2.0 * (bn.v[2] * n0 + n1 * n1);
            const double q = m2 * h * h / 8.0;
            const double la = a.phi - a.tol0 + std::min(0.0, (a.phi1 - a.tol1) * 0.5 * h) - q;
            const double lb = b.phi - b.tol0 + std::min(0.0, -(b.phi1 + b.tol1) * 0.5 * h) - q;
            return a.phi - a.tol0 > 0.0 && b.phi - b.tol0 > 0.0 && la > 0.0 && lb > 0.0;
        };
        auto cover = [&](double lo, double hi) {
            if (!(hi > lo)) return true;
            std::vector<std::pair<PhiSample, PhiSample>> stack;
            stack.push_back({sample(lo), sample(hi)});
            while (!stack.empty()) {
                auto [a, b] = stack.back();
                stack.pop_back();
                if (a.phi < -a.tol0) {
                    higher = a.w;
                    return false;
                }
                if (b.phi < -b.tol0) {
                    higher = b.w;
                    return false;
                }
                if (piece_ok(a, b)) continue;
                if (r.evaluations > budget) return false;
                const double m = 0.5 * (a.w + b.w);
                if (!(m > a.w && m < b.w)) return false;
                const PhiSample c = sample(m);
                stack.push_back({c, b});
                stack.push_back({a, c});
            }
            return true;
        };
        const bool ok = cover(0.0, w - rho) && cover(w + rho, w_hi);
        if (ok) {
            r.peaks.push_back({w, std::sqrt(g)});
            finish_string(r, lw < 0.0 ? lw : 0.0, lw < 0.0 ? w : 0.0, lw);
            return r;
        }
        if (!higher || *higher <= 0.0) return std::nullopt;
        w = *higher;  // the neighbour's maximiser was not the highest peak: Newton from the higher point
    }
    return std::nullopt;
}

}  // namespace ddemap
