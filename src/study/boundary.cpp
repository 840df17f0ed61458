#include "ddemap/study/boundary.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/analysis/ring_stability.hpp"
#include "ddemap/analysis/string_stability.hpp"

namespace ddemap {

std::string kind_name(BoundaryKind k) {
    return (k == BoundaryKind::PlantHopf || k == BoundaryKind::RingHopf) ? "hopf" : "string";
}

std::string subkind_name(BoundaryKind k) {
    switch (k) {
        case BoundaryKind::PlantHopf: return "plant";
        case BoundaryKind::RingHopf: return "ring";
        case BoundaryKind::LowFrequency: return "lowfreq";
        case BoundaryKind::Peak: return "peak";
    }
    return "unknown";
}

void BoundaryOptions::validate() const {
    if (!(initial_step > 0 && max_step >= initial_step && min_step > 0 && min_step < initial_step)) {
        throw std::invalid_argument("boundary steps: expected 0 < min_step < initial_step <= max_step");
    }
    if (max_points < 10) throw std::invalid_argument("max_points: expected >= 10");
}

namespace {

/// The boundary equations in scaled unknowns u = (X, Y[, w]), X = (x - lo) / (hi - lo).
class Problem {
public:
    Problem(const SweepSpec& spec, BoundaryKind kind, int mode) : m_spec(spec), m_kind(kind), m_mode(mode) {}
    int equations() const { return m_kind == BoundaryKind::LowFrequency ? 1 : 2; }
    int unknowns() const { return equations() + 1; }
    double x(double X) const { return m_spec.x.lo + X * (m_spec.x.hi - m_spec.x.lo); }
    double y(double Y) const { return m_spec.y.lo + Y * (m_spec.y.hi - m_spec.y.lo); }
    double X(double x) const { return (x - m_spec.x.lo) / (m_spec.x.hi - m_spec.x.lo); }
    double Y(double y) const { return (y - m_spec.y.lo) / (m_spec.y.hi - m_spec.y.lo); }

    /// F(u); false when the model cannot be built there (outside its parameter domain).
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
        f.resize(equations());
        Linearisation lin;
        try {
            lin = model_at(m_spec, x(u(0)), y(u(1)))->linearise();
        } catch (const std::invalid_argument&) {
            return false;
        }
        switch (m_kind) {
            case BoundaryKind::PlantHopf:
            case BoundaryKind::RingHopf: {
                const cplx s(0.0, u(2));
                cplx v;
                if (m_kind == BoundaryKind::PlantHopf) {
                    v = plant_characteristic(lin)(s);
                } else if (m_mode == 0) {
                    v = ring_mode0_characteristic(lin)(s);
                } else {
                    v = ring_mode_characteristic(lin, ring_zeta(m_mode, m_spec.cars))(s);
                }
                f(0) = v.real();
                f(1) = v.imag();
                return true;
            }
            case BoundaryKind::LowFrequency:
                f(0) = low_frequency_expansion(lin).c2;
                return true;
            case BoundaryKind::Peak: {
                const TransferFunction tf(lin);
                f(0) = tf.gain2(u(2)) - 1.0;
                f(1) = tf.gain2_derivative(u(2));
                return true;
            }
        }
        return false;
    }

    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const {
        const int k = equations(), n = unknowns();
        j.resize(k, n);
        for (int c = 0; c < n; ++c) {
            const double h = 1e-7 * std::max(1.0, std::abs(u(c)));
            Eigen::VectorXd up = u, um = u, fp, fm;
            up(c) += h;
            um(c) -= h;
            if (!residual(up, fp) || !residual(um, fm)) return false;
            j.col(c) = (fp - fm) / (2.0 * h);
        }
        return true;
    }

    /// Unit tangent: the null vector of the k x (k+1) Jacobian.
    bool tangent(const Eigen::VectorXd& u, Eigen::VectorXd& t) const {
        Eigen::MatrixXd j;
        if (!jacobian(u, j)) return false;
        t.resize(unknowns());
        if (equations() == 1) {
            t << -j(0, 1), j(0, 0);
        } else {
            const Eigen::Vector3d a = j.row(0).transpose(), b = j.row(1).transpose();
            t = a.cross(b);
        }
        const double n = t.norm();
        if (!(n > 0.0) || !std::isfinite(n)) return false;
        t /= n;
        return true;
    }

    /// Newton on F(u) = 0 plus one linear constraint c . u = d. Returns iterations or -1.
    int correct(Eigen::VectorXd& u, const Eigen::VectorXd& c, double d, double& res) const {
        const int n = unknowns();
        for (int it = 1; it <= 12; ++it) {
            Eigen::VectorXd f;
            Eigen::MatrixXd j;
            if (!residual(u, f) || !jacobian(u, j)) return -1;
            Eigen::MatrixXd a(n, n);
            Eigen::VectorXd r(n);
            a.topRows(n - 1) = j;
            a.row(n - 1) = c.transpose();
            r.head(n - 1) = f;
            r(n - 1) = c.dot(u) - d;
            const Eigen::VectorXd du = a.fullPivLu().solve(r);
            if (!du.allFinite()) return -1;
            u -= du;
            if (du.norm() <= 1e-13 * std::max(1.0, u.norm())) {
                if (!residual(u, f)) return -1;
                res = f.norm();
                return it;
            }
        }
        return -1;
    }

private:
    const SweepSpec& m_spec;
    BoundaryKind m_kind;
    int m_mode;
};

bool inside(const Eigen::VectorXd& u) { return u(0) >= 0.0 && u(0) <= 1.0 && u(1) >= 0.0 && u(1) <= 1.0; }

/// One direction from the seed. Appends points (not the seed) to `out`.
void trace_direction(const Problem& p, Eigen::VectorXd u, Eigen::VectorXd t, const BoundaryOptions& o,
                     std::vector<Eigen::VectorXd>& out, bool& closed, double& max_res) {
    const Eigen::VectorXd start = u;
    double h = o.initial_step;
    const bool has_omega = p.unknowns() == 3;
    const double omega_sign = has_omega && u(2) < 0.0 ? -1.0 : 1.0;
    while (static_cast<int>(out.size()) < o.max_points) {
        Eigen::VectorXd v = u + h * t;
        double res = 0.0;
        const int its = p.correct(v, t, t.dot(v), res);
        if (its < 0 || (v - u).norm() > 3.0 * h) {
            h *= 0.5;
            if (h < o.min_step) return;
            continue;
        }
        if (!inside(v)) {
            // exact crossing of the window edge: the violated coordinate fixed at the edge
            Eigen::VectorXd w = u;
            const int c = (v(0) < 0.0 || v(0) > 1.0) ? 0 : 1;
            const double edge = v(c) < 0.0 ? 0.0 : 1.0;
            Eigen::VectorXd e = Eigen::VectorXd::Zero(p.unknowns());
            e(c) = 1.0;
            w(c) = edge;
            if (p.correct(w, e, edge, res) >= 0 && (w - u).norm() <= 3.0 * h) {
                const int other = 1 - c;
                if (w(other) >= -1e-12 && w(other) <= 1.0 + 1e-12) {
                    out.push_back(w);
                    max_res = std::max(max_res, res);
                }
            }
            return;
        }
        if (has_omega && omega_sign * v(2) <= 0.0) return;  // the crossing frequency reached 0
        Eigen::VectorXd tn;
        if (!p.tangent(v, tn)) return;
        if (tn.dot(t) < 0.0) tn = -tn;
        out.push_back(v);
        max_res = std::max(max_res, res);
        if (out.size() > 8 && (v.head(2) - start.head(2)).norm() < 0.75 * h) {
            closed = true;
            return;
        }
        u = v;
        t = tn;
        if (its <= 3) h = std::min(o.max_step, 1.5 * h);
    }
}

double segment_distance(double px, double py, const BoundaryPoint& a, const BoundaryPoint& b, const Problem& p) {
    const double ax = p.X(a.x), ay = p.Y(a.y), bx = p.X(b.x), by = p.Y(b.y);
    const double dx = bx - ax, dy = by - ay;
    const double l2 = dx * dx + dy * dy;
    double s = l2 > 0 ? ((px - ax) * dx + (py - ay) * dy) / l2 : 0.0;
    s = std::clamp(s, 0.0, 1.0);
    return std::hypot(px - ax - s * dx, py - ay - s * dy);
}

struct Seed {
    BoundaryKind kind;
    int mode;
    Eigen::VectorXd u;     // scaled guess
    int fixed;             // coordinate held fixed during the seed correction (0 = X, 1 = Y)
};

}  // namespace

double boundary_residual(const SweepSpec& spec, BoundaryKind kind, int mode, const BoundaryPoint& pt) {
    const Problem p(spec, kind, mode);
    Eigen::VectorXd u(p.unknowns()), f;
    u(0) = p.X(pt.x);
    u(1) = p.Y(pt.y);
    if (p.unknowns() == 3) u(2) = pt.omega;
    if (!p.residual(u, f)) return std::numeric_limits<double>::infinity();
    return f.norm();
}

BoundarySet trace_boundaries(const SweepResult& sweep, const BoundaryOptions& options) {
    options.validate();
    const auto t0 = std::chrono::steady_clock::now();
    const SweepSpec& spec = sweep.spec;
    const int nx = spec.x.count, ny = spec.y.count;
    BoundarySet set;

    // seeds: sign changes between neighbouring grid points, along x and along y
    std::vector<Seed> seeds;
    auto add_pairs = [&](auto&& value, BoundaryKind kind, int mode, auto&& omega) {
        for (int iy = 0; iy < ny; ++iy)
            for (int ix = 0; ix < nx; ++ix)
                for (int dir = 0; dir < 2; ++dir) {
                    const int jx = ix + (dir == 0), jy = iy + (dir == 1);
                    if (jx >= nx || jy >= ny) continue;
                    const double a = value(ix, iy), b = value(jx, jy);
                    if (!std::isfinite(a) || !std::isfinite(b) || (a < 0.0) == (b < 0.0)) continue;
                    const double s = a / (a - b);
                    Seed sd{kind, mode, Eigen::VectorXd(kind == BoundaryKind::LowFrequency ? 2 : 3), dir == 0 ? 1 : 0};
                    sd.u(0) = (ix + s * (jx - ix)) / (nx - 1.0);
                    sd.u(1) = (iy + s * (jy - iy)) / (ny - 1.0);
                    if (sd.u.size() == 3) sd.u(2) = (1 - s) * omega(ix, iy) + s * omega(jx, jy);
                    seeds.push_back(sd);
                }
    };
    add_pairs([&](int ix, int iy) { return sweep.at(ix, iy).plant_root.real(); }, BoundaryKind::PlantHopf, -1,
              [&](int ix, int iy) { return std::abs(sweep.at(ix, iy).plant_root.imag()); });
    for (int m = 0; m < sweep.modes; ++m) {
        auto root = [&](int ix, int iy) {
            return sweep.mode_roots[(static_cast<std::size_t>(iy) * nx + ix) * sweep.modes + m];
        };
        add_pairs([&](int ix, int iy) { return root(ix, iy).real(); }, BoundaryKind::RingHopf, m,
                  [&](int ix, int iy) { return root(ix, iy).imag(); });
    }
    add_pairs([&](int ix, int iy) { return -sweep.at(ix, iy).lowfreq_margin; }, BoundaryKind::LowFrequency, -1,
              [](int, int) { return 0.0; });
    add_pairs(
        [&](int ix, int iy) {
            const auto& p = sweep.at(ix, iy);
            return p.peak_gain > 0.0 && p.peak_omega > 0.0 && p.lowfreq_margin > 0.0 ? p.peak_gain - 1.0
                                                                                   : std::numeric_limits<double>::quiet_NaN();
        },
        BoundaryKind::Peak, -1, [&](int ix, int iy) { return sweep.at(ix, iy).peak_omega; });
    set.seeds = static_cast<int>(seeds.size());

    const double cell = 1.0 / std::min(nx - 1, ny - 1);
    std::vector<int> traced_mode;  // the seed's mode of every curve (before relabelling)
    for (const Seed& sd : seeds) {
        const Problem p(spec, sd.kind, sd.mode);
        // already on a traced curve of the same kind and mode?
        bool known = false;
        for (std::size_t ci = 0; ci < set.curves.size(); ++ci) {
            const auto& c = set.curves[ci];
            if (c.kind != sd.kind || traced_mode[ci] != sd.mode) continue;
            for (std::size_t i = 0; i + 1 < c.points.size() && !known; ++i)
                known = segment_distance(sd.u(0), sd.u(1), c.points[i], c.points[i + 1], p) < 0.75 * cell;
            if (c.points.size() == 1) known = known || segment_distance(sd.u(0), sd.u(1), c.points[0], c.points[0], p) < 0.75 * cell;
            if (known) break;
        }
        if (known) continue;
        Eigen::VectorXd u = sd.u;
        Eigen::VectorXd e = Eigen::VectorXd::Zero(p.unknowns());
        e(sd.fixed) = 1.0;
        double res = 0.0;
        if (p.correct(u, e, u(sd.fixed), res) < 0 || !inside(u) || (u.head(2) - sd.u.head(2)).norm() > 2.0 * cell ||
            (u.size() == 3 && sd.kind != BoundaryKind::RingHopf && u(2) <= 0.0)) {
            ++set.rejected;
            continue;
        }
        Eigen::VectorXd t;
        if (!p.tangent(u, t)) {
            ++set.rejected;
            continue;
        }
        std::vector<Eigen::VectorXd> fwd, bwd;
        bool closed = false;
        double max_res = res;
        trace_direction(p, u, t, options, fwd, closed, max_res);
        if (!closed) trace_direction(p, u, -t, options, bwd, closed, max_res);
        BoundaryCurve curve;
        curve.kind = sd.kind;
        curve.mode = sd.mode;
        curve.closed = closed;
        curve.max_residual = max_res;
        std::vector<Eigen::VectorXd> all(bwd.rbegin(), bwd.rend());
        all.push_back(u);
        all.insert(all.end(), fwd.begin(), fwd.end());
        for (const auto& v : all) {
            BoundaryPoint bp{p.x(v(0)), p.y(v(1)), v.size() == 3 ? v(2) : 0.0};
            if (!curve.points.empty()) {
                const auto& q = curve.points.back();
                if (std::abs(q.x - bp.x) + std::abs(q.y - bp.y) + std::abs(q.omega - bp.omega) < 1e-13) continue;
            }
            curve.points.push_back(bp);
        }
        // a ring crossing at negative frequency is the conjugate mode's at positive frequency
        if (curve.kind == BoundaryKind::RingHopf && curve.mode > 0 && !curve.points.empty() &&
            curve.points[curve.points.size() / 2].omega < 0.0) {
            curve.mode = spec.cars - curve.mode;
            for (auto& bp : curve.points) bp.omega = -bp.omega;
        }
        set.curves.push_back(std::move(curve));
        traced_mode.push_back(sd.mode);
    }
    set.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return set;
}

}  // namespace ddemap
