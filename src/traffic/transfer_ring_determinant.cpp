// TransferRingDeterminant: det Delta = prod_i P_i det(I - T_{N-1} ... T_0) of a ring whose cars
// react to up to two cars ahead (ring_determinant.hpp has the derivation).

#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>

#include "ddemap/traffic/ring_determinant.hpp"

namespace ddemap {

namespace {

constexpr double kLn2 = 0.69314718055994530942;
/// Products are rescaled by 2^-kScaleBits when an entry leaves [2^-kScaleBits, 2^kScaleBits].
constexpr int kScaleBits = 256;
/// Longest block of cars tried when cutting the ring.
constexpr int kMaxBlock = 24;

bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }

bool same(const Linearisation& a, const Linearisation& b) {
    if (!(a.gap == b.gap && a.own == b.own && a.lead == b.lead)) return false;
    const bool fa = !a.further.empty() && !a.further[0].empty(), fb = !b.further.empty() && !b.further[0].empty();
    return fa == fb && (!fa || a.further[0] == b.further[0]);
}

/// A 2 x 2 complex matrix [[a, b], [c, d]].
struct Mat2 {
    cplx a, b, c, d;
};

Mat2 mul(const Mat2& x, const Mat2& y) {
    return {x.a * y.a + x.b * y.c, x.a * y.b + x.b * y.d, x.c * y.a + x.d * y.c, x.c * y.b + x.d * y.d};
}

Mat2 add(const Mat2& x, const Mat2& y) { return {x.a + y.a, x.b + y.b, x.c + y.c, x.d + y.d}; }

double max_abs(const cplx& z) { return std::max(std::abs(z.real()), std::abs(z.imag())); }
double max_abs(const Mat2& m) { return std::max({max_abs(m.a), max_abs(m.b), max_abs(m.c), max_abs(m.d)}); }

Mat2 scaled(const Mat2& m, int bits) {
    auto s = [bits](cplx z) { return cplx(std::ldexp(z.real(), bits), std::ldexp(z.imag(), bits)); };
    return {s(m.a), s(m.b), s(m.c), s(m.d)};
}

/// 2^e (m, dm): a product of transfer matrices and its derivative.
struct Jet {
    Mat2 m, dm;
    long e = 0;
    void rescale() {
        const double top = max_abs(m);
        if (top > std::ldexp(1.0, kScaleBits)) {
            m = scaled(m, -kScaleBits);
            dm = scaled(dm, -kScaleBits);
            e += kScaleBits;
        } else if (top < std::ldexp(1.0, -kScaleBits) && top > 0.0) {
            m = scaled(m, kScaleBits);
            dm = scaled(dm, kScaleBits);
            e -= kScaleBits;
        }
    }
};

/// x y with the product rule.
Jet mul(const Jet& x, const Jet& y) {
    Jet r{mul(x.m, y.m), add(mul(x.dm, y.m), mul(x.m, y.dm)), x.e + y.e};
    r.rescale();
    return r;
}

/// T x for a transfer matrix T = [[a, b], [1, 0]] with T' = [[da, db], [0, 0]].
void left_leaf(cplx a, cplx b, cplx da, cplx db, Jet& x) {
    const Mat2 m = x.m, dm = x.dm;
    x.m = {a * m.a + b * m.c, a * m.b + b * m.d, m.a, m.b};
    x.dm = {da * m.a + db * m.c + a * dm.a + b * dm.c, da * m.b + db * m.d + a * dm.b + b * dm.d, dm.a, dm.b};
    x.rescale();
}

/// x^k by repeated squaring (k >= 1).
Jet power(Jet x, long k) {
    Jet r;
    bool have = false;
    while (k > 0) {
        if (k & 1) {
            r = have ? mul(x, r) : x;
            have = true;
        }
        k >>= 1;
        if (k > 0) x = mul(x, x);
    }
    return r;
}

/// Matrix products of x^k: squarings and multiplications.
long power_products(long k) {
    long n = 0;
    bool have = false;
    while (k > 0) {
        if (k & 1) {
            n += have ? 1 : 0;
            have = true;
        }
        k >>= 1;
        if (k > 0) ++n;
    }
    return n;
}

/// P, Q, R of one car and their derivatives at z.
struct Factors {
    cplx p, q, r, dp, dq, dr;
};

Factors factors(const Linearisation& l, cplx z) {
    const cplx gap = l.gap(z), own = l.own(z), lead = l.lead(z);
    const cplx dgap = l.gap.derivative(z), down = l.own.derivative(z), dlead = l.lead.derivative(z);
    Factors f;
    f.p = z * z - z * own + gap;
    f.q = gap + z * lead;
    f.dp = 2.0 * z - own - z * down + dgap;
    f.dq = dgap + lead + z * dlead;
    if (!l.further.empty()) {
        const cplx fu = l.further[0](z);
        f.r = z * fu;
        f.dr = fu + z * l.further[0].derivative(z);
    }
    return f;
}

}  // namespace

TransferRingDeterminant::TransferRingDeterminant(const std::vector<Linearisation>& cars) {
    if (cars.size() < 2) throw std::invalid_argument("a ring needs at least 2 cars, got " + std::to_string(cars.size()));
    for (std::size_t i = 0; i < cars.size(); ++i) {
        const Linearisation& c = cars[i];
        if (c.leaders() > 2)
            throw std::invalid_argument("car " + std::to_string(i + 1) + " reacts to " + std::to_string(c.leaders()) +
                                        " cars ahead: the transfer-matrix ring determinant takes at most 2");
        auto it = std::find_if(m_types.begin(), m_types.end(), [&](const Type& t) { return same(t.lin, c); });
        if (it == m_types.end()) {
            m_car_type.push_back(static_cast<int>(m_types.size()));
            m_types.push_back({c, 1.0});
        } else {
            m_car_type.push_back(static_cast<int>(it - m_types.begin()));
            it->n += 1.0;
        }
    }
    for (const auto& t : m_types)
        if (t.lin.further.empty() || t.lin.further[0].empty()) m_det_zero = true;
    // cut the ring into blocks of b cars: each distinct block costs its length in leaf products,
    // each run of k equal blocks 1 + power_products(k) full products (counted twice: a full
    // product with its derivative costs about twice a leaf product)
    const long n = static_cast<long>(m_car_type.size());
    long best = std::numeric_limits<long>::max();
    for (int b = 1; b <= std::min<long>(kMaxBlock, n); ++b) {
        std::map<std::vector<int>, int> ids;
        std::vector<std::vector<int>> blocks;
        std::vector<Run> runs;
        long leaf = 0;
        for (long start = 0; start < n; start += b) {
            std::vector<int> key(m_car_type.begin() + start, m_car_type.begin() + std::min(n, start + b));
            auto [it, fresh] = ids.emplace(key, static_cast<int>(blocks.size()));
            if (fresh) {
                leaf += static_cast<long>(key.size());
                blocks.push_back(std::move(key));
            }
            if (!runs.empty() && runs.back().block == it->second)
                ++runs.back().count;
            else
                runs.push_back({it->second, 1});
        }
        long full = static_cast<long>(runs.size()) - 1;
        for (const auto& r : runs) full += power_products(r.count);
        const long cost = leaf + 2 * full;
        if (cost < best) {
            best = cost;
            m_block = b;
            m_blocks = std::move(blocks);
            m_runs = std::move(runs);
            m_products = cost;
        }
    }
}

void TransferRingDeterminant::evaluate(cplx z, Sample& s) const {
    const std::size_t nt = m_types.size();
    s.ok = false;
    s.g = s.dg = cplx(std::numeric_limits<double>::quiet_NaN(), 0.0);
    s.p.resize(nt);
    s.dlogp.resize(nt);
    std::vector<cplx>&a = s.a, &b = s.b, &da = s.da, &db = s.db;
    a.resize(nt);
    b.resize(nt);
    da.resize(nt);
    db.resize(nt);
    cplx ldet = 0.0, dldet = 0.0;
    bool det_zero = m_det_zero;
    for (std::size_t t = 0; t < nt; ++t) {
        const Factors f = factors(m_types[t].lin, z);
        if (f.p == 0.0 || !finite(f.p) || !finite(f.dp)) return;
        s.p[t] = f.p;
        s.dlogp[t] = f.dp / f.p;
        a[t] = f.q / f.p;
        b[t] = f.r / f.p;
        da[t] = (f.dq - a[t] * f.dp) / f.p;
        db[t] = (f.dr - b[t] * f.dp) / f.p;
        if (b[t] == 0.0) det_zero = true;
        if (!det_zero) {
            ldet += m_types[t].n * std::log(-b[t]);
            dldet += m_types[t].n * db[t] / b[t];
        }
    }
    // the distinct blocks, then the runs (a later car multiplies from the left)
    std::vector<Jet> block(m_blocks.size());
    for (std::size_t k = 0; k < m_blocks.size(); ++k) {
        const std::vector<int>& cars = m_blocks[k];
        Jet& x = block[k];
        x.m = {1.0, 0.0, 0.0, 1.0};
        x.dm = {0.0, 0.0, 0.0, 0.0};
        for (int t : cars) left_leaf(a[t], b[t], da[t], db[t], x);
    }
    Jet m;
    bool have = false;
    for (const auto& r : m_runs) {
        const Jet x = r.count == 1 ? block[r.block] : power(block[r.block], r.count);
        m = have ? mul(x, m) : x;
        have = true;
    }
    // det(I - M) = 1 - tr M + det M, scaled by e^-scale
    const double top = max_abs(m.m);
    const double log_m = top > 0.0 ? static_cast<double>(m.e) * kLn2 + std::log(top) : -std::numeric_limits<double>::infinity();
    double scale = std::max(0.0, log_m);
    if (!det_zero) scale = std::max(scale, ldet.real());
    if (!std::isfinite(scale)) return;
    const double f = top > 0.0 ? std::exp(static_cast<double>(m.e) * kLn2 - scale) : 0.0;
    s.g = std::exp(-scale) - (m.m.a + m.m.d) * f;
    s.dg = -(m.dm.a + m.dm.d) * f;
    if (!det_zero) {
        const cplx d = std::exp(ldet - scale);
        s.g += d;
        s.dg += d * dldet;
    }
    s.scale = scale;
    const double fro = std::sqrt(std::norm(m.m.a) + std::norm(m.m.b) + std::norm(m.m.c) + std::norm(m.m.d));
    const double dfro = std::sqrt(std::norm(m.dm.a) + std::norm(m.dm.b) + std::norm(m.dm.c) + std::norm(m.dm.d));
    s.size = fro > 0.0 ? static_cast<double>(m.e) * kLn2 + std::log(fro) : -std::numeric_limits<double>::infinity();
    s.size_rate = fro > 0.0 ? dfro / fro : 0.0;
    if (!std::isfinite(s.size) || !std::isfinite(s.size_rate)) return;
    s.ok = finite(s.g) && finite(s.dg) && s.g != 0.0;
    for (std::size_t t = 0; t < nt && s.ok; ++t) s.ok = finite(s.dlogp[t]);
}

cplx TransferRingDeterminant::log_value(cplx z) const {
    Sample s;
    evaluate(z, s);
    if (!s.ok && s.g == 0.0) return {-std::numeric_limits<double>::infinity(), 0.0};  // an exact root
    if (!s.ok) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
    cplx v = s.scale + std::log(s.g);
    for (std::size_t t = 0; t < m_types.size(); ++t) v += m_types[t].n * std::log(s.p[t]);
    return v;
}

cplx TransferRingDeterminant::log_closure(cplx z) const {
    Sample s;
    evaluate(z, s);
    if (!s.ok) return {std::numeric_limits<double>::quiet_NaN(), 0.0};
    return s.scale + std::log(s.g);
}

cplx TransferRingDeterminant::log_derivative(cplx z) const {
    Sample s;
    evaluate(z, s);
    if (!s.ok) {
        // D = 0 to working precision (g = 0) makes D'/D infinite; otherwise not evaluable
        return s.g == 0.0 && finite(s.dg) ? cplx(std::numeric_limits<double>::infinity(), 0.0)
                                          : cplx(std::numeric_limits<double>::quiet_NaN(), 0.0);
    }
    cplx d = s.dg / s.g;
    for (std::size_t t = 0; t < m_types.size(); ++t) d += m_types[t].n * s.dlogp[t];
    return d;
}

bool TransferRingDeterminant::arg_change(cplx a, cplx b, double theta, double& total, long& evaluations) const {
    const double length = std::abs(b - a);
    if (!std::isfinite(length)) return false;
    if (length == 0.0) return true;
    const double tiny = 1e-14 * (std::abs(a) + std::abs(b) + 1.0);
    // the largest local turning rate: max_t |P_t'/P_t| and |g'/g|
    auto rate = [&](const Sample& s) {
        double r = std::abs(s.dg / s.g);
        for (const auto& d : s.dlogp) r = std::max(r, std::abs(d));
        return r;
    };
    // the step control is the one phase tracker's (follow_phase); this path evaluates and tests
    struct Path {
        const TransferRingDeterminant& det;
        cplx a, b;
        double length, theta;
        long& evaluations;
        decltype(rate)& rate_of;
        Sample cur, next;
        double t = 0.0, t_next = 0.0, cur_rate = 0.0;
        double cap() const {
            double h = length / 8.0;
            if (cur_rate > 0.0) h = std::min(h, theta / cur_rate);
            // log ||M|| moves by at most max(theta, |size| / 2): no jump over the band size ~ 0
            if (cur.size_rate > 0.0) h = std::min(h, std::max(theta, 0.5 * std::abs(cur.size)) / cur.size_rate);
            return h;
        }
        bool trial(double tn, double& step_arg) {
            ++evaluations;
            t_next = tn;
            det.evaluate(a + (b - a) * (tn / length), next);
            if (!next.ok) return false;
            // the rates at the new point allow the step, and every factor turns by at most theta
            if ((tn - t) * rate_of(next) > 2.0 * theta) return false;
            const double so = cur.size, sn = next.size;
            const double near = std::min(std::abs(so), std::abs(sn));
            const double limit = (so < 0.0) == (sn < 0.0) ? std::max(theta, 0.5 * near) : theta;
            if (!(std::abs(sn - so) <= limit) || !((tn - t) * next.size_rate <= 2.0 * std::max(theta, 0.5 * std::abs(sn))))
                return false;
            double darg = 0.0;
            for (std::size_t k = 0; k < next.p.size(); ++k) {
                const double dp = std::arg(next.p[k] * std::conj(cur.p[k]));
                if (!(std::abs(dp) <= theta)) return false;
                darg += det.m_types[k].n * dp;
            }
            const double dg = std::arg(next.g * std::conj(cur.g));
            if (!(std::abs(dg) <= theta)) return false;
            step_arg = darg + dg;
            return true;
        }
        bool failed() const { return false; }
        void accept() {
            std::swap(cur, next);
            cur_rate = rate_of(cur);
            t = t_next;
        }
    };
    Path path{*this, a, b, length, theta, evaluations, rate, Sample{}, Sample{}};
    evaluate(a, path.cur);
    ++evaluations;
    if (!path.cur.ok) return false;
    path.cur_rate = rate(path.cur);
    return follow_phase(path, length, tiny, total);
}

ZeroCount TransferRingDeterminant::count(double x0, double x1, double y0, double y1, double theta) const {
    return count_zeros(*this, x0, x1, y0, y1, theta);
}

ZeroCount TransferRingDeterminant::count_symmetric(double x0, double x1, double y, double theta) const {
    return count_zeros_symmetric(*this, x0, x1, y, theta);
}

double TransferRingDeterminant::evaluation_cost() const { return static_cast<double>(m_types.size() + m_products); }

std::string TransferRingDeterminant::cost_description() const {
    return " over " + std::to_string(cars()) + " cars of " + std::to_string(types()) + (types() == 1 ? " type" : " types") +
           " (blocks of " + std::to_string(m_block) + " cars, " + std::to_string(m_products) + " matrix products per evaluation)";
}

VectorXc TransferRingDeterminant::null_vector(cplx z) const {
    // the speeds: inverse iteration with the speed matrix at z, or (exactly singular there, e.g.
    // at the trivial root lambda = 0) at z moved by a rounding-size amount
    VectorXc v = speed_null_vector(z);
    if (v.size() == 0) v = speed_null_vector(z + 1e-14 * std::max(1.0, std::abs(z)));
    if (v.size() == 0) return {};
    const int n = cars();
    VectorXc x(2 * n);
    for (int i = 0; i < n; ++i) {
        const Linearisation& l = m_types[static_cast<std::size_t>(m_car_type[static_cast<std::size_t>(i)])].lin;
        const cplx vi = v(i), va = v((i + n - 1) % n), vb = v((i + n - 2) % n);
        x(2 * i + 1) = vi;
        const cplx g = l.gap(z);
        // from the speed row when the gap term is not small, otherwise from the gap row
        if (std::abs(g) >= std::abs(z)) {
            cplx rhs = z * vi - l.own(z) * vi - l.lead(z) * va;
            if (!l.further.empty()) rhs -= l.further[0](z) * vb;
            x(2 * i) = rhs / g;
        } else {
            x(2 * i) = (va - vi) / z;
        }
    }
    return x;
}

VectorXc TransferRingDeterminant::speed_null_vector(cplx z) const {
    const int n = cars();
    std::vector<Factors> f(m_types.size());
    for (std::size_t t = 0; t < m_types.size(); ++t) f[t] = factors(m_types[t].lin, z);
    using Sp = Eigen::SparseMatrix<cplx>;
    std::vector<Eigen::Triplet<cplx>> entries;
    entries.reserve(3 * static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const Factors& c = f[static_cast<std::size_t>(m_car_type[static_cast<std::size_t>(i)])];
        entries.emplace_back(i, i, c.p);
        entries.emplace_back(i, (i + n - 1) % n, -c.q);
        if (c.r != 0.0) entries.emplace_back(i, (i + n - 2) % n, -c.r);
    }
    Sp c(n, n);
    c.setFromTriplets(entries.begin(), entries.end());  // repeated entries add up (N = 2)
    Eigen::SparseLU<Sp, Eigen::COLAMDOrdering<int>> lu;
    lu.compute(c);
    if (lu.info() != Eigen::Success) return {};
    // inverse iteration from a fixed start: two solves
    VectorXc v = VectorXc::Ones(n);
    for (int i = 0; i < n; ++i) v(i) += cplx(0.5 * std::sin(1.0 + i), 0.25 * std::cos(2.0 + i));
    for (int it = 0; it < 2; ++it) {
        v = lu.solve(v);
        const double norm = v.norm();
        if (lu.info() != Eigen::Success || !(norm > 0.0) || !std::isfinite(norm)) return {};
        v /= norm;
    }
    return v;
}

}  // namespace ddemap
