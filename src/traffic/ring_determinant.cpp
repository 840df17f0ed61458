#include "ddemap/traffic/ring_determinant.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ddemap/core/execution.hpp"
#include "ddemap/traffic/fleet.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/core/text.hpp"

namespace ddemap {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
/// From this many car types on, a contour step evaluates the types on all threads.
constexpr std::size_t kParallelTypes = 256;
/// types per block of the parallel reduction (fixed, so sums do not depend on the thread count)
constexpr long kTypeBlock = 64;

bool same(const ExpPoly& a, const ExpPoly& b) {
    const auto &ta = a.terms(), &tb = b.terms();
    if (ta.size() != tb.size()) return false;
    for (std::size_t j = 0; j < ta.size(); ++j)
        if (ta[j].coef != tb[j].coef || ta[j].delay != tb[j].delay) return false;
    return true;
}

bool same(const Linearisation& a, const Linearisation& b) {
    return same(a.gap, b.gap) && same(a.own, b.own) && same(a.lead, b.lead) && a.further.empty() && b.further.empty();
}


double scale_of(cplx z) { return std::max(1.0, std::abs(z)); }

bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }

}  // namespace

RingDeterminant::RingDeterminant(const std::vector<Linearisation>& cars) {
    if (cars.size() < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars.size()));
    for (const auto& c : cars) {
        require_single_leader(c, "the ring determinant prod P_i - prod Q_i");
        auto it = std::find_if(m_types.begin(), m_types.end(), [&](const Type& t) { return same(t.gamma.linearisation(), c); });
        if (it == m_types.end())
            m_types.push_back({TransferFunction(c), 1.0});
        else
            it->n += 1.0;
    }
}

void RingDeterminant::factors(const Type& t, cplx z, cplx& p, cplx& q, cplx* dp, cplx* dq) const {
    // Gamma = Q / P: the transfer function's numerator and denominator (one exponential per delay)
    if (dp)
        t.gamma.evaluate(z, q, p, *dq, *dp);
    else
        t.gamma.evaluate(z, q, p);
}

cplx RingDeterminant::phi(cplx z) const {
    cplx s = 0.0, p, q;
    for (const auto& t : m_types) {
        factors(t, z, p, q, nullptr, nullptr);
        s += t.n * std::log(q / p);
    }
    return s;
}

cplx RingDeterminant::log_value(cplx z) const {
    cplx sp = 0.0, sq = 0.0, ph = 0.0, p, q;
    for (const auto& t : m_types) {
        factors(t, z, p, q, nullptr, nullptr);
        sp += t.n * std::log(p);
        sq += t.n * std::log(q);
        ph += t.n * std::log(q / p);
    }
    if (ph.real() <= 0.0) return sp + std::log(1.0 - std::exp(ph));
    return cplx(0.0, kTwoPi / 2.0) + sq + std::log(1.0 - std::exp(-ph));
}

cplx RingDeterminant::log_derivative(cplx z) const {
    cplx dp = 0.0, dq = 0.0, ph = 0.0, p, q, pd, qd;
    for (const auto& t : m_types) {
        factors(t, z, p, q, &pd, &qd);
        dp += t.n * pd / p;
        dq += t.n * qd / q;
        ph += t.n * std::log(q / p);
    }
    const cplx dphi = dq - dp;
    if (ph.real() <= 0.0) {
        const cplx e = std::exp(ph);
        return dp - dphi * e / (1.0 - e);
    }
    const cplx e = std::exp(-ph);
    return dq + dphi * e / (1.0 - e);
}

bool RingDeterminant::follow(cplx a, cplx b, double theta, double& total, long& evaluations) const {
    const double length = std::abs(b - a);
    if (!std::isfinite(length)) return false;
    if (length == 0.0) return true;
    const double tiny = 1e-14 * (std::abs(a) + std::abs(b) + 1.0);
    const std::size_t nt = m_types.size();
    const int threads = thread_count();
    // At each point: P_t and Gamma_t per type, Phi (principal logs at the start of the segment,
    // then continued by the increments: e^Phi is exact either way) and the local turning rates
    // max_t(|P_t'/P_t|, |Gamma_t'/Gamma_t|) and Phi', which cap the next step (the end-point
    // checks alone could alias a step over a whole turn).
    std::vector<cplx> cp(nt), cr(nt), np(nt), nr(nt);
    struct Rates {
        double factor = 0.0;  ///< max over the types of |P'/P| and |Gamma'/Gamma|
        cplx phi = 0.0;       ///< Phi'
    };
    auto one = [&](std::size_t k, cplx z, cplx& pk, cplx& rk, Rates& rates) {
        cplx qk, dpk, dqk;
        factors(m_types[k], z, pk, qk, &dpk, &dqk);
        if (pk == 0.0 || qk == 0.0 || !finite(pk) || !finite(qk)) return false;
        rk = qk / pk;
        const cplx lp = dpk / pk, lg = dqk / qk - lp;
        rates.factor = std::max({rates.factor, std::abs(lp), std::abs(lg)});
        rates.phi += m_types[k].n * lg;
        return finite(lp) && finite(lg);
    };
    cplx cphi = 0.0;
    Rates cur;
    for (std::size_t k = 0; k < nt; ++k) {
        if (!one(k, a, cp[k], cr[k], cur)) return false;
        cphi += m_types[k].n * std::log(cr[k]);
    }
    ++evaluations;
    // the largest step the rates at the current point allow
    auto cap = [&](const Rates& r, cplx phi) {
        double h = length / 8.0;
        if (r.factor > 0.0) h = std::min(h, theta / r.factor);
        const double re = std::abs(phi.real());
        const double dphi = std::abs(r.phi);
        if (dphi > 0.0) {
            h = std::min(h, std::max(theta, 0.5 * re) / dphi);
            // arg(1 - e^{+-Phi}) turns at |Phi'| |e^{-|Re Phi|}| / |1 - e^{+-Phi}|
            const cplx e = std::exp(phi.real() <= 0.0 ? phi : -phi);
            const double g = dphi * std::abs(e) / std::abs(1.0 - e);
            if (g > 0.0 && std::isfinite(g)) h = std::min(h, theta / g);
        }
        return h;
    };
    double t = 0.0, h = cap(cur, cphi);
    while (t < length) {
        h = std::min(h, length - t);
        const double tn = (length - t - h <= tiny) ? length : t + h;
        const cplx z = a + (b - a) * (tn / length);
        ++evaluations;
        // every factor's argument moves by at most theta (types spread over the threads when many)
        bool ok = true;
        Rates next;
        if (nt >= kParallelTypes && threads > 1) {
            // fixed blocks of types, combined in block order: the same sums for any thread count
            struct Part {
                bool bad = false;
                Rates rates;
            };
            const Part all = parallel_reduce(
                static_cast<long>(nt), kTypeBlock, Part{},
                [&](long begin, long end) {
                    Part part;
                    for (long k = begin; k < end; ++k)
                        if (!one(static_cast<std::size_t>(k), z, np[k], nr[k], part.rates)) part.bad = true;
                    return part;
                },
                [](Part acc, const Part& p) {
                    acc.bad = acc.bad || p.bad;
                    acc.rates.factor = std::max(acc.rates.factor, p.rates.factor);
                    acc.rates.phi += p.rates.phi;
                    return acc;
                });
            ok = !all.bad;
            next = all.rates;
        } else
        {
            // serially, a type that turns too far rejects the step at once
            for (std::size_t k = 0; k < nt && ok; ++k)
                ok = one(k, z, np[k], nr[k], next) && std::abs(std::arg(np[k] * std::conj(cp[k]))) <= theta &&
                     std::abs(std::arg(nr[k] / cr[k])) <= theta;
        }
        bool accept = ok;
        double darg = 0.0;
        cplx dphi = 0.0;
        for (std::size_t k = 0; k < nt && accept; ++k) {
            const double dp = std::arg(np[k] * std::conj(cp[k]));
            const cplx dr = std::log(nr[k] / cr[k]);
            if (!(std::abs(dp) <= theta && std::abs(dr.imag()) <= theta)) accept = false;
            darg += m_types[k].n * dp;
            dphi += m_types[k].n * dr;
        }
        const cplx nphi = cphi + dphi;
        double dg = 0.0;
        if (accept) {
            const double ro = cphi.real(), rn = nphi.real();
            const bool left_o = ro <= 0.0, left_n = rn <= 0.0;
            const double near = std::min(std::abs(ro), std::abs(rn));
            const double limit = left_o == left_n ? std::max(theta, 0.5 * near) : theta;
            if (!(std::abs(dphi) <= limit)) accept = false;
            if (accept) {
                // arg(1 - e^Phi): directly where |e^Phi| <= 1, through Im Phi + arg(1 - e^-Phi) beyond
                cplx ratio;
                if (!left_o && !left_n) {
                    ratio = (1.0 - std::exp(-nphi)) / (1.0 - std::exp(-cphi));
                    dg = dphi.imag();
                } else {
                    ratio = (1.0 - std::exp(nphi)) / (1.0 - std::exp(cphi));
                }
                const double wrapped = std::arg(ratio);
                if (!finite(ratio) || ratio == 0.0 || !(std::abs(wrapped) <= theta)) accept = false;
                dg += wrapped;
            }
        }
        if (accept) {
            total += darg + dg;
            std::swap(cp, np);
            std::swap(cr, nr);
            cphi = nphi;
            cur = next;
            t = tn;
            h = std::min(1.6 * h, cap(cur, cphi));
        } else {
            h *= 0.35;
            if (h < tiny) return false;
        }
    }
    return true;
}

RingDeterminant::Count RingDeterminant::count(double x0, double x1, double y0, double y1, double theta) const {
    Count c;
    double total = 0.0;
    const cplx z00(x0, y0), z10(x1, y0), z11(x1, y1), z01(x0, y1);
    c.ok = follow(z00, z10, theta, total, c.evaluations) && follow(z10, z11, theta, total, c.evaluations) &&
           follow(z11, z01, theta, total, c.evaluations) && follow(z01, z00, theta, total, c.evaluations);
    if (!c.ok) return c;
    const double w = total / kTwoPi;
    c.zeros = static_cast<int>(std::lround(w));
    c.ok = std::abs(w - c.zeros) < 0.25 && c.zeros >= 0;
    return c;
}

RingDeterminant::Count RingDeterminant::count_symmetric(double x0, double x1, double y, double theta) const {
    Count c;
    double total = 0.0;
    const cplx a(x1, 0.0), b(x1, y), d(x0, y), e(x0, 0.0);
    c.ok = follow(a, b, theta, total, c.evaluations) && follow(b, d, theta, total, c.evaluations) &&
           follow(d, e, theta, total, c.evaluations);
    if (!c.ok) return c;
    const double w = 2.0 * total / kTwoPi;
    c.zeros = static_cast<int>(std::lround(w));
    c.ok = std::abs(w - c.zeros) < 0.25 && c.zeros >= 0;
    return c;
}

void ProductRootOptions::validate() const {
    auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
    if (count < 1) fail("count = " + std::to_string(count) + ": expected an integer >= 1");
    if (!(max_arg_step > 0.0 && max_arg_step <= 1.0)) fail("max_arg_step: expected a value in (0, 1] radians");
    if (max_cells < 1) fail("max_cells: expected >= 1");
    if (!(max_type_evaluations >= 1.0)) fail("max_type_evaluations: expected >= 1");
    if (newton_max_iterations < 1) fail("newton_max_iterations: expected >= 1");
    if (!(std::isfinite(newton_tolerance) && newton_tolerance > 0.0)) fail("newton_tolerance: expected a finite value > 0");
    if (!(std::isfinite(residual_tolerance) && residual_tolerance > 0.0)) fail("residual_tolerance: expected a finite value > 0");
}

namespace {

/// A cell of the search: [x0, x1] x [y0, y1], or for an axis cell [x0, x1] x [-y1, y1].
struct Cell {
    double x0, x1, y0, y1;
    bool axis;
    int zeros;
};

class Locator {
public:
    Locator(const RingDeterminant& det, const ProductRootOptions& o) : m_det(det), m_o(o) {}

    /// Count of a cell (false when a zero lies on its boundary or a budget ran out).
    bool count(Cell& c) {
        if (exhausted()) return false;
        ++m_counts;
        const auto r = c.axis ? m_det.count_symmetric(c.x0, c.x1, c.y1, m_o.max_arg_step)
                              : m_det.count(c.x0, c.x1, c.y0, c.y1, m_o.max_arg_step);
        m_evaluations += r.evaluations;
        c.zeros = r.zeros;
        return r.ok;
    }

    /// The cell-count or evaluation budget is used up.
    bool exhausted() const {
        return m_counts >= m_o.max_cells || static_cast<double>(m_evaluations) * m_det.types() > m_o.max_type_evaluations;
    }

    /// Count of the child cell made by `make(f)`, f the fraction of the split; when a zero lies
    /// on the split line the line is moved (the parent's outer boundary never moves).
    template <class Make>
    bool count_split(Make make, Cell& child) {
        for (double f : {0.5, 0.5123, 0.4871, 0.5377, 0.4619, 0.5931}) {
            child = make(f);
            if (count(child)) return true;
            if (exhausted()) return false;
        }
        return false;
    }

    /// Newton on D from z; true when converged.
    bool newton(cplx z, bool real, cplx& out, double& step_out) const {
        double step = std::numeric_limits<double>::infinity();
        out = z;
        step_out = step;
        for (int it = 0; it < m_o.newton_max_iterations; ++it) {
            const cplx d = m_det.log_derivative(z);
            if (d == 0.0) return false;  // D' = 0: a critical point, not a root
            if (!finite(d)) {
                step = 0.0;  // D = 0 to working precision makes D'/D infinite: at a root
                break;
            }
            cplx s = 1.0 / d;
            if (real) s.imag(0.0);
            z -= s;
            step = std::abs(s);
            if (!finite(z)) return false;
            if (step <= m_o.newton_tolerance * scale_of(z)) break;
        }
        out = z;
        step_out = step;
        return step <= 1e-8 * scale_of(z);
    }

    /// Splits `top` until every root inside is isolated and found. A cell that cannot be split
    /// further (too small, or every split line meets a root: coincident roots) is recorded as a
    /// cluster of its count. False when a budget ran out or the counts were inconsistent.
    bool locate(const Cell& top) {
        std::vector<Cell> stack{top};
        while (!stack.empty()) {
            Cell c = stack.back();
            stack.pop_back();
            if (c.zeros == 0) continue;
            if (c.zeros < 0) return false;
            const double w = c.x1 - c.x0, h = c.axis ? 2.0 * c.y1 : c.y1 - c.y0;
            const cplx centre(0.5 * (c.x0 + c.x1), c.axis ? 0.0 : 0.5 * (c.y0 + c.y1));
            const bool smallest = std::max(w, h) <= 1e-11 * scale_of(centre);
            if (c.zeros == 1 || smallest) {
                cplx z;
                double step = 0.0;
                const bool real = c.axis && c.zeros == 1;
                if (newton(centre, real, z, step) && inside(c, z) && !known(z)) {
                    record(c, z, c.zeros, step, c.zeros > 1);
                    continue;
                }
            }
            if (smallest) {
                cluster(c, centre);
                continue;
            }
            // split; the second child's count follows from the first's
            bool split = true;
            if (c.axis && w >= c.y1) {
                Cell a{}, b = c;
                split = count_split([&](double f) { Cell x = c; x.x1 = c.x0 + f * w; return x; }, a);
                if (split) {
                    b.x0 = a.x1;
                    b.zeros = c.zeros - a.zeros;
                    stack.push_back(a);
                    stack.push_back(b);
                }
            } else if (c.axis) {
                Cell low{}, up = c;
                split = count_split([&](double f) { Cell x = c; x.y1 = f * c.y1; return x; }, low);
                if (split) {
                    up.axis = false;
                    up.y0 = low.y1;
                    const int rest = c.zeros - low.zeros;
                    if (rest < 0 || rest % 2 != 0) return false;
                    up.zeros = rest / 2;
                    stack.push_back(low);
                    stack.push_back(up);
                }
            } else {
                Cell a{}, b = c;
                if (w >= h) {
                    split = count_split([&](double f) { Cell x = c; x.x1 = c.x0 + f * w; return x; }, a);
                    b.x0 = a.x1;
                } else {
                    split = count_split([&](double f) { Cell x = c; x.y1 = c.y0 + f * h; return x; }, a);
                    b.y0 = a.y1;
                }
                if (split) {
                    b.zeros = c.zeros - a.zeros;
                    stack.push_back(a);
                    stack.push_back(b);
                }
            }
            if (!split) {
                if (exhausted()) return false;
                cluster(c, centre);  // coincident roots: no split line avoids them
            }
        }
        return true;
    }

    struct Found {
        cplx value;
        int multiplicity;
        double step;
        bool cluster;
    };
    const std::vector<Found>& found() const { return m_found; }
    int counts() const { return m_counts; }
    long evaluations() const { return m_evaluations; }

private:
    static bool inside(const Cell& c, cplx z) {
        return z.real() >= c.x0 && z.real() <= c.x1 && (c.axis ? std::abs(z.imag()) <= c.y1 : (z.imag() >= c.y0 && z.imag() <= c.y1));
    }
    bool known(cplx z) const {
        for (const auto& f : m_found)
            if (std::abs(f.value - z) <= 1e-12 * scale_of(z) || std::abs(std::conj(f.value) - z) <= 1e-12 * scale_of(z)) return true;
        return false;
    }
    /// `count` coincident roots in a cell that cannot be split: Newton from its centre if that
    /// stays inside, else the centre (newton_step infinite).
    void cluster(const Cell& c, cplx centre) {
        cplx z;
        double step = 0.0;
        if (!(newton(centre, c.axis, z, step) && inside(c, z))) {
            z = centre;
            step = std::numeric_limits<double>::infinity();
        }
        record(c, z, c.zeros, step, true);
    }
    void record(const Cell& c, cplx z, int multiplicity, double step, bool cluster) {
        // an axis cell's single root or cluster is real (a pair would have been split off)
        if (c.axis && (multiplicity == 1 || cluster)) z.imag(0.0);
        m_found.push_back({z, multiplicity, step, cluster});
    }

    const RingDeterminant& m_det;
    const ProductRootOptions& m_o;
    std::vector<Found> m_found;
    int m_counts = 0;
    long m_evaluations = 0;
};

/// ||Delta(lambda) x|| / (||x|| scale) for the ring eigenvector x_v,i = Gamma_i x_v,i-1.
double ring_residual(const std::vector<Linearisation>& cars, const std::vector<TransferFunction>& gamma, const SparseDDE& dde,
                     const detail::RootBounds& bounds, cplx z) {
    const int n = static_cast<int>(cars.size());
    std::vector<cplx> logv(n);
    logv[0] = 0.0;
    for (int i = 1; i < n; ++i) logv[i] = logv[i - 1] + std::log(gamma[i](z));
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& l : logv) top = std::max(top, l.real());
    Eigen::VectorXcd x(2 * n);
    for (int i = 0; i < n; ++i) x(2 * i + 1) = std::exp(logv[i] - top);
    for (int i = 0; i < n; ++i) {
        const cplx v = x(2 * i + 1), va = x(2 * ((i + n - 1) % n) + 1);
        const cplx g = cars[i].gap(z);
        // from the speed row when the gap term is not small, otherwise from the gap row
        if (std::abs(g) >= std::abs(z))
            x(2 * i) = (z * v - cars[i].own(z) * v - cars[i].lead(z) * va) / g;
        else
            x(2 * i) = (va - v) / z;
    }
    const double norm = x.norm();
    if (!(norm > 0.0) || !std::isfinite(norm)) return std::numeric_limits<double>::infinity();
    return (dde.characteristic_matrix(z) * x).norm() / (norm * bounds.scale(z));
}

bool rightmost_first(const Root& a, const Root& b) {
    if (a.value.real() != b.value.real()) return a.value.real() > b.value.real();
    return a.value.imag() > b.value.imag();
}

}  // namespace

SparseRootResult product_ring_roots(const std::vector<Linearisation>& cars, const ProductRootOptions& options) {
    options.validate();
    const RingDeterminant det(cars);
    const SparseDDE dde = mixed_ring_dde(cars);
    const detail::RootBounds bounds = detail::root_bounds(normalised(dde));
    double tau = 0.0;
    for (const auto& c : cars) tau = std::max(tau, c.max_delay());
    const double beta = bounds.right_bound();
    SparseRootResult result;
    result.right_bound = beta;
    Locator loc(det, options);
    const std::vector<TransferFunction> gamma(cars.begin(), cars.end());
    // the strip [a, beta] x [-R(a), R(a)]; a is moved by a hair when a root lies on its edge
    auto count_from = [&](double a, Cell& cell) {
        for (int attempt = 0; attempt < 6; ++attempt) {
            const double x = a - 1e-9 * attempt * std::max(1.0, std::abs(a));
            cell = {x, beta, 0.0, bounds.radius(x), true, 0};
            if (!std::isfinite(cell.y1)) return false;
            if (loc.count(cell)) return true;
        }
        return false;
    };
    auto fail = [&](const std::string& why) {
        result.status = RootStatus::EigenFailure;
        result.reason = why;
        return result;
    };
    // a floor with at least `count` roots right of it (or left of every root: a delay-free ring
    // has only 2N roots, all with |lambda| <= R, and then the whole spectrum is listed)
    const double unit = tau > 0.0 ? 1.0 / tau : 1.0;
    double a_hi = beta, a_lo = std::min(0.0, beta) - unit;
    Cell lo{}, mid{};
    // (with delays R(x) grows like e^{-x tau} and roots reach Re -> -infinity, so never then)
    auto everything = [&](double a) { return tau == 0.0 && a < -bounds.radius(a); };
    if (!count_from(a_lo, lo)) return fail("the argument principle failed on the first strip");
    for (int i = 0; lo.zeros < options.count && !everything(a_lo); ++i) {
        if (i == 60) return fail("fewer than " + std::to_string(options.count) + " roots in any strip");
        a_hi = a_lo;
        a_lo -= std::max(beta - a_lo, unit);
        if (!count_from(a_lo, lo)) return fail("the argument principle failed on a strip (Re >= " + detail::format_number(a_lo) + ")");
    }
    // bisection: as few roots as possible beyond `count` (a conjugate pair may add one)
    while (lo.zeros > options.count + 1 && a_hi - a_lo > 1e-12 * std::max(1.0, std::abs(a_lo))) {
        const double a = 0.5 * (a_lo + a_hi);
        if (!count_from(a, mid)) return fail("the argument principle failed while bisecting the strip floor");
        if (mid.zeros >= options.count) {
            lo = mid;
            a_lo = lo.x0;
        } else {
            a_hi = a;
        }
    }
    const bool located = loc.locate(lo);
    result.strip_floor = lo.x0;
    result.height = lo.y1;
    result.eigenvalues_found = lo.zeros;
    int listed = 0, clusters = 0;
    for (const auto& f : loc.found()) {
        listed += f.multiplicity;
        clusters += f.cluster ? 1 : 0;
        Root r;
        r.value = f.value;
        r.newton_step = f.step;
        r.residual = ring_residual(cars, gamma, dde, bounds, f.value);
        result.roots.push_back(r);
        if (f.value.imag() > 0.0) {
            r.value = std::conj(f.value);
            result.roots.push_back(r);
            listed += f.multiplicity;
        }
    }
    std::stable_sort(result.roots.begin(), result.roots.end(), rightmost_first);
    std::vector<Root> all = result.roots;
    result.roots = detail::cut_rightmost(all, options.count);
    if (result.roots.size() < all.size() && !result.roots.empty())
        result.strip_floor = std::max(result.strip_floor, result.roots.back().value.real());
    for (const auto& r : result.roots) {
        result.eigenvalues.push_back(r.value);
        result.max_residual = std::max(result.max_residual, r.residual);
    }
    int bad = 0;
    for (const auto& r : result.roots) bad += r.residual <= options.residual_tolerance ? 0 : 1;
    std::ostringstream os;
    os.precision(3);
    if (!located || listed != lo.zeros) {
        result.status = RootStatus::EigenFailure;
        os << "the argument principle counts " << lo.zeros << " roots with Re >= " << lo.x0 << " but " << listed
           << " were located (" << loc.counts() << " contour counts)";
    } else if (bad > 0 || clusters > 0) {
        result.status = RootStatus::MaxDegreeReached;
        os << bad << " roots above the residual tolerance, " << clusters << " clusters of coincident roots";
    } else {
        os << "all " << lo.zeros << " roots of det Delta = prod P_i - prod Q_i with Re >= " << lo.x0
           << " located (argument principle on [" << lo.x0 << ", " << beta << "] x [-" << lo.y1 << ", " << lo.y1
           << "], no root lies outside it; " << loc.counts() << " contour counts, " << loc.evaluations() << " evaluations over "
           << det.types() << (det.types() == 1 ? " car type" : " car types") << "); each refined by Newton on D (max residual " << result.max_residual << ")";
    }
    result.reason = os.str();
    return result;
}

}  // namespace ddemap
