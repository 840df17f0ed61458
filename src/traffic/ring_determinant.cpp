#include "ddemap/traffic/ring_determinant.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "ddemap/core/execution.hpp"
#include "ddemap/traffic/fleet.hpp"

namespace ddemap {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
/// From this many car types on, a contour step evaluates the types on all threads.
constexpr std::size_t kParallelTypes = 256;
/// types per block of the parallel reduction (fixed, so sums do not depend on the thread count)
constexpr long kTypeBlock = 64;

bool same(const Linearisation& a, const Linearisation& b) {
    return a.gap == b.gap && a.own == b.own && a.lead == b.lead && a.further.empty() && b.further.empty();
}


bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }

}  // namespace

RingDeterminant::RingDeterminant(const std::vector<Linearisation>& cars) : m_gamma(cars.begin(), cars.end()) {
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

bool RingDeterminant::arg_change(cplx a, cplx b, double theta, double& total, long& evaluations) const {
    const double length = std::abs(b - a);
    if (!std::isfinite(length)) return false;
    if (length == 0.0) return true;
    const double tiny = 1e-14 * (std::abs(a) + std::abs(b) + 1.0);
    const std::size_t nt = m_types.size();
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
    auto step_cap = [&](const Rates& r, cplx phi) {
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
    // the step control is the one phase tracker's; this path evaluates and tests the steps
    struct Path {
        const RingDeterminant& det;
        cplx a, b;
        double length, theta;
        long& evaluations;
        std::vector<cplx>& cp, &cr, &np, &nr;
        cplx& cphi;
        Rates& cur;
        decltype(one)& eval;
        decltype(step_cap)& bound;
        Rates next;
        cplx nphi;
        double cap() const { return bound(cur, cphi); }
        bool trial(double tn, double& step_arg) {
            const std::size_t nt = det.m_types.size();
            const cplx z = a + (b - a) * (tn / length);
            ++evaluations;
            // every factor's argument moves by at most theta (types spread over the threads when many)
            bool ok = true;
            next = Rates{};
            if (nt >= kParallelTypes && thread_count() > 1) {
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
                            if (!eval(static_cast<std::size_t>(k), z, np[k], nr[k], part.rates)) part.bad = true;
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
                    ok = eval(k, z, np[k], nr[k], next) && std::abs(std::arg(np[k] * std::conj(cp[k]))) <= theta &&
                         std::abs(std::arg(nr[k] / cr[k])) <= theta;
            }
            bool accept = ok;
            double darg = 0.0;
            cplx dphi = 0.0;
            for (std::size_t k = 0; k < nt && accept; ++k) {
                const double dp = std::arg(np[k] * std::conj(cp[k]));
                const cplx dr = std::log(nr[k] / cr[k]);
                if (!(std::abs(dp) <= theta && std::abs(dr.imag()) <= theta)) accept = false;
                darg += det.m_types[k].n * dp;
                dphi += det.m_types[k].n * dr;
            }
            nphi = cphi + dphi;
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
            step_arg = darg + dg;
            return accept;
        }
        bool failed() const { return false; }
        void accept() {
            std::swap(cp, np);
            std::swap(cr, nr);
            cphi = nphi;
            cur = next;
        }
    };
    Path path{*this, a, b, length, theta, evaluations, cp, cr, np, nr, cphi, cur, one, step_cap, Rates{}, cplx(0.0)};
    return follow_phase(path, length, tiny, total);
}

RingDeterminant::Count RingDeterminant::count(double x0, double x1, double y0, double y1, double theta) const {
    return count_zeros(*this, x0, x1, y0, y1, theta);
}

RingDeterminant::Count RingDeterminant::count_symmetric(double x0, double x1, double y, double theta) const {
    return count_zeros_symmetric(*this, x0, x1, y, theta);
}

std::string RingDeterminant::cost_description() const {
    return " over " + std::to_string(types()) + (types() == 1 ? " car type" : " car types");
}

VectorXc RingDeterminant::null_vector(cplx z) const {
    const int n = static_cast<int>(m_gamma.size());
    auto car = [&](int i) -> const Linearisation& { return m_gamma[static_cast<std::size_t>(i)].linearisation(); };
    std::vector<cplx> logv(n);
    logv[0] = 0.0;
    for (int i = 1; i < n; ++i) logv[i] = logv[i - 1] + std::log(m_gamma[static_cast<std::size_t>(i)](z));
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& l : logv) top = std::max(top, l.real());
    VectorXc x(2 * n);
    for (int i = 0; i < n; ++i) x(2 * i + 1) = std::exp(logv[i] - top);
    for (int i = 0; i < n; ++i) {
        const cplx v = x(2 * i + 1), va = x(2 * ((i + n - 1) % n) + 1);
        const cplx g = car(i).gap(z);
        // from the speed row when the gap term is not small, otherwise from the gap row
        if (std::abs(g) >= std::abs(z))
            x(2 * i) = (z * v - car(i).own(z) * v - car(i).lead(z) * va) / g;
        else
            x(2 * i) = (va - v) / z;
    }
    return x;
}

RootProblem ring_root_problem(const std::vector<Linearisation>& cars) {
    const bool one_leader = std::all_of(cars.begin(), cars.end(), [](const Linearisation& l) { return l.leaders() == 1; });
    const bool two_leaders = std::all_of(cars.begin(), cars.end(), [](const Linearisation& l) { return l.leaders() <= 2; });
    RootProblem p{mixed_ring_dde(cars), nullptr};
    if (one_leader)
        p.characteristic = std::make_shared<RingDeterminant>(cars);
    else if (two_leaders)
        p.characteristic = std::make_shared<TransferRingDeterminant>(cars);
    return p;
}

}  // namespace ddemap
