#include "ddemap/analysis/stability/peak_stability.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/internal/text.hpp"
#include "ddemap/solve/integrate.hpp"

namespace ddemap {

void PeakOptions::validate() const {
    if (!(tolerance > 0.0) || !std::isfinite(tolerance)) throw std::invalid_argument("peak tolerance: expected a finite number > 0");
    if (!(max_time > 0.0) || !std::isfinite(max_time)) throw std::invalid_argument("peak max_time: expected a finite number > 0 (s)");
    if (max_steps < 1000) throw std::invalid_argument("peak max_steps: expected >= 1000");
}

namespace {

using Terms = std::vector<std::pair<double, double>>;  // (coefficient, delay)

Terms terms_of(const ExpPoly& p) {
    Terms out;
    for (const auto& t : p.terms()) out.emplace_back(t.coef, t.delay);
    return out;
}

std::string num(double x) { return detail::significant(x, 4); }

/// One resolution: the step response on [0, T] with step h, its total variation and more.
struct Run {
    double norm = 0.0, overshoot = 0.0, tail = 0.0, rounding = 0.0;
    long steps = 0;
    std::vector<double> gradient;  ///< d norm / d direction_k (with directions)
};

/// The derivative of one term list along a direction: the direction's coefficients at the same
/// delays (a delay of the direction that `base` does not have: false).
bool matched(const Terms& base, const Terms& direction, Terms& out) {
    out.clear();
    for (const auto& [c, d] : direction) {
        const bool found = std::any_of(base.begin(), base.end(), [d = d](const auto& t) { return t.second == d; });
        if (!found) return false;
        out.emplace_back(c, d);
    }
    return true;
}

class StepResponse {
public:
    /// Delays below `zero_below` are taken as 0 (a step no longer than each delay would make the
    /// run endless): x(t - d) - x(t) is at most d max|x'|, and short_error() estimates the effect.
    StepResponse(const Linearisation& lin, double zero_below, const std::vector<Linearisation>& directions = {})
        : m_gap(terms_of(lin.gap)), m_own(terms_of(lin.own)), m_lead(terms_of(lin.lead)) {
        for (const Linearisation& dl : directions) {
            Direction dir;
            if (!matched(m_gap, terms_of(dl.gap), dir.gap) || !matched(m_own, terms_of(dl.own), dir.own) ||
                !matched(m_lead, terms_of(dl.lead), dir.lead))
                throw std::invalid_argument("peak string stability: a direction has a delay the linearisation does not (only coefficients may change)");
            m_dir.push_back(std::move(dir));
        }
        auto shorten = [&](Terms& t, bool count) {
            for (auto& [c, d] : t) {
                if (d > 0.0 && d < zero_below) {
                    if (count) m_short += std::abs(c) * d;
                    d = 0.0;
                }
                if (count && d > 0.0) m_delays.push_back(d);
            }
        };
        for (Terms* t : {&m_gap, &m_own, &m_lead}) shorten(*t, true);
        for (Direction& dir : m_dir)
            for (Terms* t : {&dir.gap, &dir.own, &dir.lead}) shorten(*t, false);
        std::sort(m_delays.begin(), m_delays.end());
        m_delays.erase(std::unique(m_delays.begin(), m_delays.end()), m_delays.end());
    }

    /// sum of |c| d over the delays taken as 0, times 10 (|x'| <= 1 to 10 for a unit step here)
    double short_error() const { return 10.0 * m_short; }
    double min_delay() const { return m_delays.empty() ? 0.0 : m_delays.front(); }
    double max_delay() const { return m_delays.empty() ? 0.0 : m_delays.back(); }
    /// sum over all terms of |coefficient|
    double size() const {
        double s = 0.0;
        for (const Terms* t : {&m_gap, &m_own, &m_lead})
            for (const auto& [c, d] : *t) s += std::abs(c);
        return s;
    }

    Run run(double h, double T, double alpha) const {
        // states 0-3: s_a, v_a, s_b, v_b; with directions, 4 more per direction k (at 4 + 4k):
        // their derivatives along it, which obey the same equations forced by the direction's
        // coefficients times the responses themselves
        const int dim = 4 + 4 * static_cast<int>(m_dir.size());
        DdeSolver solver(
            dim, 0.0, [dim](double, double* y) { std::fill(y, y + dim, 0.0); },
            [this](double t, const double* y, const DdeSolver& s, double* f) {
                const auto at = [&](int i, double d) { return d == 0.0 ? y[i] : s.value(i, t - d); };
                double a = 0.0, b = 1.0;
                for (const auto& [c, d] : m_gap) {
                    a += c * at(0, d);
                    b += c * at(2, d);
                }
                for (const auto& [c, d] : m_own) {
                    a += c * at(1, d);
                    b += c * at(3, d);
                }
                f[0] = 1.0 - y[1];
                f[1] = a;
                f[2] = -y[3];
                f[3] = b;
                for (std::size_t k = 0; k < m_dir.size(); ++k) {
                    const int o = 4 + 4 * static_cast<int>(k);
                    double da = 0.0, db = 0.0;
                    for (const auto& [c, d] : m_gap) {
                        da += c * at(o, d);
                        db += c * at(o + 2, d);
                    }
                    for (const auto& [c, d] : m_own) {
                        da += c * at(o + 1, d);
                        db += c * at(o + 3, d);
                    }
                    for (const auto& [c, d] : m_dir[k].gap) {
                        da += c * at(0, d);
                        db += c * at(2, d);
                    }
                    for (const auto& [c, d] : m_dir[k].own) {
                        da += c * at(1, d);
                        db += c * at(3, d);
                    }
                    f[o] = -y[o + 1];
                    f[o + 1] = da;
                    f[o + 2] = -y[o + 3];
                    f[o + 3] = db;
                }
            });
        // the derivatives of the responses jump at sums of up to three delays
        std::vector<double> bp, level{0.0};
        for (int depth = 0; depth < 3; ++depth) {
            std::vector<double> next;
            for (double b : level)
                for (double d : m_delays)
                    if (b + d < T) next.push_back(b + d);
            std::sort(next.begin(), next.end());
            next.erase(std::unique(next.begin(), next.end()), next.end());
            bp.insert(bp.end(), next.begin(), next.end());
            level = std::move(next);
        }
        std::sort(bp.begin(), bp.end());
        bp.erase(std::unique(bp.begin(), bp.end()), bp.end());
        solver.integrate(T, h, bp);
        Run out;
        out.steps = static_cast<long>(solver.steps());
        // y(t) = v_a(t) + sum_j lead_j v_b(t - d_j); h(t) = y'(t) from the right-hand sides
        const auto y = [&](double t) {
            double v = solver.value(1, t);
            for (const auto& [c, d] : m_lead) v += c * solver.value(3, t - d);
            return v;
        };
        // the derivative of y along direction k
        const auto dy = [&](std::size_t k, double t) {
            const int o = 4 + 4 * static_cast<int>(k);
            double v = solver.value(o + 1, t);
            for (const auto& [c, d] : m_lead) v += c * solver.value(o + 3, t - d);
            for (const auto& [c, d] : m_dir[k].lead) v += c * solver.value(3, t - d);
            return v;
        };
        // d TV = sum over the pieces between the nodes and the extrema of sign(y_b - y_a) (dy_b - dy_a):
        // the extrema move with the parameters, but y' = 0 there, so to first order only the
        // values at the (moving) ends of the monotone pieces change
        const std::size_t nd = m_dir.size();
        std::vector<double> grad(nd, 0.0), dya(nd), dyz(nd), dyb(nd);
        auto dy_all = [&](double t, std::vector<double>& out) {
            for (std::size_t k = 0; k < nd; ++k) out[k] = dy(k, t);
        };
        auto add_piece = [&](double from, double to, const std::vector<double>& dfrom, const std::vector<double>& dto) {
            const double sg = to > from ? 1.0 : to < from ? -1.0 : 0.0;
            for (std::size_t k = 0; k < nd; ++k) grad[k] += sg * (dto[k] - dfrom[k]);
        };
        const auto vb_rate = [&](double t) {  // v_b'(t), 0 before the step
            if (t <= 0.0) return 0.0;
            double b = 1.0;
            for (const auto& [c, d] : m_gap) b += c * solver.value(2, t - d);
            for (const auto& [c, d] : m_own) b += c * solver.value(3, t - d);
            return b;
        };
        const auto rate = [&](double t) {
            double a = 0.0;
            if (t > 0.0) {
                for (const auto& [c, d] : m_gap) a += c * solver.value(0, t - d);
                for (const auto& [c, d] : m_own) a += c * solver.value(1, t - d);
            }
            for (const auto& [c, d] : m_lead) a += c * vb_rate(t - d);
            return a;
        };
        // nodes: half steps and the jumps of h (the lead delays)
        std::vector<double> nodes;
        const long n = static_cast<long>(std::ceil(2.0 * T / h));
        nodes.reserve(static_cast<std::size_t>(n) + m_lead.size() + 1);
        for (long k = 0; k <= n; ++k) nodes.push_back(std::min(T, k * (h / 2.0)));
        for (const auto& [c, d] : m_lead)
            if (d > 0.0 && d < T) nodes.push_back(d);
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
        double tv = 0.0, ymax = 0.0, hmax_tail = 0.0;
        const double tail_from = T - std::min(T / 4.0, 5.0 / std::abs(alpha));
        double ya = y(nodes[0]);
        if (nd) dy_all(nodes[0], dya);
        for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
            const double a = nodes[i], b = nodes[i + 1];
            const double yb = y(b);
            if (nd) dy_all(b, dyb);
            const double e = 1e-9 * (b - a);
            const double ra = rate(a + e), rb = rate(b - e);
            if (b > tail_from) hmax_tail = std::max({hmax_tail, std::abs(ra), std::abs(rb)});
            if ((ra > 0.0 && rb < 0.0) || (ra < 0.0 && rb > 0.0)) {
                double lo = a + e, hi = b - e, rlo = ra;
                for (int it = 0; it < 60 && hi - lo > 1e-15 * std::max(1.0, hi); ++it) {
                    const double mid = 0.5 * (lo + hi), rm = rate(mid);
                    if ((rm > 0.0) == (rlo > 0.0)) {
                        lo = mid;
                        rlo = rm;
                    } else {
                        hi = mid;
                    }
                }
                const double yz = y(0.5 * (lo + hi));
                tv += std::abs(yz - ya) + std::abs(yb - yz);
                if (nd) {
                    dy_all(0.5 * (lo + hi), dyz);
                    add_piece(ya, yz, dya, dyz);
                    add_piece(yz, yb, dyz, dyb);
                }
                ymax = std::max(ymax, yz);
            } else {
                tv += std::abs(yb - ya);
                if (nd) add_piece(ya, yb, dya, dyb);
            }
            ymax = std::max(ymax, yb);
            ya = yb;
            dya.swap(dyb);
        }
        out.norm = tv;
        out.gradient = std::move(grad);
        // the rounding of the sum: each of the n increments carries a relative error of a few eps
        out.rounding = 4.0 * std::numeric_limits<double>::epsilon() * static_cast<double>(nodes.size()) * std::max(1.0, tv);
        out.overshoot = std::max(0.0, ymax - 1.0);
        out.tail = hmax_tail / std::abs(alpha);
        return out;
    }

private:
    struct Direction {
        Terms gap, own, lead;
    };
    Terms m_gap, m_own, m_lead;
    std::vector<Direction> m_dir;
    std::vector<double> m_delays;
    double m_short = 0.0;
};

}  // namespace

PeakResult peak_string_stability(const Linearisation& lin, double plant_abscissa, const PeakOptions& options) {
    std::vector<double> none;
    return peak_string_stability(lin, plant_abscissa, options, {}, none);
}

PeakResult peak_string_stability(const Linearisation& lin, double plant_abscissa, const PeakOptions& options,
                                 const std::vector<Linearisation>& directions, std::vector<double>& gradient) {
    options.validate();
    gradient.clear();
    require_single_leader(lin, "peak string stability");
    PeakResult r;
    if (!std::isfinite(plant_abscissa)) {
        r.status = Status::NumericalIssue;
        r.message = "the plant's spectral abscissa is not a number: no peak verdict";
        return r;
    }
    if (plant_abscissa >= 0.0) {
        r.verdict = Verdict::Unstable;
        r.message = "the plant is not stable (rightmost root Re = " + num(plant_abscissa) + "): ||h||_1 is infinite";
        return r;
    }
    double size = 0.0;
    for (const ExpPoly* p : {&lin.gap, &lin.own, &lin.lead}) size += p->abs_sum();
    // delays this short together move ||h||_1 by about half the tolerance at most (short_error)
    const StepResponse sr(lin, options.tolerance / (20.0 * std::max(1.0, size)), directions);
    const double rate = std::max(1.0, sr.size());
    double h = 0.05 / rate;
    if (sr.min_delay() > 0.0) h = std::min(h, sr.min_delay() / 2.0);
    // e^{alpha T} = e^{-30}: the slowest mode has decayed by 1e-13
    double T = std::min(options.max_time, std::max(10.0 * sr.max_delay() + 10.0 * h, 30.0 / -plant_abscissa));
    r.finite = true;
    for (;;) {
        if (T / h > static_cast<double>(options.max_steps)) {
            r.status = Status::BudgetExhausted;
            r.message = "the step response would need " + num(T / h) + " steps (" + num(T) + " s at step " + num(h) + " s), more than " +
                        num(static_cast<double>(options.max_steps)) + ": no peak verdict";
            return r;
        }
        Run coarse = sr.run(h, T, plant_abscissa), fine;
        double diff = 0.0;
        bool settled = false, budget = false, have_fine = false;
        for (int halving = 0; halving < 8; ++halving) {
            if (T / (h / 2.0) > static_cast<double>(options.max_steps)) {
                budget = true;
                break;
            }
            have_fine = true;
            fine = sr.run(h / 2.0, T, plant_abscissa);
            h /= 2.0;
            diff = std::abs(fine.norm - coarse.norm);
            if (diff <= options.tolerance / 2.0) {
                settled = true;
                break;
            }
            coarse = fine;
        }
        if (!have_fine) {  // not even one halving fits the budget: no error estimate
            r.status = Status::BudgetExhausted;
            r.message = "||h||_1 = " + num(coarse.norm) + " at step " + num(h) + " s; checking it at half the step would need " + num(2.0 * T / h) +
                        " steps (" + num(T) + " s), more than " + num(static_cast<double>(options.max_steps)) + ": no peak verdict";
            return r;
        }
        r.norm = fine.norm;
        r.overshoot = fine.overshoot;
        r.t_end = T;
        r.step = h;
        r.steps = fine.steps;
        r.error = diff + fine.tail + sr.short_error() + fine.rounding;
        if (!settled) {
            r.status = budget ? Status::BudgetExhausted : Status::MaxIterations;
            r.message = std::string(budget ? "||h||_1 did not settle within the step budget: " : "||h||_1 did not settle: ") + num(fine.norm) + " and " + num(coarse.norm) + " at steps " + num(h) + " and " +
                        num(2 * h) + " s (tolerance " + num(options.tolerance) + "): no peak verdict";
            return r;
        }
        if (fine.tail <= options.tolerance / 10.0) {
            gradient = fine.gradient;  // only with a converged norm
            break;
        }
        if (T >= options.max_time) {
            r.status = Status::BudgetExhausted;
            r.message = "the step response has not decayed after " + num(T) + " s (tail estimate " + num(fine.tail) + "): no peak verdict";
            return r;
        }
        T = std::min(options.max_time, 2.0 * T);
        h *= 4.0;  // start again two halvings coarser
    }
    r.status = Status::Converged;
    r.verdict = r.norm - 1.0 > r.error ? Verdict::Unstable : Verdict::Stable;
    r.message = "||h||_1 = " + num(r.norm) + " +- " + num(r.error);
    return r;
}

}  // namespace ddemap
