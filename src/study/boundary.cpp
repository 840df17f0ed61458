#include "ddemap/study/boundary.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "ddemap/analysis/ring_stability.hpp"
#include "ddemap/analysis/string_stability.hpp"
#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/solve/continuation.hpp"

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
class Problem final : public ContinuationProblem {
public:
    Problem(const SweepSpec& spec, BoundaryKind kind, int mode) : m_spec(spec), m_kind(kind), m_mode(mode) {}
    int equations() const override { return m_kind == BoundaryKind::LowFrequency ? 1 : 2; }
    double x(double X) const { return m_spec.x.lo + X * (m_spec.x.hi - m_spec.x.lo); }
    double y(double Y) const { return m_spec.y.lo + Y * (m_spec.y.hi - m_spec.y.lo); }
    double X(double x) const { return (x - m_spec.x.lo) / (m_spec.x.hi - m_spec.x.lo); }
    double Y(double y) const { return (y - m_spec.y.lo) / (m_spec.y.hi - m_spec.y.lo); }

    /// F(u); false when the model cannot be built there (outside its parameter domain).
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const override {
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

    /// Central differences: any model works, linear in its parameters or not.
    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const override {
        return central_difference_jacobian(*this, u, j);
    }

    /// A branch keeps the sign of its crossing frequency (it ends where the frequency reaches 0).
    bool in_domain(const Eigen::VectorXd& u) const override { return unknowns() == 2 || m_omega_sign * u(2) > 0.0; }
    void keep_omega_sign(const Eigen::VectorXd& u) { m_omega_sign = unknowns() == 3 && u(2) < 0.0 ? -1.0 : 1.0; }

private:
    const SweepSpec& m_spec;
    BoundaryKind m_kind;
    int m_mode;
    double m_omega_sign = 1.0;
};

bool inside(const Eigen::VectorXd& u) { return u(0) >= 0.0 && u(0) <= 1.0 && u(1) >= 0.0 && u(1) <= 1.0; }

/// The engine's options for a branch in the unit window: BoundaryOptions' steps, at most
/// max_points points each way from the seed, no angle test, the window as the box.
ContinuationOptions engine_options(const BoundaryOptions& o, int unknowns) {
    ContinuationOptions c;
    c.initial_step = o.initial_step;
    c.max_step = o.max_step;
    c.min_step = o.min_step;
    c.max_points = o.max_points + 1;
    c.max_angle = std::acos(0.0);
    c.lower = Eigen::VectorXd::Constant(unknowns, -std::numeric_limits<double>::infinity());
    c.upper = Eigen::VectorXd::Constant(unknowns, std::numeric_limits<double>::infinity());
    c.lower.head(2).setZero();
    c.upper.head(2).setOnes();
    return c;
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
    if (sweep.spec.cars > 0 && sweep.modes == 0) {
        // a winding sweep holds no per-mode roots; the ring Hopf seeds need them
        SweepSpec spec = sweep.spec;
        spec.ring_method = "modes";
        return trace_boundaries(run_sweep(spec), options);
    }
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
        Problem p(spec, sd.kind, sd.mode);
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
        const CorrectorResult seed = correct(p, u, Eigen::VectorXd::Unit(p.unknowns(), sd.fixed), u(sd.fixed));
        if (!converged(seed.status) || !inside(u) || (u.head(2) - sd.u.head(2)).norm() > 2.0 * cell ||
            (u.size() == 3 && sd.kind != BoundaryKind::RingHopf && u(2) <= 0.0)) {
            ++set.rejected;
            continue;
        }
        Eigen::VectorXd t;
        if (!tangent(p, u, Eigen::VectorXd(), t)) {
            ++set.rejected;
            continue;
        }
        p.keep_omega_sign(u);
        const ContinuationOptions eo = engine_options(options, p.unknowns());
        const ContinuationResult fwd = continue_branch(p, u, t, eo);
        if (fwd.points.empty()) {  // no tangent at the seed after all
            ++set.rejected;
            continue;
        }
        ContinuationResult bwd;
        if (fwd.stop != ContinuationStop::ClosedLoop) bwd = continue_branch(p, u, -t, eo);
        BoundaryCurve curve;
        curve.kind = sd.kind;
        curve.mode = sd.mode;
        curve.closed = fwd.stop == ContinuationStop::ClosedLoop || bwd.stop == ContinuationStop::ClosedLoop;
        curve.max_residual = std::max(fwd.max_residual, bwd.max_residual);
        // the backward branch reversed, the seed, the forward branch
        std::vector<Eigen::VectorXd> all;
        if (!bwd.points.empty()) all.assign(bwd.points.rbegin(), bwd.points.rend() - 1);
        all.insert(all.end(), fwd.points.begin(), fwd.points.end());
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
