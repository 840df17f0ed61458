#include "ddemap/analysis/stability/attenuation_margin.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/solve/optimize/golden.hpp"

namespace ddemap {

namespace {


// Refines the (up to) three lowest interior local minima of v on the grid u; returns the best
// (value, u) over them and the grid.
template <class F>
std::pair<double, double> refine_minima(const F& h, const std::vector<double>& u, const std::vector<double>& v, int& evaluations,
                                        std::vector<std::pair<double, double>>* all = nullptr) {
    std::vector<std::size_t> minima;
    for (std::size_t i = 1; i + 1 < u.size(); ++i)
        if (v[i] <= v[i - 1] && v[i] <= v[i + 1]) minima.push_back(i);
    std::sort(minima.begin(), minima.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
    if (minima.size() > 3) minima.resize(3);
    std::size_t ib = static_cast<std::size_t>(std::min_element(v.begin(), v.end()) - v.begin());
    std::pair<double, double> best{v[ib], u[ib]};
    for (std::size_t i : minima) {
        double val = 0.0;
        const double at = golden_minimize(h, u[i - 1], u[i + 1], val, evaluations);
        if (all) all->push_back({val, at});
        if (val < best.first) best = {val, at};
    }
    return best;
}

}  // namespace

AttenuationScan attenuation_scan(const Linearisation& lin, double weight, int grid) {
    if (!(weight >= 0.0) || !std::isfinite(weight))
        throw std::invalid_argument("attenuation_scan: weight = " + std::to_string(weight) + " s: expected a finite number >= 0");
    if (grid < 16) throw std::invalid_argument("attenuation_scan: grid = " + std::to_string(grid) + ": expected at least 16 points");
    const LowFrequency lf = low_frequency_expansion(lin);
    if (lf.d0 == 0.0) throw std::invalid_argument("attenuation margin: D(0) = 0 (no restoring gap term): Gamma(0) is not 1");
    const TransferFunction tf(lin);
    AttenuationScan s;
    const double scale = std::sqrt(lin.gap.abs_sum()) + lin.own.abs_sum() + lin.lead.abs_sum();
    const double w_lo = 1e-5 * scale, w_hi = 1e5 * scale;
    std::vector<double> u(static_cast<std::size_t>(grid)), neg_gain(u.size()), ratio(u.size()), neg_weighted(u.size());
    s.weight = weight;
    auto gain_at = [&](double uu) {
        return -std::abs(tf(cplx(0.0, std::exp(uu))));
    };
    auto weighted_at = [&](double uu) {
        const double w = std::exp(uu);
        return -std::abs(tf(cplx(0.0, w))) * std::hypot(1.0, weight * w);
    };
    auto ratio_at = [&](double uu) {
        const double w = std::exp(uu);
        double q = 0.0;
        tf.attenuation(w, &q);
        const double n2 = std::norm(tf.numerator(cplx(0.0, w)));
        return n2 > 0.0 ? q / n2 : std::numeric_limits<double>::infinity();
    };
    for (std::size_t i = 0; i < u.size(); ++i) {
        u[i] = std::log(w_lo) + (std::log(w_hi) - std::log(w_lo)) * static_cast<double>(i) / static_cast<double>(grid - 1);
        neg_gain[i] = gain_at(u[i]);
        ratio[i] = ratio_at(u[i]);
        neg_weighted[i] = weight > 0.0 ? weighted_at(u[i]) : neg_gain[i];
    }
    s.evaluations = 2 * grid;
    const auto g = refine_minima(gain_at, u, neg_gain, s.evaluations);
    if (-g.first > 1.0) {
        s.sup_gamma = -g.first;
        s.omega_sup = std::exp(g.second);
    }
    if (weight > 0.0) {
        const auto h = refine_minima(weighted_at, u, neg_weighted, s.evaluations);
        if (-h.first > 1.0) {
            s.weighted_sup = -h.first;
            s.omega_weighted = std::exp(h.second);
        }
    } else {
        s.weighted_sup = s.sup_gamma;
        s.omega_weighted = s.omega_sup;
    }
    std::vector<std::pair<double, double>> minima;
    const auto m = refine_minima(ratio_at, u, ratio, s.evaluations, &minima);
    const double mu0 = lf.c2 / (lf.d0 * lf.d0);
    s.mu_minima.push_back({0.0, mu0});
    for (const auto& [val, at] : minima) s.mu_minima.push_back({std::exp(at), val});
    if (ratio.back() < ratio[ratio.size() - 2]) s.mu_minima.push_back({w_hi, ratio.back()});
    if (mu0 <= m.first) {
        s.mu = mu0;
        s.omega_mu = 0.0;
    } else {
        s.mu = m.first;
        s.omega_mu = std::exp(m.second);
    }
    s.margin = std::copysign(std::sqrt(std::abs(s.mu)), s.mu);
    return s;
}

double attenuation_piece(const Linearisation& lin, double omega, double m2) {
    // at w = 0 for ovrv: 2 B - m2 k1 with B of the design's infeasibility proof, linear in
    // (k1, k2), where mu = c2 / k1^2 itself is far from linear
    if (omega == 0.0) {
        const LowFrequency lf = low_frequency_expansion(lin);
        return (lf.c2 - m2 * lf.d0 * lf.d0) / std::abs(lf.d0);
    }
    const TransferFunction tf(lin);
    double q = 0.0;
    tf.attenuation(omega, &q);
    const double nn = std::abs(tf.numerator(cplx(0.0, omega)));
    if (!(nn > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return (q - m2 * nn * nn) / nn;
}

}  // namespace ddemap
