#include "ddemap/study/boundary.hpp"

#include <algorithm>
#include <map>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Dense>

#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/ring_winding.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/problem/quasi_polynomial.hpp"
#include "ddemap/solve/continuation.hpp"
#include "ddemap/traffic/ring.hpp"
#include "ddemap/traffic/transfer_function.hpp"

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

std::string ring_curves_name(RingCurves r) {
    switch (r) {
        case RingCurves::All: return "all";
        case RingCurves::Envelope: return "envelope";
        case RingCurves::Auto: return "auto";
    }
    return "unknown";
}

RingCurves parse_ring_curves(const std::string& text) {
    if (text == "all") return RingCurves::All;
    if (text == "envelope") return RingCurves::Envelope;
    if (text == "auto") return RingCurves::Auto;
    throw std::invalid_argument("ring curves '" + text + "': expected all, envelope or auto");
}

RingCurves resolve_ring_curves(RingCurves r, const SweepSpec& spec) {
    if (spec.cars == 0) return r == RingCurves::Auto ? RingCurves::Envelope : r;  // N = inf: no ring Hopf curves either way
    const bool applies = ring_winding_applies(model_at(spec, spec.x.lo, spec.y.lo)->linearise());
    if (r == RingCurves::Envelope && !applies)
        throw std::invalid_argument("ring curves envelope: the model '" + spec.model + "' uses more than the car ahead; expected a law of the car ahead only");
    if (r == RingCurves::Auto) return applies && spec.cars > kEnvelopeAutoCars ? RingCurves::Envelope : RingCurves::All;
    return r;
}

bool on_ring_envelope(const SweepSpec& spec, int mode, double x, double y, double omega) {
    if (spec.cars <= 0) throw std::invalid_argument("on_ring_envelope: expected a finite ring (N >= 2)");
    Linearisation lin;
    try {
        lin = model_at(spec, x, y)->linearise();
    } catch (const std::invalid_argument&) {
        return false;
    }
    if (!is_computable(lin)) return false;
    const int n = spec.cars;
    const int low = std::min(((mode % n) + n) % n, n - ((mode % n) + n) % n);  // m or N - m, whichever is <= N/2
    // the crossing as the guess of the abscissa's Newton steps (root Im >= 0: mode m at omega > 0, N - m below)
    RingWindingGuess guess;
    const int carrier = omega >= 0.0 ? ((mode % n) + n) % n : (n - ((mode % n) + n) % n) % n;
    if (carrier == 0) {
        guess.have_mode0 = true;
        guess.mode0 = cplx(0.0, std::abs(omega));
    } else {
        guess.have = true;
        guess.mode = carrier;
        guess.root = cplx(0.0, std::abs(omega));
    }
    RingWindingResult w;
    try {
        w = analyse_ring_winding(lin, n, {}, guess);
    } catch (const std::invalid_argument&) {
        return false;
    }
    if (w.status != Status::Converged) {
        // the axis table is undecided when the crossing pair sits within rounding of the tangency
        // at s = 0 (a huge ring's smallest wave numbers): count the roots of every mode right of
        // the line Re = 1e-10 max(1, |omega|) instead (mode 0 on its own, without its trivial root)
        const double sigma = 1e-10 * std::max(1.0, std::abs(omega));
        const RingWindingTable t = ring_winding_table(TransferFunction(lin), sigma);
        if (!t.ok) return false;  // undecided: the arc ends (never a guess)
        const int zeros0 = ring_mode0_characteristic(lin).zeros_right_of(sigma);
        if (zeros0 != 0) return false;
        return t.mode_zeros(n) == 0;
    }
    if (w.verdict == Verdict::Stable || w.verdict == Verdict::Marginal) return true;
    if (w.verdict != Verdict::Unstable) return false;
    // only the traced pair (within rounding of the axis) right of it
    return w.unstable_roots <= 2 && w.abscissa_mode == low && w.spectral_abscissa < 1e-9 * std::max(1.0, std::abs(w.abscissa_root));
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

namespace {

/// Do the segments a-b and c-d (scaled coordinates) cross or touch?
bool segments_meet(double ax, double ay, double bx, double by, double cx, double cy, double dx, double dy) {
    auto orient = [](double px, double py, double qx, double qy, double rx, double ry) {
        const double v = (qx - px) * (ry - py) - (qy - py) * (rx - px);
        return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0);
    };
    const int o1 = orient(ax, ay, bx, by, cx, cy), o2 = orient(ax, ay, bx, by, dx, dy);
    const int o3 = orient(cx, cy, dx, dy, ax, ay), o4 = orient(cx, cy, dx, dy, bx, by);
    return o1 != o2 && o3 != o4;
}

/// The curve from a backward and a forward branch through the same start (backward reversed).
void append_branches(BoundaryCurve& curve, const Problem& p, const ContinuationResult& bwd, const ContinuationResult& fwd) {
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
}

/// The envelope's arcs (BoundaryOptions: RingCurves::Envelope), appended to set.curves.
void trace_envelope(const SweepResult& sweep, const BoundaryOptions& options, BoundarySet& set) {
    const SweepSpec& spec = sweep.spec;
    const int nx = spec.x.count, ny = spec.y.count, cars = spec.cars;
    const double cell = 1.0 / std::min(nx - 1, ny - 1);
    const std::size_t first_arc = set.curves.size();
    std::vector<int> arc_mode;  // every arc's traced mode (before relabelling), omega sign included in the curve
    const int max_arcs = std::max(200, 20 * (nx + ny));

    // scaled coordinates of a boundary point
    const Problem frame(spec, BoundaryKind::RingHopf, 0);
    auto envelope_test = [&](int mode) {
        TestFunction g;
        g.name = "another mode unstable";
        g.terminal = true;
        g.value = [&spec, mode, &frame](const Eigen::VectorXd& u, const Eigen::VectorXd&) {
            return on_ring_envelope(spec, mode, frame.x(u(0)), frame.y(u(1)), u(2)) ? 1.0 : -1.0;
        };
        return g;
    };
    auto ok_at = [&](int mode, const Eigen::VectorXd& u) { return inside(u) && on_ring_envelope(spec, mode, frame.x(u(0)), frame.y(u(1)), u(2)); };
    auto arc_length = [&](const BoundaryCurve& c) {
        double l = 0.0;
        for (std::size_t i = 0; i + 1 < c.points.size(); ++i)
            l += std::hypot(frame.X(c.points[i + 1].x) - frame.X(c.points[i].x), frame.Y(c.points[i + 1].y) - frame.Y(c.points[i].y));
        return l;
    };
    // a corner to continue from: the end point of an arc and the direction it was going
    struct Corner {
        Eigen::VectorXd u, t;
        int mode;
    };
    std::vector<Corner> corners;

    // one arc of `mode` through u (on its Hopf curve and on the envelope), traced both ways
    // (`both`) or only along +t, starting with `prefix` (the corner it comes from)
    auto trace_arc = [&](int mode, const Eigen::VectorXd& u, const Eigen::VectorXd& t, bool both, const Eigen::VectorXd* prefix) {
        Problem p(spec, BoundaryKind::RingHopf, mode);
        p.keep_omega_sign(u);
        const ContinuationOptions eo = engine_options(options, 3);
        const std::vector<TestFunction> tests{envelope_test(mode)};
        const ContinuationResult fwd = continue_branch(p, u, t, eo, tests);
        if (fwd.points.empty()) return false;
        ContinuationResult bwd;
        if (both && fwd.stop != ContinuationStop::ClosedLoop) bwd = continue_branch(p, u, -t, eo, tests);
        BoundaryCurve curve;
        curve.kind = BoundaryKind::RingHopf;
        curve.mode = mode;
        curve.closed = fwd.stop == ContinuationStop::ClosedLoop || bwd.stop == ContinuationStop::ClosedLoop;
        curve.max_residual = std::max(fwd.max_residual, bwd.max_residual);
        if (prefix) curve.points.push_back({p.x((*prefix)(0)), p.y((*prefix)(1)), (*prefix)(2)});
        append_branches(curve, p, bwd, fwd);
        const bool chain = arc_length(curve) >= 1e-3 * cell;  // far below a pixel: the scallops of a huge ring
        if (chain && fwd.stop == ContinuationStop::TerminalEvent) corners.push_back({fwd.points.back(), fwd.tangents.back(), mode});
        if (chain && bwd.stop == ContinuationStop::TerminalEvent) corners.push_back({bwd.points.back(), bwd.tangents.back(), mode});
        // a crossing at negative frequency is the conjugate mode's at positive frequency
        if (curve.mode > 0 && curve.points[curve.points.size() / 2].omega < 0.0) {
            curve.mode = cars - curve.mode;
            for (auto& bp : curve.points) bp.omega = -bp.omega;
        }
        set.curves.push_back(std::move(curve));
        arc_mode.push_back(mode);
        return true;
    };

    // the next mode at a corner: the one unstable just past it; its arc starts at the corner
    auto follow_corners = [&] {
        while (!corners.empty() && static_cast<int>(set.curves.size() - first_arc) < max_arcs) {
            const Corner c = corners.back();
            corners.pop_back();
            Eigen::VectorXd beyond = c.u + 1e-6 * c.t;
            Linearisation lin;
            try {
                lin = model_at(spec, frame.x(beyond(0)), frame.y(beyond(1)))->linearise();
            } catch (const std::invalid_argument&) {
                continue;
            }
            if (!inside(beyond) || !is_computable(lin)) continue;
            const RingWindingResult w = analyse_ring_winding(lin, cars);
            if (w.status != Status::Converged || w.verdict != Verdict::Unstable || w.abscissa_mode < 0) continue;
            const int next = w.abscissa_mode;
            const double omega = std::abs(w.abscissa_root.imag());
            if (!(omega > 0.0)) continue;
            // already reached by an arc of that mode?
            bool known = false;
            for (std::size_t i = 0; i < arc_mode.size() && !known; ++i) {
                if (arc_mode[i] != next) continue;
                const auto& pts = set.curves[first_arc + i].points;
                for (const auto* e : {&pts.front(), &pts.back()})
                    known = known || std::hypot(frame.X(e->x) - c.u(0), frame.Y(e->y) - c.u(1)) < 1e-5;
            }
            if (known) continue;
            bool done = false;
            for (double sign : {1.0, -1.0}) {
                for (int fixed = 0; fixed < 2 && !done; ++fixed) {
                    Problem p(spec, BoundaryKind::RingHopf, next);
                    Eigen::VectorXd u = c.u;
                    u(2) = sign * omega;
                    const CorrectorResult cr = correct(p, u, Eigen::VectorXd::Unit(3, fixed), u(fixed));
                    if (!converged(cr.status) || (u.head(2) - c.u.head(2)).norm() > 1e-4 || sign * u(2) <= 0.0) continue;
                    Eigen::VectorXd t;
                    if (!tangent(p, u, Eigen::VectorXd(), t)) continue;
                    for (double d : {1.0, -1.0}) {
                        Eigen::VectorXd v = u + 1e-6 * d * t;
                        const Eigen::VectorXd dir = d * t;
                        if (!converged(correct(p, v, dir, dir.dot(v)).status) || !ok_at(next, v)) continue;
                        ++set.corners;
                        done = trace_arc(next, v, dir, false, &u);
                        break;
                    }
                }
                if (done) break;
            }
        }
    };

    // frequencies where |f_m(i w)| has its smallest local minima at a point (signed: mode m's
    // crossings at w < 0 are mode N - m's at -w), for a seed whose root frequency is unknown
    auto frequency_guesses = [&](int mode, const Eigen::VectorXd& at) {
        const Problem p(spec, BoundaryKind::RingHopf, mode);
        constexpr int samples = 800;
        std::vector<std::pair<double, double>> values;  // (w, |f|) on w = +-1e-3 .. +-50, geometric
        Eigen::VectorXd u = at, f;
        for (int side = -1; side <= 1; side += 2)
            for (int k = 0; k < samples; ++k) {
                u(2) = side * 1e-3 * std::pow(5e4, k / (samples - 1.0));
                values.emplace_back(u(2), p.residual(u, f) ? f.norm() : std::numeric_limits<double>::infinity());
            }
        std::vector<std::pair<double, double>> minima;  // (|f|, w)
        for (int side = 0; side < 2; ++side)
            for (int k = 1; k + 1 < samples; ++k) {
                const auto& v = values[static_cast<std::size_t>(side * samples + k)];
                if (v.second < values[static_cast<std::size_t>(side * samples + k - 1)].second &&
                    v.second <= values[static_cast<std::size_t>(side * samples + k + 1)].second)
                    minima.emplace_back(v.second, v.first);
            }
        std::sort(minima.begin(), minima.end());
        std::vector<double> out;
        for (std::size_t i = 0; i < minima.size() && i < 4; ++i) out.push_back(minima[i].second);
        return out;
    };

    // seeds: grid edges with unstable ring roots at one end only (both ends certified); the mode is the
    // abscissa mode at the unstable end, the frequency its root's
    for (int iy = 0; iy < ny; ++iy)
        for (int ix = 0; ix < nx; ++ix)
            for (int dir = 0; dir < 2; ++dir) {
                const int jx = ix + (dir == 0), jy = iy + (dir == 1);
                if (jx >= nx || jy >= ny) continue;
                const SweepPoint &a = sweep.at(ix, iy), &b = sweep.at(jx, jy);
                // unstable: a root right of the marginal band (a marginal point is on the stable side:
                // a huge ring's smallest wave numbers have roots within rounding of the axis)
                if (!a.certified || !b.certified || (a.unstable_roots > 0) == (b.unstable_roots > 0)) continue;
                const SweepPoint& unstable = a.unstable_roots > 0 ? a : b;
                ++set.seeds;
                const double ex0 = ix / (nx - 1.0), ey0 = iy / (ny - 1.0), ex1 = jx / (nx - 1.0), ey1 = jy / (ny - 1.0);
                // already crossed by an arc?
                bool known = false;
                for (std::size_t ci = first_arc; ci < set.curves.size() && !known; ++ci) {
                    const auto& pts = set.curves[ci].points;
                    for (std::size_t i = 0; i + 1 < pts.size() && !known; ++i)
                        known = segments_meet(ex0, ey0, ex1, ey1, frame.X(pts[i].x), frame.Y(pts[i].y), frame.X(pts[i + 1].x), frame.Y(pts[i + 1].y));
                }
                // or near an arc of the same mode (the polyline's chords may pass a grid point that lies
                // within their sag of the curve on the wrong side)
                const Problem same(spec, BoundaryKind::RingHopf, unstable.abscissa_mode);
                const double sx = ex0 + 0.5 * (ex1 - ex0), sy = ey0 + 0.5 * (ey1 - ey0);
                for (std::size_t i = 0; i < arc_mode.size() && !known; ++i) {
                    if (arc_mode[i] != unstable.abscissa_mode) continue;
                    const auto& pts = set.curves[first_arc + i].points;
                    for (std::size_t k = 0; k + 1 < pts.size() && !known; ++k) known = segment_distance(sx, sy, pts[k], pts[k + 1], same) < 0.75 * cell;
                }
                if (known) continue;
                const int mode = unstable.abscissa_mode;
                if (mode < 0) {
                    ++set.rejected;
                    continue;
                }
                const double sa = a.spectral_abscissa, sb = b.spectral_abscissa;
                const double s = std::isfinite(sa) && std::isfinite(sb) && sa != sb ? std::clamp(sa / (sa - sb), 0.0, 1.0) : 0.5;
                Eigen::VectorXd start(3);
                start << ex0 + s * (ex1 - ex0), ey0 + s * (ey1 - ey0), 0.0;
                bool traced = false, corrected = false;
                int seed_mode = mode;
                double seed_omega = unstable.abscissa_omega;
                // the abscissa mode at the unstable end need not be the first to cross (a huge ring's
                // smallest wave numbers): off the envelope, the mode rightmost there is tried next
                for (int attempt = 0; attempt < 40 && !traced; ++attempt) {
                    int next = -1;
                    double next_omega = 0.0;
                    std::vector<double> guesses;
                    if (seed_omega > 0.0) guesses = {seed_omega, -seed_omega};
                    bool scanned = false;
                    for (std::size_t gi = 0; gi < guesses.size() || !scanned; ++gi) {
                        if (gi == guesses.size()) {  // the root's frequency failed (or is 0: a real root): scan
                            scanned = true;
                            if (next >= 0) break;  // it was right, the mode was not
                            const std::vector<double> more = frequency_guesses(seed_mode, start);
                            guesses.insert(guesses.end(), more.begin(), more.end());
                            if (gi == guesses.size()) break;
                        }
                        const double sign = guesses[gi] > 0.0 ? 1.0 : -1.0;
                        Problem p(spec, BoundaryKind::RingHopf, seed_mode);
                        Eigen::VectorXd u = start;
                        u(2) = guesses[gi];
                        const int fixed = dir == 0 ? 1 : 0;
                        const CorrectorResult cr = correct(p, u, Eigen::VectorXd::Unit(3, fixed), u(fixed));
                        if (!converged(cr.status) || !inside(u) || (u.head(2) - start.head(2)).norm() > 2.0 * cell || sign * u(2) <= 0.0) continue;
                        corrected = true;
                        if (!ok_at(seed_mode, u)) {
                            if (next >= 0) continue;
                            const Linearisation lin = model_at(spec, frame.x(u(0)), frame.y(u(1)))->linearise();
                            const RingWindingResult w = analyse_ring_winding(lin, cars);
                            if (w.status == Status::Converged && w.verdict == Verdict::Unstable && w.abscissa_mode >= 0 &&
                                w.abscissa_mode != std::min(seed_mode, cars - seed_mode)) {
                                next = w.abscissa_mode;
                                next_omega = std::abs(w.abscissa_root.imag());
                            }
                            continue;
                        }
                        Eigen::VectorXd t;
                        if (!tangent(p, u, Eigen::VectorXd(), t)) continue;
                        traced = trace_arc(seed_mode, u, t, true, nullptr);
                        if (traced) break;
                    }
                    if (traced || next < 0) break;
                    seed_mode = next;
                    seed_omega = next_omega;
                }
                if (!traced) ++(corrected ? set.off_envelope : set.rejected);
                follow_corners();
            }
}

}  // namespace

BoundarySet trace_boundaries(const SweepResult& sweep, const BoundaryOptions& options) {
    options.validate();
    const RingCurves ring_curves = resolve_ring_curves(options.ring_curves, sweep.spec);
    if (sweep.spec.cars > 0 && sweep.modes == 0 && ring_curves == RingCurves::All) {
        // a winding sweep holds no per-mode roots; the ring Hopf seeds of every mode need them
        SweepSpec spec = sweep.spec;
        spec.ring_method = "modes";
        return trace_boundaries(run_sweep(spec), options);
    }
    const bool envelope = ring_curves == RingCurves::Envelope && sweep.spec.cars > 0;
    const auto t0 = std::chrono::steady_clock::now();
    const SweepSpec& spec = sweep.spec;
    const int nx = spec.x.count, ny = spec.y.count;
    BoundarySet set;
    set.ring_curves = ring_curves;

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
    for (int m = 0; m < sweep.modes && !envelope; ++m) {
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
    // the curves traced so far by (kind, the seed's mode before relabelling): a seed is compared
    // with its own kind and mode only (a ring of 10^5 cars has 5 10^4 modes' curves)
    std::map<std::pair<int, int>, std::vector<std::size_t>> traced;
    long done = 0;
    for (const Seed& sd : seeds) {
        if (options.progress) options.progress(done, static_cast<long>(seeds.size()));
        ++done;
        Problem p(spec, sd.kind, sd.mode);
        // already on a traced curve of the same kind and mode?
        bool known = false;
        const auto key = std::make_pair(static_cast<int>(sd.kind), sd.mode);
        for (std::size_t ci : traced[key]) {
            const auto& c = set.curves[ci];
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
        append_branches(curve, p, bwd, fwd);
        // a ring crossing at negative frequency is the conjugate mode's at positive frequency
        if (curve.kind == BoundaryKind::RingHopf && curve.mode > 0 && !curve.points.empty() &&
            curve.points[curve.points.size() / 2].omega < 0.0) {
            curve.mode = spec.cars - curve.mode;
            for (auto& bp : curve.points) bp.omega = -bp.omega;
        }
        traced[key].push_back(set.curves.size());
        set.curves.push_back(std::move(curve));
    }
    if (options.progress && !seeds.empty()) options.progress(static_cast<long>(seeds.size()), static_cast<long>(seeds.size()));
    if (envelope) trace_envelope(sweep, options, set);
    set.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return set;
}

}  // namespace ddemap
