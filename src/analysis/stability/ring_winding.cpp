#include "ddemap/analysis/stability/ring_winding.hpp"

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "ddemap/analysis/stability/string_stability.hpp"
#include "core/internal/text.hpp"
#include "ddemap/core/newton.hpp"
#include "ddemap/core/phase_tracking.hpp"
#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/ring.hpp"

namespace ddemap {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
constexpr double kEps = std::numeric_limits<double>::epsilon();

double wrap_angle(double a) {
    a = std::fmod(a, kTwoPi);
    if (a < 0.0) a += kTwoPi;
    if (a >= kTwoPi) a = 0.0;
    return a;
}

/// Roots accounted for by Newton right of the axis (analyse_ring_winding's few-mode shortcut) lie
/// at least this far right of it, relative to max(1, |z|): clear of the marginal band and of Newton's
/// rounding.
constexpr double kAccountedClear = 1e-6;

/// The gap of the sweep's certificates: no zero right of Re z + 1e-10 max(1, |z|).
double certificate_gap(cplx z) { return 1e-10 * std::max(1.0, std::abs(z)); }

/// Sums of |coefficients| of gap, own and lead weighted by e^{-sigma d_j}.
struct Sizes {
    double gap = 0.0, own = 0.0, lead = 0.0;
};
Sizes sizes_at(const Linearisation& lin, double sigma) {
    Sizes z;
    auto sum = [&](const ExpPoly& e) {
        double s = 0.0;
        for (const auto& t : e.terms()) s += std::abs(t.coef) * (t.delay == 0.0 ? 1.0 : std::exp(-sigma * t.delay));
        return s;
    };
    z.gap = sum(lin.gap);
    z.own = sum(lin.own);
    z.lead = sum(lin.lead);
    return z;
}

/// r with |P - (lambda - sigma)^2| + |Q| < r^2 / 2 on |lambda - sigma| >= r, Re lambda >= sigma
/// (0 when none is found).
double half_disc_radius(const Sizes& z, double sigma) {
    const double s = std::abs(sigma);
    // |2 sigma lambda - sigma^2 - lambda own + gap| + |gap + lambda lead| <= c0 + c1 |lambda|
    const double c0 = s * s + 2.0 * z.gap, c1 = 2.0 * s + z.own + z.lead;
    auto enough = [&](double r) { return c0 + c1 * (r + s) < 0.5 * r * r; };
    double r = 1.0;
    for (int i = 0; i < 400 && !enough(r); ++i) r *= 1.25;
    return enough(r) ? r : 0.0;
}

struct Sample {
    double s = 0.0;
    cplx g, dg;        // Gamma and dGamma/ds at sigma + i s
    PhaseSample p;     // P with |P'/P|^2
    double ell = 0.0;  // log |Gamma|
    int side = 0;      // -1 inside the unit circle, +1 outside, 0 on it to rounding
    // formed once per sample (piece() looks at each sample up to three times)
    double rate = 0.0;    // d log|Gamma| / ds = Re(dGamma/ds / Gamma)
    double speed2 = 0.0;  // |dGamma/ds|^2 / max(|Gamma|^2, 1/4)
    double g2 = 0.0, dg2 = 0.0;  // |Gamma|^2, |dGamma/ds|^2
};

class LineSampler {
public:
    LineSampler(const TransferFunction& tf, const Linearisation& lin, double sigma, int budget)
        : budget(budget), m_tf(tf), m_line(tf, sigma), m_sigma(sigma), m_sizes(sizes_at(lin, sigma)) {}
    int budget;
    bool failed = false;
    long evaluations = 0;
    std::string why;

    Sample operator()(double s) {
        ++evaluations;
        Sample x;
        x.s = s;
        cplx n, d, dn, dd;
        m_line(s, n, d, dn, dd);  // one sin/cos per delay, real arithmetic
        const double nn = n.real() * n.real() + n.imag() * n.imag(), nd = d.real() * d.real() + d.imag() * d.imag();
        if (nd == 0.0 || !std::isfinite(nd) || !std::isfinite(nn)) {
            fail("a zero of the plant's P on the line");
            return x;
        }
        // Gamma = N conj(D) / |D|^2 and dGamma/ds = i Gamma' = i (N' - Gamma D') / D
        const double gr = (n.real() * d.real() + n.imag() * d.imag()) / nd, gi = (n.imag() * d.real() - n.real() * d.imag()) / nd;
        x.g = cplx(gr, gi);
        const double ur = dn.real() - (gr * dd.real() - gi * dd.imag()), ui = dn.imag() - (gr * dd.imag() + gi * dd.real());
        const double vr = (ur * d.real() + ui * d.imag()) / nd, vi = (ui * d.real() - ur * d.imag()) / nd;  // (N' - Gamma D') / D
        x.dg = cplx(-vi, vr);
        x.p = {s, d, (dd.real() * dd.real() + dd.imag() * dd.imag()) / nd};
        x.g2 = std::norm(x.g);
        x.dg2 = std::norm(x.dg);
        x.rate = (x.dg.real() * gr + x.dg.imag() * gi) / x.g2;  // Re(dGamma/ds conj(Gamma)) / |Gamma|^2
        x.speed2 = x.dg2 / std::max(x.g2, 0.25);
        x.ell = nn > 0.0 ? 0.5 * std::log(nn / nd) : -std::numeric_limits<double>::infinity();
        if (m_sigma == 0.0 && std::abs(x.ell) < 1e-6) {
            if (s == 0.0) {  // Gamma(0) = 1: the tangency, decided by the series
                x.ell = 0.0;
                x.side = 0;
            } else {
                double q = 0.0, noise = 0.0;
                const double a = m_tf.attenuation(s, &q, &noise);  // 1 - |Gamma|^2 without cancellation
                x.ell = 0.5 * std::log1p(-a);
                x.side = std::abs(q) <= noise ? 0 : (q < 0.0 ? 1 : -1);
            }
        } else {
            // rounding of |N| and |D| relative to the sizes of their terms
            const double al = std::sqrt(m_sigma * m_sigma + s * s);  // |lambda|
            const double big_d = al * al + al * m_sizes.own + m_sizes.gap, big_n = m_sizes.gap + al * m_sizes.lead;
            const double tol = 8.0 * kEps * (big_d / std::sqrt(nd) + big_n / std::sqrt(std::max(nn, 1e-300)));
            x.side = x.ell > tol ? 1 : (x.ell < -tol ? -1 : 0);
        }
        if (!std::isfinite(x.g.real()) || !std::isfinite(x.g.imag()) || !std::isfinite(x.dg.real()) ||
            !std::isfinite(x.dg.imag()))
            fail("a non-finite value of Gamma on the line");
        return x;
    }
    void fail(const std::string& w) {
        if (!failed) why = w;
        failed = true;
    }

private:
    const TransferFunction& m_tf;
    TransferFunction::Line m_line;
    double m_sigma;
    Sizes m_sizes;
};


/// Signed crossings of the ray {p + t u : t > 0} by the segment from x to y: +1 when the
/// segment passes it counter-clockwise about p. Summed over a closed polygon that keeps away
/// from p, this is its winding number about p (no arctangents).
int ray_crossing(cplx x, cplx y, cplx p, cplx u) {
    const cplx a = (x - p) * std::conj(u), b = (y - p) * std::conj(u);
    if ((a.imag() < 0.0) == (b.imag() < 0.0)) return 0;
    // where the segment meets the line of the ray: Re there, by interpolation in Im
    const double t = a.imag() / (a.imag() - b.imag());
    if (a.real() + t * (b.real() - a.real()) <= 0.0) return 0;
    return a.imag() < 0.0 ? 1 : -1;
}

/// d log|Gamma| / ds
double ell_rate(const Sample& x) { return x.rate; }
int sign_of(double v) { return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0); }

/// One pass along [0, r] (see the file comment of the header for the acceptance tests).
struct Pass {
    LineSampler& f;
    bool on_axis;
    int touch_side;                      // the series' side of the circle next to s = 0 (0: unknown)
    std::vector<Sample> path;            // accepted samples in order of s
    std::vector<double> reach;           // excursion bound between path[j] and path[j + 1]
    std::vector<WindingCrossing> crossings;
    int p_turns = 0;                     // signed crossings of the negative real axis by P along [0, r]

    void accept(const Sample& a, const Sample& m, const Sample& b, double e) {
        path.push_back(m);
        path.push_back(b);
        reach.push_back(e);
        reach.push_back(e);
        // each half turns arg P by less than pi/4: its continuous change is the change of the
        // principal args plus 2 pi per crossing of the negative real axis
        p_turns += ray_crossing(a.p.f, m.p.f, 0.0, -1.0) + ray_crossing(m.p.f, b.p.f, 0.0, -1.0);
    }

    void locate(Sample lo, Sample hi, int direction) {
        // Illinois iterations on log|Gamma| between samples on either side of the circle
        double fl = lo.ell, fh = hi.ell;
        if (sign_of(fl) != lo.side) fl = lo.side * std::abs(fl);
        if (sign_of(fh) != hi.side) fh = hi.side * std::abs(fh);
        int last = 0;
        Sample x = lo;
        bool exact = false;
        for (int it = 0; it < 100 && hi.s - lo.s > 4.0 * kEps * std::max(1.0, hi.s); ++it) {
            double s = (lo.s * fh - hi.s * fl) / (fh - fl);
            if (!(s > lo.s && s < hi.s)) s = 0.5 * (lo.s + hi.s);
            x = f(s);
            if (f.failed) return;
            if (x.side == 0) {
                exact = true;
                break;
            }
            if (x.side == lo.side) {
                lo = x;
                fl = x.ell;
                if (last == -1) fh *= 0.5;
                last = -1;
            } else {
                hi = x;
                fh = x.ell;
                if (last == 1) fl *= 0.5;
                last = 1;
            }
        }
        if (!exact) x = f(0.5 * (lo.s + hi.s));
        if (f.failed) return;
        WindingCrossing c;
        c.s = x.s;
        c.angle = wrap_angle(std::arg(x.g));
        c.direction = direction;
        c.re_rate = -(x.g / x.dg).real();
        crossings.push_back(c);
    }

    void piece(const Sample& a, const Sample& b, int depth) {
        if (--f.budget < 0 || depth > 80) {
            f.fail("the sampling budget was used up (a root on or within rounding of the line)");
            return;
        }
        const Sample m = f(0.5 * (a.s + b.s));
        if (f.failed) return;
        const double h = 0.5 * (b.s - a.s);
        const double e = std::sqrt(std::max({a.dg2, m.dg2, b.dg2})) * h;
        // Gamma resolved as the tracker resolves a phase (where |Gamma| >= 1/2, near the circle)
        constexpr double kEighth = 0.39269908169872414;  // pi / 8
        const double limit = kEighth * kEighth / (h * h);
        auto speed2 = [](const Sample& x) { return x.speed2; };
        auto within_quarter = [](cplx y, cplx x) {
            const cplx w = y * std::conj(x);
            return w.real() > std::abs(w.imag());
        };
        bool resolved = speed2(a) < limit && speed2(m) < limit && speed2(b) < limit && phase_piece_resolved(a.p, m.p, b.p);
        if (resolved && std::min({a.g2, m.g2, b.g2}) >= 0.25)
            resolved = within_quarter(m.g, a.g) && within_quarter(b.g, m.g);
        if (resolved) {
            // l = log|Gamma| on a half piece stays on its side of 0 when the Taylor bounds
            // l(x + t) >= l(x) + t l'(x) - D t^2 from both ends over the two quarters stay there,
            // with D twice the second derivative seen in the differences of the sampled l'
            const double la = ell_rate(a), lm = ell_rate(m), lb = ell_rate(b);
            const double d2 = std::max(std::abs(lm - la), std::abs(lb - lm)) / h;
            const double big_d = 2.0 * d2 + 1e-3 * std::max({std::abs(la), std::abs(lm), std::abs(lb)}) / h;
            auto clear_half = [&](const Sample& x, const Sample& y, double lx, double ly) {
                const double side = x.side, q = 0.5 * h;
                const double fx = side * x.ell, fy = side * y.ell, dx = side * lx, dy = side * ly;
                return std::min(fx, fx + q * dx - big_d * q * q) > 0.0 && std::min(fy, fy - q * dy - big_d * q * q) > 0.0;
            };
            if (on_axis && a.s == 0.0) {
                // the tangency at Gamma(0) = 1: the series' side on the whole first piece; the
                // Taylor bounds on its second half (the first ends at the tangency itself)
                if (m.side != 0 && m.side == b.side && (touch_side == 0 || m.side == touch_side) && clear_half(m, b, lm, lb)) {
                    accept(a, m, b, e);
                    return;
                }
            } else if (a.side != 0 && a.side == m.side && m.side == b.side) {
                if (clear_half(a, m, la, lm) && clear_half(m, b, lm, lb)) {
                    accept(a, m, b, e);
                    return;
                }
            } else if (a.side != 0 && m.side != 0 && b.side != 0 && (a.side != m.side) + (m.side != b.side) == 1) {
                const int direction = b.side > a.side ? 1 : -1;  // -1 inside to +1 outside: outward
                if (sign_of(la) == direction && sign_of(lm) == direction && sign_of(lb) == direction &&
                    std::min({std::abs(la), std::abs(lm), std::abs(lb)}) > 2.0 * h * d2) {
                    if (a.side != m.side) locate(a, m, direction);
                    else locate(m, b, direction);
                    if (f.failed) return;
                    accept(a, m, b, e);
                    return;
                }
            }
        }
        piece(a, m, depth + 1);
        if (f.failed) return;
        piece(m, b, depth + 1);
    }
};

}  // namespace

int RingWindingTable::winding(double phi) const {
    const auto it = std::upper_bound(jumps.begin(), jumps.end(), phi, [](double x, const Jump& j) { return x < j.angle; });
    int w = base;
    for (auto j = jumps.begin(); j != it; ++j) w += j->direction;
    return w;
}

namespace {
RingWindingTable winding_table(const TransferFunction& gamma, double sigma, int budget, const LowFrequency* series);
}  // namespace

RingWindingTable ring_winding_table(const TransferFunction& gamma, double sigma, int budget) {
    return winding_table(gamma, sigma, budget, nullptr);
}

namespace {

/// The table, with the low-frequency series of gamma when the caller has it (else formed here
/// for the axis, where it decides the tangency at s = 0).
RingWindingTable winding_table(const TransferFunction& gamma, double sigma, int budget, const LowFrequency* series) {
    RingWindingTable t;
    t.sigma = sigma;
    const Linearisation& lin = gamma.linearisation();
    const double r = half_disc_radius(sizes_at(lin, sigma), sigma);
    t.radius = r;
    if (!(r > 0.0)) {
        t.message = "no radius closes the contour at sigma = " + std::to_string(sigma);
        return t;
    }
    LineSampler f(gamma, lin, sigma, budget);
    int touch = 0;
    if (sigma == 0.0) {
        const LowFrequency lf = series ? *series : low_frequency_expansion(lin);
        if (lf.decisive_order > 0) touch = lf.attenuates ? -1 : 1;
    }
    Pass pass{f, sigma == 0.0, touch, {}, {}, {}, 0};
    const double tau = lin.max_delay();
    int pieces = 4;
    // (capped in double before the conversion: r tau is not bounded, an int cannot hold it)
    if (tau > 0.0) pieces = std::max(pieces, static_cast<int>(std::min(4096.0, std::ceil(r * tau * 4.0 / M_PI))));
    Sample a = f(0.0);
    if (!f.failed) {
        if (sigma != 0.0 && a.side == 0) f.fail("Gamma(sigma) is on the unit circle to rounding");
        if (a.p.f.imag() != 0.0 || a.p.f.real() == 0.0) {
            // P(sigma) is real for real coefficients; exactly zero means a plant root on the line
            if (a.p.f.real() == 0.0) f.fail("a zero of the plant's P at sigma");
        }
    }
    if (!f.failed) {
        pass.path.reserve(256);
        pass.reach.reserve(256);
        pass.path.push_back(a);
        for (int i = 1; i <= pieces && !f.failed; ++i) {
            const Sample b = f(r * i / pieces);
            if (f.failed) break;
            pass.piece(a, b, 0);
            a = b;
        }
    }
    t.evaluations = f.evaluations;
    if (f.failed) {
        t.message = "winding table at sigma = " + std::to_string(sigma) + ": " + f.why;
        return t;
    }
    // N_P(sigma) = (arc - change along the line) / 2 pi; along the arc arg P follows
    // (lambda - sigma)^2: 2 pi + arg h(top) - arg h(bottom), h = P / (lambda - sigma)^2, and
    // h(bottom) = conj h(top); the line's change is twice the change along [0, r]
    const cplx p_top = pass.path.back().p.f;
    // principal args with the negative real axis on the side ray_crossing gives it (Im <= 0)
    auto ray_arg = [](cplx x) { return x.imag() == 0.0 && x.real() < 0.0 ? -M_PI : std::arg(x); };
    const double p_arg = ray_arg(p_top) - ray_arg(pass.path.front().p.f) + kTwoPi * pass.p_turns;
    const double arc = kTwoPi + 2.0 * std::arg(-p_top);
    const double zp = (arc - 2.0 * p_arg) / kTwoPi;
    const double zpr = std::round(zp);
    if (std::abs(zp - zpr) > 0.05 || zpr < 0) {
        t.message = "winding table: the plant's zero count is not an integer";
        return t;
    }
    t.plant_zeros = static_cast<int>(zpr);
    t.crossings = pass.crossings;
    for (const auto& c : t.crossings) {
        t.jumps.push_back({c.angle, c.s, c.re_rate, c.direction});
        t.jumps.push_back({wrap_angle(-c.angle), -c.s, -c.re_rate, -c.direction});
    }
    std::sort(t.jumps.begin(), t.jumps.end(), [](const auto& x, const auto& y) {
        return x.angle != y.angle ? x.angle < y.angle : x.s < y.s;
    });
    // the anchor: W at the middle of a gap between jump angles (and angle 0), the widest first;
    // every step of the path must keep its reach from the anchor point and its mirror
    std::vector<double> cuts{0.0};
    for (const auto& j : t.jumps) cuts.push_back(j.angle);
    cuts.push_back(kTwoPi);
    std::vector<std::pair<double, double>> gaps;  // (width, middle)
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
        if (cuts[i + 1] > cuts[i]) gaps.push_back({cuts[i + 1] - cuts[i], 0.5 * (cuts[i] + cuts[i + 1])});
    std::sort(gaps.begin(), gaps.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
    bool anchored = false;
    double phi0 = M_PI, w0r = 0.0;
    for (std::size_t k = 0; k < std::min<std::size_t>(gaps.size(), 8) && !anchored; ++k) {
        phi0 = gaps[k].second;
        const cplx p = std::polar(1.0, phi0), pc = std::conj(p);
        // W about p of the closed curve C (s from -r to r, then the chord): the path [0, r] about
        // p and about its mirror pc (Gamma(-s) = conj Gamma(s)), counted by crossings of the rays
        // from p and pc away from the origin. A step counts as its chord when the curve between
        // its samples stays within its reach e of them and e is smaller than their distance to p
        // and pc (then curve and chord wind alike); a step too close is sampled finer.
        int crossings = 0;
        bool clear = true;
        auto far = [&](cplx g, double e) { return std::norm(g - p) > e * e && std::norm(g - pc) > e * e; };  // |g - p| > e
        auto count = [&](cplx g0, cplx g1) {
            // the mirror half (s from -r to 0) runs through the conjugate samples in reverse order
            crossings += ray_crossing(g0, g1, p, p) - ray_crossing(std::conj(g0), std::conj(g1), p, p);
        };
        std::function<void(const Sample&, const Sample&, int)> finer = [&](const Sample& x, const Sample& y, int depth) {
            if (!clear) return;
            if (--f.budget < 0 || depth > 40) {
                clear = false;
                return;
            }
            const Sample z = f(0.5 * (x.s + y.s));
            if (f.failed) {
                clear = false;
                return;
            }
            const double e = 0.5 * (y.s - x.s) * std::sqrt(std::max({x.dg2, z.dg2, y.dg2}));
            if (far(x.g, e) && far(z.g, e) && far(y.g, e)) {
                count(x.g, z.g);
                count(z.g, y.g);
                return;
            }
            finer(x, z, depth + 1);
            finer(z, y, depth + 1);
        };
        for (std::size_t j = 0; j + 1 < pass.path.size() && clear; ++j) {
            const Sample &x = pass.path[j], &y = pass.path[j + 1];
            if (far(x.g, pass.reach[j]) && far(y.g, pass.reach[j])) count(x.g, y.g);
            else finer(x, y, 0);
        }
        if (!clear) continue;
        w0r = crossings;  // the closing chord lies in the unit disc and meets no ray
        anchored = true;
    }
    t.evaluations = f.evaluations;
    if (!anchored) {
        t.message = "winding table: no anchor angle away from the image curve";
        return t;
    }
    int below = 0;
    for (const auto& j : t.jumps)
        if (j.angle <= phi0) below += j.direction;
    t.base = static_cast<int>(w0r) - below;
    t.ok = true;
    return t;
}

}  // namespace

void RingWindingOptions::validate() const {
    if (budget < 100) throw std::invalid_argument("budget = " + std::to_string(budget) + ": expected >= 100");
}

bool ring_winding_applies(const Linearisation& lin) { return lin.further.empty(); }

namespace {

/// The marginal window of a crossing: modes within band / |re_rate| of its angle have a root
/// within the marginal band of the axis (Re ~ (phi - angle) re_rate).
double marginal_window(const RingWindingTable::Jump& j) {
    const double band = marginal_band(cplx(0.0, j.s));
    return j.re_rate != 0.0 ? band / std::abs(j.re_rate) : kTwoPi;
}

/// phi_m = 2 pi m / N, the one formula of this file
double mode_angle(long long m, int cars) { return kTwoPi * static_cast<double>(m) / cars; }

/// #{m in [1, N-1] : phi_m < alpha}
long long modes_below(double alpha, int cars) {
    if (alpha <= 0.0) return 0;
    long long k = static_cast<long long>(std::floor(alpha * cars / kTwoPi));
    k = std::max(0LL, std::min<long long>(k, cars - 1));
    while (k + 1 <= cars - 1 && mode_angle(k + 1, cars) < alpha) ++k;
    while (k >= 1 && !(mode_angle(k, cars) < alpha)) --k;
    return k;
}

/// An interval of angles between consecutive jump angles, with Z on it.
struct Interval {
    double lo, hi;
    int zeros;
    std::size_t left, right;  // jump indices bounding it (npos at 0 and 2 pi)
};

std::vector<Interval> intervals(const RingWindingTable& t) {
    std::vector<Interval> out;
    const std::size_t npos = static_cast<std::size_t>(-1);
    double lo = 0.0;
    std::size_t left = npos;
    int w = t.base;
    for (std::size_t i = 0; i <= t.jumps.size(); ++i) {
        const double hi = i < t.jumps.size() ? t.jumps[i].angle : kTwoPi;
        if (hi > lo) out.push_back({lo, hi, t.plant_zeros - w, left, i < t.jumps.size() ? i : npos});
        if (i < t.jumps.size()) {
            w += t.jumps[i].direction;
            lo = hi;
            left = i;
        }
    }
    return out;
}

struct Totals {
    long long zeros = 0;  // sum of Z over the modes m = 1..N-1
    bool negative = false;
};

Totals mode_totals(const RingWindingTable& t, int cars) {
    Totals out;
    for (const auto& iv : intervals(t)) {
        const long long n = modes_below(iv.hi, cars) - modes_below(iv.lo, cars);
        if (n <= 0) continue;
        if (iv.zeros < 0) out.negative = true;
        out.zeros += n * iv.zeros;
    }
    return out;
}

}  // namespace

long long RingWindingTable::mode_zeros(int cars) const {
    if (cars < 2) throw std::invalid_argument("mode_zeros: expected cars >= 2");
    const Totals t = mode_totals(*this, cars);
    return t.negative ? -1 : t.zeros;
}

namespace {

/// Newton on f_m = P - zeta_m Q from z (in place).
bool mode_newton(const TransferFunction& tf, cplx zeta, cplx& z) {
    NewtonOptions o;
    o.max_iterations = 60;
    const NewtonSummary s = newton(
        z,
        [&](const cplx& x, cplx& dx) {
            cplx n, d, dn, dd;
            tf.evaluate(x, n, d, dn, dd);
            const cplx f = d - zeta * n, fp = dd - zeta * dn;
            if (f == cplx(0.0)) return NewtonStep::Exact;
            if (fp == cplx(0.0)) return NewtonStep::Singular;
            dx = f / fp;
            return NewtonStep::Ok;
        },
        o);
    return s.status == Status::Converged;
}

/// N, D and their first and second derivatives at z (one exponential per term):
/// N = gap + z lead, N' = gap' + lead + z lead', N'' = gap'' + 2 lead' + z lead'',
/// D = z^2 - z own + gap, D' = 2 z - own - z own' + gap', D'' = 2 - 2 own' - z own'' + gap''.
struct Derivatives2 {
    cplx n, d, dn, dd, ddn, ddd;
};
Derivatives2 derivatives2(const Linearisation& lin, cplx z) {
    // e(z) = sum c e^{-z d}, e' = -sum d c e^{-z d}, e'' = sum d^2 c e^{-z d}
    auto ev = [&](const ExpPoly& p, cplx out[3]) {
        out[0] = out[1] = out[2] = 0.0;
        for (const auto& t : p.terms()) {
            const cplx e = t.delay == 0.0 ? cplx(t.coef) : t.coef * std::exp(-z * t.delay);
            out[0] += e;
            out[1] -= t.delay * e;
            out[2] += t.delay * t.delay * e;
        }
    };
    cplx g[3], o[3], l[3];
    ev(lin.gap, g);
    ev(lin.own, o);
    ev(lin.lead, l);
    Derivatives2 r;
    r.n = g[0] + z * l[0];
    r.dn = g[1] + l[0] + z * l[1];
    r.ddn = g[2] + 2.0 * l[1] + z * l[2];
    r.d = z * z - z * o[0] + g[0];
    r.dd = 2.0 * z - o[0] - z * o[1] + g[1];
    r.ddd = 2.0 - 2.0 * o[1] - z * o[2] + g[2];
    return r;
}

/// The maximum of Re lambda on the level curve |Gamma(lambda)| = 1: Newton on
/// log|Gamma| = 0, Im Phi'(lambda) = 0 (the gradient of log|Gamma| is horizontal there).
/// The Jacobian uses Phi'' = N''/N - (N'/N)^2 - D''/D + (D'/D)^2 (one evaluation per step).
bool level_maximum(const TransferFunction& tf, cplx& z) {
    const Linearisation& lin = tf.linearisation();
    for (int it = 0; it < 40; ++it) {
        const Derivatives2 v = derivatives2(lin, z);
        if (v.n == cplx(0.0) || v.d == cplx(0.0)) return false;
        const double f1 = 0.5 * std::log(std::norm(v.n) / std::norm(v.d));
        const cplx qn = v.dn / v.n, qd = v.dd / v.d;
        const cplx r1 = qn - qd;
        const double f2 = r1.imag();
        const cplx r2 = v.ddn / v.n - qn * qn - v.ddd / v.d + qd * qd;
        // d f1/dx = Re Phi', d f1/dy = -Im Phi'; d f2/dx = Im Phi'', d f2/dy = Re Phi''
        const double a11 = r1.real(), a12 = -r1.imag(), a21 = r2.imag(), a22 = r2.real();
        const double det = a11 * a22 - a12 * a21;
        if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
        const double dx = (f1 * a22 - a12 * f2) / det, dy = (a11 * f2 - a21 * f1) / det;
        z -= cplx(dx, dy);
        if (!std::isfinite(z.real()) || !std::isfinite(z.imag())) return false;
        if (std::hypot(dx, dy) <= 1e-14 * std::max(1.0, std::abs(z))) return true;
    }
    return false;
}

struct Engine {
    const Linearisation& lin;
    int cars;
    const RingWindingOptions& options;
    TransferFunction tf;
    RingWindingResult& r;
    const QuasiPolynomial& f0;  // mode 0 without its trivial root
    const LowFrequency& series; // the low-frequency series of tf

    RingWindingTable table(double sigma) {
        RingWindingTable t = winding_table(tf, sigma, options.budget, &series);
        ++r.tables;
        r.evaluations += t.evaluations;
        return t;
    }
    /// Zeros of mode 0 without its trivial root right of t's line: Z(0) of the table less the
    /// trivial root when the line is left of 0 (f_0 = P - Q = lambda (lambda - own - lead)); on the
    /// axis itself, where the trivial root lies, by f0's own count.
    int mode0_count(const RingWindingTable& t, bool& bad) const {
        if (t.sigma == 0.0) {
            const int c = f0.zeros_right_of(0.0);
            if (c < 0) bad = true;
            return std::max(c, 0);
        }
        for (const auto& j : t.jumps)
            if (j.angle == 0.0) {  // a root of mode 0 on the line
                bad = true;
                return 0;
            }
        const int c = t.zeros(0.0) - (t.sigma < 0.0 ? 1 : 0);
        if (c < 0) bad = true;
        return std::max(c, 0);
    }
    /// Finite N: the zeros right of t's line over all modes (mode 0 without its trivial root);
    /// N = inf: the largest count over wave numbers.
    long long right_count(const RingWindingTable& t, bool& bad) const {
        if (cars > 0) {
            const Totals tot = mode_totals(t, cars);
            bad = bad || tot.negative;
            return tot.zeros + mode0_count(t, bad);
        }
        long long most = 0;
        for (const auto& iv : intervals(t)) {
            if (iv.zeros < 0) bad = true;
            most = std::max<long long>(most, iv.zeros);
        }
        return most;
    }
    /// A guess for a root right of t's line: an interval with Z > 0 (holding a mode for finite
    /// N), the mode nearest its middle and the Im interpolated between its crossings; mode 0 last.
    bool guess_from(const RingWindingTable& t, cplx& z, double& phi, long long& mode) const {
        for (const auto& iv : intervals(t)) {
            if (iv.zeros <= 0) continue;
            double mid = 0.5 * (iv.lo + iv.hi);
            mode = -1;
            if (cars > 0) {
                const long long a = modes_below(iv.lo, cars), b = modes_below(iv.hi, cars);
                if (b - a <= 0) continue;
                long long m = static_cast<long long>(std::llround(mid * cars / kTwoPi));
                mode = std::max(a + 1, std::min(b, m));
                mid = mode_angle(mode, cars);
            }
            const double s0 = iv.left < t.jumps.size() ? t.jumps[iv.left].s : 0.0;
            const double s1 = iv.right < t.jumps.size() ? t.jumps[iv.right].s : 0.0;
            const double w = (iv.hi > iv.lo) ? (mid - iv.lo) / (iv.hi - iv.lo) : 0.5;
            z = cplx(t.sigma, s0 + w * (s1 - s0));
            phi = mid;
            return true;
        }
        bool bad = false;
        if (cars > 0 && mode0_count(t, bad) > 0) {
            z = cplx(t.sigma, 0.0);
            phi = 0.0;
            mode = 0;
            return true;
        }
        return false;
    }
};

}  // namespace

RingWindingResult analyse_ring_winding(const Linearisation& lin, int cars, const RingWindingOptions& options,
                                       const RingWindingGuess& guess) {
    options.validate();
    if (cars != 0 && cars < 2) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected N >= 2 or inf");
    require_single_leader(lin, "the winding count of a ring");
    RingWindingResult r;
    r.cars = cars;
    const QuasiPolynomial f0 = ring_mode0_characteristic(lin);
    const LowFrequency lf = low_frequency_expansion(lin);
    Engine en{lin, cars, options, TransferFunction(lin), r, f0, lf};
    double margin = 0.0;
    switch (lf.decisive_order) {
        case 2: margin = lf.c2; break;
        case 4: margin = lf.c4; break;
        case 6: margin = lf.c6; break;
        case 8: margin = lf.c8; break;
        default: margin = 0.0;
    }
    const bool series = lf.decisive_order > 0 && lf.gamma_prime0 != 0.0 && lf.d0 != 0.0;
    auto undecided = [&](const std::string& why) {
        r.status = Status::NumericalIssue;
        r.verdict = Verdict::Undecided;
        r.message = why;
        r.certified = false;
        return r;
    };
    if (!series) return undecided("the low-frequency series does not decide the branch through the trivial root");
    bool bad = false;
    const char* negative = "winding table: a negative zero count";

    std::optional<RingWindingTable> axis;  // the table on the imaginary axis (the verdict's)

    // ---- candidates for the rightmost root: Newton from the previous point ----
    struct Best {
        bool have = false;
        cplx z;
        long long mode = 0;
        double phi = 0.0;
    } best;
    cplx z0;
    bool have0 = false;
    auto consider = [&](cplx z, long long m, double phi) {
        if (!best.have || z.real() > best.z.real()) best = {true, z, m, phi};
    };
    auto try_mode = [&](long long m, cplx z) {
        if (cars == 0) return;
        m = ((m % cars) + cars) % cars;
        if (m == 0) {
            if (!f0.newton(z)) return;
            if (z.imag() < 0.0) z = std::conj(z);
            if (!have0 || z.real() > z0.real()) z0 = z;
            have0 = true;
            consider(z, 0, 0.0);
            return;
        }
        if (mode_newton(en.tf, ring_zeta(static_cast<int>(m), cars), z)) consider(z, m, mode_angle(m, cars));
    };
    const bool few = cars > 0 && cars <= 64;  // few modes: the neighbours of the last mode; many: the level curve
    auto try_optimum = [&](cplx z) {
        if (!level_maximum(en.tf, z)) return;
        if (z.imag() < 0.0) z = std::conj(z);
        r.next.optimum = z;
        r.next.have_optimum = true;
        const double phi = wrap_angle(std::arg(en.tf(z)));
        if (cars == 0) {
            consider(z, -1, phi);
            return;
        }
        const long long m = static_cast<long long>(std::floor(phi * cars / kTwoPi));
        try_mode(m, z);
        try_mode(m + 1, z);
    };

    bool nothing_unstable_inf = false;
    if (cars == 0) {
        // the sup over theta is 0 unless something is unstable: decide that first
        axis = en.table(0.0);
        if (!axis->ok) return undecided(axis->message);
        nothing_unstable_inf = en.right_count(*axis, bad) == 0;
        if (bad) return undecided(negative);
    }
    if (nothing_unstable_inf) {
        r.spectral_abscissa = 0.0;
        r.abscissa_is_limit = true;
        r.abscissa_mode = -1;
        r.abscissa_theta = 0.0;
        r.certified = true;
        if (guess.have_optimum) {
            r.next.optimum = guess.optimum;
            r.next.have_optimum = true;
        }
    } else {
        if (cars > 0) try_mode(0, guess.have_mode0 ? guess.mode0 : cplx(0.0));
        if (guess.have && cars > 0 && guess.mode > 0 && guess.mode < cars) {
            try_mode(guess.mode, guess.root);
            if (few) {
                try_mode(guess.mode - 1, guess.root);
                try_mode(guess.mode + 1, guess.root);
            }
        }
        if (guess.have_optimum && !few) try_optimum(guess.optimum);

        // certificate: no root of any mode right of the candidate plus the gap
        bool done = false;
        double lo = -std::numeric_limits<double>::infinity();
        std::optional<RingWindingTable> lo_table;
        // Few modes and a candidate clearly right of the axis: the axis table (which the verdict
        // needs anyway) counts every mode's roots right of the axis; when Newton finds as many
        // distinct roots right of the axis in every mode, they are all of them, and the rightmost
        // is the abscissa without the table on the certificate line.
        if (few && best.have && best.z.real() > kAccountedClear * std::max(1.0, std::abs(best.z))) {
            axis = en.table(0.0);
            if (!axis->ok) return undecided(axis->message);
            const RingWindingTable& t = *axis;
            const double branch_sign = margin / lf.gamma_prime0;
            bool ok = true;
            for (const auto& j : t.jumps)
                if (marginal_window(j) >= std::min(j.angle, kTwoPi - j.angle)) ok = false;  // a root near mode 0's axis point
            Best all;
            auto clear = [&](cplx z) { return z.real() > kAccountedClear * std::max(1.0, std::abs(z)); };
            // mode 0 (without its trivial root): Z(0+) less the trivial branch when it bends right
            if (ok) {
                const int c0 = t.plant_zeros - t.base - (branch_sign > 0.0 ? 1 : 0);
                const bool pair = have0 && std::abs(z0.imag()) > 1e-8 * std::max(1.0, std::abs(z0));
                if (c0 < 0 || c0 > 2) ok = false;
                else if (c0 > 0 && !(have0 && clear(z0) && c0 == (pair ? 2 : 1))) ok = false;
                else if (c0 > 0) all = {true, z0, 0, 0.0};
            }
            for (long long m = 1; ok && 2 * m <= cars; ++m) {
                const double phi = mode_angle(m, cars);
                for (const auto& j : t.jumps)
                    if (std::abs(phi - j.angle) <= marginal_window(j)) ok = false;  // a root within the band
                if (!ok) break;
                const int zm = t.zeros(phi);
                if (zm < 0) {
                    ok = false;
                    break;
                }
                if (zm == 0) continue;
                // seeds: the continued candidate, then the crossings whose branches move right
                // towards phi (Re ~ (phi - angle) re_rate) and the branch through the trivial root,
                // nearest first
                std::vector<std::pair<double, cplx>> seeds;
                if (best.mode == m || best.mode == cars - m) seeds.push_back({-1.0, best.mode == m ? best.z : std::conj(best.z)});
                for (const auto& j : t.jumps) {
                    double d = phi - j.angle;
                    if (d > M_PI) d -= kTwoPi;
                    if (d < -M_PI) d += kTwoPi;
                    if (d * j.re_rate > 0.0) seeds.push_back({std::abs(d), cplx(d * j.re_rate, j.s)});
                }
                // the branch through the trivial root when it bends right: Gamma(i w) ~ e^{i Gamma'(0) w}
                if (branch_sign > 0.0) seeds.push_back({phi, cplx(0.0, phi / lf.gamma_prime0)});
                std::sort(seeds.begin(), seeds.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
                std::vector<cplx> found;
                for (std::size_t k = 0; k < seeds.size() && k < static_cast<std::size_t>(zm) + 3 && static_cast<int>(found.size()) < zm; ++k) {
                    cplx z = seeds[k].second;
                    if (!mode_newton(en.tf, ring_zeta(static_cast<int>(m), cars), z) || !clear(z)) continue;
                    bool fresh = true;
                    for (const cplx& y : found) fresh = fresh && std::abs(z - y) > 1e-6 * std::max(1.0, std::abs(z));
                    // a real mode (2 m = N) has its roots in conjugate pairs: a complex root accounts for two
                    if (fresh) {
                        found.push_back(z);
                        if (2 * m == cars && std::abs(z.imag()) > 1e-8 * std::max(1.0, std::abs(z))) found.push_back(std::conj(z));
                    }
                }
                if (static_cast<int>(found.size()) != zm) {
                    ok = false;
                    break;
                }
                for (const cplx& z : found)
                    if (!all.have || z.real() > all.z.real()) all = {true, z, m, phi};
            }
            if (ok && all.have) {
                best = all;
                done = true;
                r.accounted = true;
            }
        }
        if (!done && best.have) {
            const RingWindingTable t = en.table(best.z.real() + certificate_gap(best.z));
            if (!t.ok) return undecided(t.message);
            const long long c = en.right_count(t, bad);
            if (bad) return undecided(negative);
            if (c == 0) {
                done = true;
            } else {
                lo = t.sigma;
                lo_table = t;
                best = Best{};
            }
        }
        if (!done) {
            // bracket the abscissa by counts: roots right of lo, none right of hi
            r.bisected = true;
            if (!lo_table) {
                double s = 0.0;
                for (int k = 0; k < 60 && !lo_table; ++k) {
                    if (s == 0.0 && !axis) axis = en.table(0.0);
                    const RingWindingTable t = s == 0.0 ? *axis : en.table(s);
                    if (!t.ok) return undecided(t.message);
                    if (en.right_count(t, bad) > 0) {
                        lo = s;
                        lo_table = t;
                    }
                    s = s == 0.0 ? -0.125 : 2.0 * s;
                }
                if (!lo_table) return undecided("no line with roots right of it was found");
            }
            double hi = lo + std::max(1.0, std::abs(lo));
            for (int k = 0;; ++k) {
                const RingWindingTable t = en.table(hi);
                if (!t.ok) return undecided(t.message);
                if (en.right_count(t, bad) == 0) break;
                lo = hi;
                lo_table = t;
                hi = lo + 2.0 * std::max(1.0, std::abs(lo));
                if (k > 60) return undecided("no line without roots right of it was found");
            }
            if (bad) return undecided(negative);
            double s_guess = 0.0;
            int attempts = 0;
            for (int k = 0; k < 200 && !done; ++k) {
                const double scale = std::max({1.0, std::abs(lo), std::abs(s_guess)});
                const double width = hi - lo;
                if ((attempts == 0 && width <= 1e-4 * scale) || (attempts == 1 && width <= 1e-8 * scale)) {
                    // close enough for Newton from the crossings of the line lo
                    ++attempts;
                    cplx z;
                    double phi = 0.0;
                    long long m = -1;
                    if (en.guess_from(*lo_table, z, phi, m)) {
                        z = cplx(0.5 * (lo + hi), z.imag());
                        if (cars > 0) try_mode(m, z);
                        if (m != 0) try_optimum(z);
                    }
                    if (best.have && best.z.real() >= lo) {
                        const RingWindingTable t = en.table(best.z.real() + certificate_gap(best.z));
                        if (!t.ok) return undecided(t.message);
                        if (en.right_count(t, bad) == 0) {
                            done = true;
                            break;
                        }
                    }
                    best = Best{};  // not it: bisect on
                }
                if (width <= 1e-10 * scale) break;
                const double mid = 0.5 * (lo + hi);
                const RingWindingTable t = en.table(mid);
                if (!t.ok) return undecided(t.message);
                if (en.right_count(t, bad) > 0) {
                    lo = mid;
                    lo_table = t;
                } else {
                    hi = mid;
                }
                if (bad) return undecided(negative);
                cplx zg;
                double pg = 0.0;
                long long mg = -1;
                if (en.guess_from(*lo_table, zg, pg, mg)) s_guess = zg.imag();
            }
            if (!done) {
                // the bracket itself is the certificate
                cplx z;
                double phi = 0.0;
                long long m = -1;
                if (!en.guess_from(*lo_table, z, phi, m)) return undecided("the bracket holds no mode");
                best = {true, cplx(hi, z.imag()), cars > 0 ? m : -1, phi};
            }
        }
        r.certified = true;
        cplx z = best.z;
        long long m = best.mode;
        if (cars > 0 && 2 * m > cars) {
            m = cars - m;
            z = std::conj(z);
        }
        if (z.imag() < 0.0 && (cars == 0 || m == 0 || 2 * m == cars)) z = std::conj(z);
        r.spectral_abscissa = z.real();
        r.abscissa_root = z;
        r.abscissa_mode = cars > 0 ? static_cast<int>(m) : -1;
        r.abscissa_theta = cars > 0 ? mode_angle(m, cars) : std::min(best.phi, kTwoPi - best.phi);
        if (cars == 0 || best.mode != 0) {
            r.next.have = true;
            r.next.root = best.z;
            r.next.mode = static_cast<int>(std::max(best.mode, 0LL));
        }
        if (have0) {
            r.next.mode0 = z0;
            r.next.have_mode0 = true;
        }
    }

    // ---- the verdict ----
    // Every root of every mode lies left of the certified line Re = abscissa + gap. When that
    // line is left of -1e-12 max(1, r(0)) no root can be within the marginal band of the axis
    // (such a root would have |lambda| >= 1e12 times its distance, beyond the root bound r).
    const double r0 = half_disc_radius(sizes_at(lin, 0.0), 0.0);
    const double line = r.spectral_abscissa + certificate_gap(r.abscissa_root);
    if (cars > 0 && line < -1e-12 * std::max(1.0, r0)) {
        r.unstable_roots = 0;
        r.marginal_roots = 0;
        r.status = Status::Converged;
        r.verdict = Verdict::Stable;
        return r;
    }
    if (!axis) axis = en.table(0.0);
    const RingWindingTable& t = *axis;
    if (!t.ok) return undecided(t.message);
    bool marginal = false;
    long long unstable = 0;
    // roots of mode phi near a crossing k: Re ~ (phi - angle_k) re_rate_k
    auto window = [&](const RingWindingTable::Jump& j) { return marginal_window(j); };
    // the branch through the trivial root: Re lambda(theta) ~ margin w^k / (2 d0^2 Gamma'(0)),
    // w = theta / |Gamma'(0)|
    const double branch_sign = margin / lf.gamma_prime0;  // > 0: the branch is unstable
    const double theta_band =
        std::abs(lf.gamma_prime0) *
        std::pow(1e-13 * 2.0 * lf.d0 * lf.d0 * std::abs(lf.gamma_prime0) / std::abs(margin), 1.0 / lf.decisive_order);
    bool near_zero_angle = false;  // a crossing whose window reaches theta = 0: a root of mode 0 near the axis
    for (const auto& j : t.jumps)
        if (window(j) >= std::min(j.angle, kTwoPi - j.angle)) near_zero_angle = true;
    if (cars > 0) {
        const Totals tot = mode_totals(t, cars);
        if (tot.negative) return undecided(negative);
        unstable = tot.zeros;
        for (const auto& j : t.jumps) {
            const double w = window(j);
            const long long a = modes_below(j.angle - w, cars), b = modes_below(std::nextafter(j.angle + w, 10.0), cars);
            // modes a+1..b lie within the window: those on the side where the table counts them right
            // of the axis are within the band (counted in O(1): a huge ring holds many there)
            if (b > a) {
                marginal = true;
                const long long below = std::max(0LL, std::min(b, modes_below(j.angle, cars)) - a);  // angle < j.angle
                unstable -= j.re_rate > 0.0 ? (b - a) - below : below;
            }
        }
        // the smallest wave numbers on the trivial branch, within the band
        const long long nb = std::min<long long>(modes_below(std::nextafter(theta_band, 10.0), cars), cars / 2);
        if (nb > 0) {
            marginal = true;
            if (branch_sign > 0.0) unstable -= 2 * nb - (2 * nb > cars - 1 ? 1 : 0);
        }
        // mode 0: Z(0+) less the trivial branch when it bends right; next to a crossing at
        // angle 0, as the per-mode path counts it (band edges)
        if (near_zero_angle) {
            const double band0 = marginal_band(have0 ? z0 : cplx(0.0));
            const int above = f0.zeros_right_of(band0);
            if (above < 0) return undecided("mode 0: a root within rounding of the band's edge");
            if (above == 0 && f0.zeros_right_of(-band0) > 0) marginal = true;
            unstable += above;
        } else {
            const int c0 = t.plant_zeros - t.base - (branch_sign > 0.0 ? 1 : 0);
            if (c0 < 0) return undecided(negative);
            unstable += c0;
        }
        if (unstable < 0) return undecided("winding table: inconsistent marginal counts");
        // The count finds roots right of the axis but the located rightmost root lies left of
        // it: both certificates hold only if those roots are within the abscissa's gap of the
        // axis, so the rightmost root is not resolved and no verdict is given.
        if (unstable > 0 && r.spectral_abscissa <= 0.0)
            return undecided("the count finds " + std::to_string(unstable) +
                             " roots right of the axis, but the rightmost root located is at Re = " +
                             detail::format_number(r.spectral_abscissa) + ", left of it (certificate line Re = " +
                             detail::format_number(line) + "): the rightmost root is not resolved");
        r.unstable_roots = unstable;
        r.marginal_roots = marginal ? 1 : 0;
    } else {
        // N = inf: unstable when an interval of wave numbers wider than the windows at its ends
        // holds roots right of the axis, or the trivial branch bends right
        for (const auto& iv : intervals(t)) {
            if (iv.zeros <= 0) continue;
            const double wl = iv.left < t.jumps.size() ? window(t.jumps[iv.left]) : 0.0;
            const double wr = iv.right < t.jumps.size() ? window(t.jumps[iv.right]) : 0.0;
            if (iv.hi - iv.lo > wl + wr) ++unstable;
            else marginal = true;
        }
        if (near_zero_angle) marginal = true;
        if (branch_sign > 0.0) ++unstable;
        r.unstable_roots = -1;
        r.marginal_roots = marginal ? 1 : 0;
    }
    r.status = Status::Converged;
    r.verdict = verdict_of(r.status, unstable > 0 ? 1 : 0, marginal ? 1 : 0);
    if (cars == 0 && r.verdict != Verdict::Unstable) {
        r.spectral_abscissa = 0.0;
        r.abscissa_is_limit = r.verdict == Verdict::Stable;
    }
    return r;
}

}  // namespace ddemap
