#include "ddemap/analysis/bifurcation/bistability.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <limits>
#include <numeric>
#include <set>
#include <tuple>
#include <stdexcept>
#include <utility>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

/// Sets a parameter for the lifetime of the guard and restores its value after.
class ParameterGuard {
public:
    ParameterGuard(NonlinearDDE& s, std::string name) : m_system(s), m_name(std::move(name)) {
        m_value = s.parameter_values()[static_cast<std::size_t>(s.parameter_index(m_name))];
    }
    ParameterGuard(const ParameterGuard&) = delete;
    ParameterGuard& operator=(const ParameterGuard&) = delete;
    ~ParameterGuard() { m_system.set_parameter(m_name, m_value); }
    double held() const { return m_value; }

private:
    NonlinearDDE& m_system;
    std::string m_name;
    double m_value = 0.0;
};

/// A one-parameter slice at p2: the equilibrium branch in p1 and the orbit branches from its Hopf points.
struct Slice {
    double par2 = 0.0;
    EquilibriumBranch eq;
    std::vector<OrbitBranch> orbits;
    std::vector<double> orbit_start;  ///< p1 of the Hopf point each orbit branch starts from
    Status status = Status::Converged;
    std::string message;
};

using Polyline = std::vector<std::pair<double, double>>;  // (p1, p2)

/// p1 where the polyline crosses p2 = y (half-open rule: an end exactly on y counts once), with `id`.
void crossings(const Polyline& l, double y, std::vector<std::pair<double, int>>& out, int id) {
    for (std::size_t i = 0; i + 1 < l.size(); ++i) {
        const auto& a = l[i];
        const auto& b = l[i + 1];
        if ((a.second <= y) == (b.second <= y)) continue;
        out.emplace_back(a.first + (b.first - a.first) * (y - a.second) / (b.second - a.second), id);
    }
}
void crossings(const Polyline& l, double y, std::vector<double>& out) {
    std::vector<std::pair<double, int>> x;
    crossings(l, y, x, 0);
    for (const auto& c : x) out.push_back(c.first);
}

/// Whether the vertical segment p1 = x, p2 in [y0, y1] crosses one of the lines.
bool crosses_vertical(const std::vector<Polyline>& lines, double x, double y0, double y1) {
    for (const Polyline& l : lines)
        for (std::size_t i = 0; i + 1 < l.size(); ++i) {
            const auto& a = l[i];
            const auto& b = l[i + 1];
            if ((a.first <= x) == (b.first <= x)) continue;
            const double y = a.second + (b.second - a.second) * (x - a.first) / (b.first - a.first);
            if (y >= y0 && y <= y1) return true;
        }
    return false;
}

/// Whether the segment (x0, y0)-(x1, y1) crosses one of the lines (proper or touching).
bool crosses_segment(const std::vector<Polyline>& lines, double x0, double y0, double x1, double y1) {
    auto orient = [](double ax, double ay, double bx, double by, double cx, double cy) {
        const double v = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
        return v > 0.0 ? 1 : v < 0.0 ? -1 : 0;
    };
    for (const Polyline& l : lines)
        for (std::size_t i = 0; i + 1 < l.size(); ++i) {
            const auto& a = l[i];
            const auto& b = l[i + 1];
            const int o1 = orient(x0, y0, x1, y1, a.first, a.second), o2 = orient(x0, y0, x1, y1, b.first, b.second);
            const int o3 = orient(a.first, a.second, b.first, b.second, x0, y0), o4 = orient(a.first, a.second, b.first, b.second, x1, y1);
            if (o1 * o2 <= 0 && o3 * o4 <= 0 && !(o1 == 0 && o2 == 0)) return true;
        }
    return false;
}

struct UnionFind {
    std::vector<int> parent;
    int add() {
        parent.push_back(static_cast<int>(parent.size()));
        return parent.back();
    }
    int find(int i) {
        while (parent[static_cast<std::size_t>(i)] != i) i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
        return i;
    }
    void unite(int a, int b) { parent[static_cast<std::size_t>(find(a))] = find(b); }
};

/// A point of a branch in order along it: a regular point with its verdict, or a special point
/// (a Hopf point, a fold, a period doubling, a torus bifurcation) where the verdict may change.
struct BranchNode {
    double order = 0.0;  ///< position along the branch (a special point after point i: i + 0.5)
    double par = 0.0;
    enum Kind { Stable, Unstable, Undecided, Special } kind = Special;
};

/// Whether the branch has a stable part over p1 = m: 1 when some piece between consecutive nodes
/// around m is stable (its regular ends stable; a special end bounds the piece and takes the
/// verdict of the other, since between a regular point and the next special point nothing
/// changes: every crossing of a step is a located special point), 0 when none is, -1 when none is
/// stable and some piece around m has no verdict (an undecided end, or two special ends: two
/// changes within one step, the verdict between them unknown; so is a piece ending at one of
/// several special points of one step, whose order along it is not known).
int stable_over(std::vector<BranchNode> nodes, double m) {
    std::stable_sort(nodes.begin(), nodes.end(), [](const BranchNode& a, const BranchNode& b) { return a.order < b.order; });
    // several special points within one step: their order along it is not known, so no piece
    // that ends at one of them has a verdict
    auto crowded = [&](std::size_t i) {
        return nodes[i].kind != BranchNode::Stable && nodes[i].kind != BranchNode::Unstable &&
               ((i > 0 && nodes[i - 1].order == nodes[i].order) || (i + 1 < nodes.size() && nodes[i + 1].order == nodes[i].order));
    };
    bool unknown = false;
    for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
        const BranchNode &a = nodes[i], &b = nodes[i + 1];
        if ((a.par - m) * (b.par - m) > 0.0) continue;
        if (a.kind == BranchNode::Undecided || b.kind == BranchNode::Undecided || (a.kind == BranchNode::Special && b.kind == BranchNode::Special) ||
            crowded(i) || crowded(i + 1))
            unknown = true;
        else if (a.kind != BranchNode::Unstable && b.kind != BranchNode::Unstable)
            return 1;
    }
    return unknown ? -1 : 0;
}

}  // namespace

bool BistabilityOptions::is_valid(std::string* why) const {
    const char* w = nullptr;
    if (parameter.empty() || parameter2.empty()) w = "parameter, parameter2: expected two names";
    else if (parameter == parameter2) w = "parameter2: expected a parameter other than the first";
    else if (!std::isfinite(from) || !std::isfinite(to) || !(from < to)) w = "from, to: expected finite values with from < to";
    else if (!std::isfinite(from2) || !std::isfinite(to2) || !(from2 < to2)) w = "from2, to2: expected finite values with from2 < to2";
    else if (degree < 1 || degree > 20) w = "degree: expected an integer between 1 and 20";
    else if (intervals < 2 || intervals > 100000) w = "intervals: expected an integer between 2 and 100000";
    else if (max_points < 2) w = "max_points: expected an integer >= 2";
    else if (rows < 4 || rows > 100000) w = "rows: expected an integer between 4 and 100000";
    if (w && why) *why = w;
    return w == nullptr;
}

BistabilityChart bistability_chart(NonlinearDDE& system, const Eigen::VectorXd& guess, const BistabilityOptions& o) {
    std::string why;
    if (!o.is_valid(&why)) throw std::invalid_argument("bistability options: " + why);
    system.parameter_index(o.parameter);  // unknown names: std::invalid_argument
    const ParameterGuard guard(system, o.parameter2);
    const double held = guard.held();
    if (!(held >= o.from2 && held <= o.to2))
        throw std::invalid_argument("bistability: " + o.parameter2 + " = " + detail::format_number(held) + " lies outside its range [" +
                                    detail::format_number(o.from2) + ", " + detail::format_number(o.to2) + "]");
    BistabilityChart chart;
    chart.parameter = o.parameter;
    chart.parameter2 = o.parameter2;
    chart.from = o.from;
    chart.to = o.to;
    chart.from2 = o.from2;
    chart.to2 = o.to2;
    const double width = o.to - o.from, height = o.to2 - o.from2;
    long stages = 0;
    const long stage_bound = 8L + 3L * o.rows;
    auto report = [&](double p) {
        if (o.progress) o.progress(++stages, stage_bound, p);
    };
    // within a stage: every point of its curves and branches reports the stages done so far and
    // where it is (the printer shows a line every few seconds), so a long stage is not silent
    const BranchProgress beat = [&](long, long, double p) {
        if (o.progress) o.progress(stages, stage_bound, p);
    };
    auto fail = [&](Status s, const std::string& m) {
        if (chart.status == Status::Converged) {
            chart.status = s;
            chart.message = m;
        }
    };

    // 1. the Hopf curves through the Hopf points at the held p2
    HopfCurveOptions ho;
    ho.branch.parameter = o.parameter;
    ho.branch.from = o.from;
    ho.branch.to = o.to;
    ho.parameter2 = o.parameter2;
    ho.from2 = o.from2;
    ho.to2 = o.to2;
    ho.continuation.max_points = o.max_points;
    ho.branch.before_roots = o.before_roots;
    if (o.progress) {
        ho.progress = beat;
        ho.branch.progress = beat;
    }
    chart.hopf = hopf_curves(system, guess, ho);
    if (chart.hopf.status != Status::Converged) fail(chart.hopf.status, "the Hopf curves: " + chart.hopf.message);
    report(o.from);

    PeriodicOrbitOptions po;
    po.parameter = o.parameter;
    po.from = o.from;
    po.to = o.to;
    po.degree = o.degree;
    po.intervals = o.intervals;
    po.max_points = o.max_points;
    if (o.progress) po.progress = beat;
    OrbitFoldCurveOptions fo;
    fo.orbit = po;
    // the fold curves only bound the cells: their points' multipliers (a certificate of `orbits
    // --par2`, one dense monodromy eigenproblem per point, most of the time on longer rings) are
    // not computed; |g| and the residual certify them
    fo.orbit.floquet = false;
    // and their steps are measured in units of the state's size (the norm measures the profile in
    // the system's units: the fold curve of a ring of speeds and gaps of 20-30 m, whose waves swing
    // by 10-40 m/s, took 400 points of 0.1 m/s for a tenth of its box)
    fo.orbit.max_step *= std::max(1.0, guess.cwiseAbs().maxCoeff());
    fo.parameter2 = o.parameter2;
    fo.from2 = o.from2;
    fo.to2 = o.to2;

    // a slice at p2 (the system's p2 set to it)
    auto slice_at = [&](double p2) {
        Slice s;
        s.par2 = p2;
        system.set_parameter(o.parameter2, p2);
        EquilibriumBranchOptions eo;
        eo.parameter = o.parameter;
        eo.from = o.from;
        eo.to = o.to;
        eo.roots.count = 2;
        if (o.progress) eo.progress = beat;
        s.eq = equilibrium_branch(system, guess, eo);
        if (s.eq.status != Status::Converged) {
            s.status = s.eq.status;
            s.message = "the equilibrium branch at " + o.parameter2 + " = " + detail::format_number(p2) + ": " + s.eq.message;
        }
        // the orbits are followed beyond the box by half its width on either side: a branch that
        // leaves the box through a face may turn at a fold outside it and come back (the stable
        // large waves of the ov ring return so from a fold below the box's headways); what fails
        // outside the box does not make the slice undecided
        PeriodicOrbitOptions so = po;
        so.from = o.from - 0.5 * width;
        so.to = o.to + 0.5 * width;
        for (const HopfPoint& h : s.eq.hopf) {
            if (h.status != Status::Converged || !(h.omega > 0.0)) continue;
            // a branch from an earlier Hopf point that ended at this one is its branch too
            bool reached = false;
            for (const OrbitBranch& b : s.orbits)
                reached = reached || (b.stop == "hopf" && !b.points.empty() && std::abs(b.points.back().par - h.par) < 0.02 * width);
            if (reached) continue;
            s.orbits.push_back(orbit_branch_from_hopf(system, h, so));
            s.orbit_start.push_back(h.par);
            report(h.par);
            const OrbitBranch& b = s.orbits.back();
            const bool outside = !b.points.empty() && (b.points.back().par < o.from || b.points.back().par > o.to);
            if (b.status != Status::Converged && !outside && s.status == Status::Converged) {
                s.status = b.status;
                s.message = "the orbits from the Hopf point at " + o.parameter + " = " + detail::format_number(h.par) + ", " + o.parameter2 + " = " +
                            detail::format_number(p2) + ": " + b.message;
            }
        }
        ++chart.slices;
        return s;
    };

    auto hopf_lines = [&] {
        std::vector<Polyline> out;
        for (const HopfCurve& c : chart.hopf.curves) {
            Polyline l;
            for (const HopfCurvePoint& q : c.points) l.emplace_back(q.par, q.par2);
            out.push_back(std::move(l));
        }
        return out;
    };
    // an end of a fold curve at a generalised Hopf point (stop "hopf": its orbits shrink, and its
    // last point lies within the fold system's reach of the point, ~a^2 away) is joined to the
    // located point within 2 % of the box, so that the curve meets the Hopf curve there
    auto generalised_near = [&](double p1, double p2, std::pair<double, double>& at) {
        double best = 0.02;
        for (const HopfCurve& h : chart.hopf.curves)
            for (const GeneralisedHopfPoint& g : h.generalised) {
                const double d = std::hypot((g.par - p1) / width, (g.par2 - p2) / height);
                if (g.status == Status::Converged && d < best) {
                    best = d;
                    at = {g.par, g.par2};
                }
            }
        return best < 0.02;
    };
    auto fold_lines = [&] {
        std::vector<Polyline> out;
        for (const OrbitFoldCurve& c : chart.folds) {
            Polyline l;
            for (const OrbitFoldCurvePoint& q : c.points) l.emplace_back(q.par, q.par2);
            std::pair<double, double> g;
            if (!l.empty() && c.stop_backward == "hopf" && generalised_near(l.front().first, l.front().second, g)) l.insert(l.begin(), g);
            if (!l.empty() && c.stop_forward == "hopf" && generalised_near(l.back().first, l.back().second, g)) l.push_back(g);
            out.push_back(std::move(l));
        }
        return out;
    };
    // whether p1 at p2 lies on one of the lines (within 1 % of the box's width)
    auto on_lines = [&](const std::vector<Polyline>& lines, double p1, double p2) {
        std::vector<double> x;
        for (const Polyline& l : lines) crossings(l, p2, x);
        for (double v : x)
            if (std::abs(v - p1) <= 0.01 * width) return true;
        return false;
    };
    // whether the fold f of an orbit branch at p2 lies on a traced fold curve: a crossing of p2
    // within 1 % of the box's width in p1 and 1 % in the period (two folds of one branch can be
    // closer in p1 than that, as near a cusp of folds, but differ in their orbits)
    auto on_fold_curve = [&](const OrbitFold& f, double p2) {
        for (const OrbitFoldCurve& c : chart.folds)
            for (std::size_t i = 0; i + 1 < c.points.size(); ++i) {
                const OrbitFoldCurvePoint &a = c.points[i], &b = c.points[i + 1];
                if ((a.par2 <= p2) == (b.par2 <= p2)) continue;
                const double t = (p2 - a.par2) / (b.par2 - a.par2);
                const double p1 = a.par + t * (b.par - a.par), period = a.orbit.period + t * (b.orbit.period - a.orbit.period);
                if (std::abs(p1 - f.par) <= 0.01 * width && std::abs(period - f.period) <= 0.01 * f.period) return true;
            }
        return false;
    };
    auto trace_fold = [&](const OrbitFold& f, double p2) {
        system.set_parameter(o.parameter2, p2);
        chart.folds.push_back(orbit_fold_curve(system, f, fo));
        report(f.par);
        const OrbitFoldCurve& c = chart.folds.back();
        if (c.status != Status::Converged)
            fail(c.status, "the fold curve through " + o.parameter + " = " + detail::format_number(f.par) + ": " + c.message);
        // an end where the orbits shrank must be at a located generalised Hopf point (joined to it
        // below): else the curve's rest, and the cells it bounds, are unknown
        std::pair<double, double> g;
        for (int end = 0; end < 2 && !c.points.empty(); ++end) {
            const OrbitFoldCurvePoint& q = end == 0 ? c.points.front() : c.points.back();
            if ((end == 0 ? c.stop_backward : c.stop_forward) == "hopf" && !generalised_near(q.par, q.par2, g))
                fail(Status::NumericalIssue, "the fold curve through " + o.parameter + " = " + detail::format_number(f.par) + " ends at (" +
                                                 detail::format_number(q.par) + ", " + detail::format_number(q.par2) +
                                                 ") where its orbits shrink, but no generalised Hopf point was located there");
        }
    };
    // where Hopf curve k crosses the line p2 = y: the chord's crossing corrected onto the curve (the
    // Hopf point in p1 at that p2, Newton from the chord's x, p1 and omega; the chord itself where
    // that fails or moves by more than 1 % of the box). A chord of a curve with steps of a few % of
    // the box is off it by ~1e-4 of the box, wider than a band between the Hopf curve and a fold
    // curve born at a generalised Hopf point with a small L2 (7e-5 on the acc ring): the order of
    // the crossings on the line, so the cells, would be wrong. Cached by (curve, segment, line).
    const int p1_index = system.parameter_index(o.parameter);
    std::map<std::tuple<std::size_t, std::size_t, double>, double> hopf_cache;
    auto hopf_crossings = [&](std::size_t k, double y, std::vector<std::pair<double, int>>& out) {
        const std::vector<HopfCurvePoint>& pts = chart.hopf.curves[k].points;
        for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
            const HopfCurvePoint &a = pts[i], &b = pts[i + 1];
            if ((a.par2 <= y) == (b.par2 <= y)) continue;
            auto found = hopf_cache.find({k, i, y});
            if (found == hopf_cache.end()) {
                const double t = (y - a.par2) / (b.par2 - a.par2);
                const double chord = a.par + t * (b.par - a.par);
                double p1 = chord;
                if (a.x.size() == b.x.size() && a.x.size() > 0) {
                    system.set_parameter(o.parameter2, y);
                    const HopfPoint h = correct_hopf(system, p1_index, a.x + t * (b.x - a.x), chord, a.omega + t * (b.omega - a.omega));
                    // (the same curve: omega as interpolated, not a neighbouring mode's)
                    const double omega = a.omega + t * (b.omega - a.omega);
                    if (h.status == Status::Converged && std::abs(h.par - chord) <= 0.01 * width && std::abs(h.omega - omega) <= 0.01 * omega) p1 = h.par;
                }
                found = hopf_cache.emplace(std::make_tuple(k, i, y), p1).first;
            }
            out.emplace_back(found->second, static_cast<int>(k));
        }
    };
    // traces the curves through the folds and Hopf points of a slice that lie on none traced;
    // returns whether it traced any
    auto trace_new = [&](const Slice& s) {
        bool any = false;
        for (const HopfPoint& h : s.eq.hopf) {
            if (h.status != Status::Converged || !(h.omega > 0.0) || on_lines(hopf_lines(), h.par, s.par2)) continue;
            system.set_parameter(o.parameter2, s.par2);
            chart.hopf.curves.push_back(hopf_curve(system, h, ho));
            report(h.par);
            if (chart.hopf.curves.back().status != Status::Converged)
                fail(chart.hopf.curves.back().status, "the Hopf curve through " + o.parameter + " = " + detail::format_number(h.par) + ": " +
                                                          chart.hopf.curves.back().message);
            any = true;
        }
        for (const OrbitBranch& b : s.orbits)
            for (const OrbitFold& f : b.folds) {
                if (!f.located || f.par < o.from || f.par > o.to || on_fold_curve(f, s.par2)) continue;  // (the slices' orbits run beyond the box)
                trace_fold(f, s.par2);
                any = true;
            }
        return any;
    };
    // the fold curves born at the generalised Hopf points: where L2 != 0 a curve of folds of
    // orbits starts at the point, on the side of the Hopf curve where L1 L2 < 0 (the orbits from a
    // Hopf point there turn back at an amplitude ~ sqrt(-L1 / (2 L2)), in p1 ~ L1^2 / (4 L2) from
    // it): a band along the Hopf curve too thin for slices to meet. From the Hopf curve's points on
    // that side (both sides when L2 has no value), nearest first but at least 1 % of the box from
    // the point (so that the fold lies beyond the branch's first orbit; the farthest one when none
    // is), up to 3 of them: the orbit branch from the Hopf point there (at most 150 orbits), whose
    // first fold must lie in the box, and the curves through its folds. Where the Hopf curve goes
    // on beyond the point but none of them finds that fold, the chart is undecided. Returns
    // whether it traced any.
    std::set<std::pair<std::size_t, std::size_t>> seeded;  // (curve, generalised Hopf point)
    auto seed_generalised = [&] {
        bool any = false;
        for (std::size_t ci = 0; ci < chart.hopf.curves.size(); ++ci)
            for (std::size_t gi = 0; gi < chart.hopf.curves[ci].generalised.size(); ++gi) {
                if (!seeded.insert({ci, gi}).second) continue;
                const HopfCurve& c = chart.hopf.curves[ci];  // (only fold curves are added below)
                const GeneralisedHopfPoint& g = c.generalised[gi];
                if (g.status != Status::Converged) continue;
                const double l2 = g.normal_form.status == Status::Converged ? g.normal_form.l2 : std::numeric_limits<double>::quiet_NaN();
                const bool known = std::isfinite(l2) && l2 != 0.0;
                bool candidates = false, found = false;
                std::string why;  // what went wrong at the points tried
                for (int side : {-1, 1}) {
                    // the side's points with a decided L1 of the fold side's sign, in order from
                    // the point: those at least 1 % of the box away first, else the farthest
                    std::vector<std::size_t> far, near;
                    for (int j = side < 0 ? g.after : g.after + 1; j >= 0 && j < static_cast<int>(c.points.size()); j += side) {
                        const HopfCurvePoint& q = c.points[static_cast<std::size_t>(j)];
                        if (q.coefficients.status != Status::Converged) continue;
                        if (known && !(q.coefficients.l1 * l2 < 0.0)) break;  // the side without the fold curve (or past another such point)
                        (std::hypot((q.par - g.par) / width, (q.par2 - g.par2) / height) < 0.01 ? near : far).push_back(static_cast<std::size_t>(j));
                    }
                    if (far.empty() && !near.empty()) far.push_back(near.back());
                    if (far.size() > 3) far.resize(3);
                    candidates = candidates || !far.empty();
                    for (std::size_t j : far) {
                        if (found) break;
                        const HopfCurvePoint& q = c.points[j];
                        system.set_parameter(o.parameter2, q.par2);
                        const HopfPoint h = correct_hopf(system, p1_index, q.x, q.par, q.omega);
                        if (h.status != Status::Converged) {
                            why = "the Hopf point at " + o.parameter2 + " = " + detail::format_number(q.par2) + " did not converge";
                            continue;
                        }
                        PeriodicOrbitOptions so = po;
                        so.from = o.from - 0.5 * width;
                        so.to = o.to + 0.5 * width;
                        so.max_points = std::min(o.max_points, 150);
                        const OrbitBranch b = orbit_branch_from_hopf(system, h, so);
                        report(h.par);
                        // the branch's first fold is the one born at the generalised Hopf point
                        // (later ones may belong to other curves); it must lie in the box
                        const OrbitFold* first = nullptr;
                        for (const OrbitFold& f : b.folds)
                            if (!first || f.after < first->after) first = &f;
                        if (!first || !first->located || first->par < o.from || first->par > o.to) {
                            why = "the orbits from the Hopf point at " + o.parameter2 + " = " + detail::format_number(q.par2) +
                                  (b.status != Status::Converged ? " failed: " + b.message
                                   : !first                     ? " did not fold within " + std::to_string(so.max_points) + " orbits"
                                   : !first->located            ? " folded, but the fold was not located"
                                                                : " folded outside the box");
                            continue;
                        }
                        found = true;
                        for (const OrbitFold& f : b.folds) {
                            if (!f.located || f.par < o.from || f.par > o.to || on_fold_curve(f, q.par2)) continue;
                            trace_fold(f, q.par2);
                            any = true;
                        }
                    }
                }
                // a generic generalised Hopf point (L2 != 0, also when its value failed) has a fold
                // curve on one side: not finding it where the Hopf curve goes on is no verdict
                if (candidates && !found)
                    fail(Status::NumericalIssue, "no fold of orbits found beside the generalised Hopf point at " + o.parameter + " = " +
                                                     detail::format_number(g.par) + ", " + o.parameter2 + " = " + detail::format_number(g.par2) +
                                                     (known ? " although L2 = " + detail::format_number(l2) + " implies a curve of them there"
                                                            : " (L2 not computed), where a curve of them starts") +
                                                     (why.empty() ? std::string() : ": " + why));
            }
        return any;
    };

    // 2. the fold curves through the folds of the orbits at the held p2
    trace_new(slice_at(held));
    seed_generalised();

    // 3. and 4. cells and their verdicts, again while a slice meets a curve not traced
    std::map<int, Slice> slices;  // by line
    for (int round = 0; round < 4; ++round) {
        chart.rounds = round + 1;
        std::vector<Polyline> lines = hopf_lines();
        for (Polyline& l : fold_lines()) lines.push_back(std::move(l));
        UnionFind uf;
        struct Piece {
            int line, id;
            double lo, hi;
            int left, right;  // the curves (or faces, -1 and -2) that bound it
            /// per curve: the parity of its crossings of the line left of the piece
            std::vector<bool> side;
        };
        std::vector<Piece> pieces, previous;
        for (int r = 0; r < o.rows; ++r) {
            const double y = o.from2 + (r + 0.5) * height / o.rows;
            std::vector<std::pair<double, int>> x;
            for (std::size_t k = 0; k < lines.size(); ++k) {
                if (k < chart.hopf.curves.size()) hopf_crossings(k, y, x);
                else crossings(lines[k], y, x, static_cast<int>(k));
            }
            // (crossings left of the box count in the pieces' sides: a curve that leaves the box
            // through its left face does not change the side of the pieces right of it)
            // and so does a curve that ends on the left face, continued outside along the ray of
            // its last step (it was followed in the box only)
            std::vector<bool> side(lines.size(), false);
            for (const auto& v : x)
                if (!(v.first > o.from)) side[static_cast<std::size_t>(v.second)] = !side[static_cast<std::size_t>(v.second)];
            for (std::size_t k = 0; k < lines.size(); ++k) {
                const Polyline& l = lines[k];
                if (l.size() < 2) continue;
                for (int end = 0; end < 2; ++end) {
                    const auto& e = end == 0 ? l.front() : l.back();
                    const auto& before = end == 0 ? l[1] : l[l.size() - 2];
                    const double dy = e.second - before.second;
                    if (std::abs(e.first - o.from) <= 1e-9 * width && e.first < before.first && dy != 0.0 && (y - e.second) * dy > 0.0)
                        side[k] = !side[k];
                }
            }
            x.erase(std::remove_if(x.begin(), x.end(), [&](const std::pair<double, int>& v) { return !(v.first > o.from && v.first < o.to); }), x.end());
            x.emplace_back(o.from, -1);
            x.emplace_back(o.to, -2);
            std::sort(x.begin(), x.end());
            std::vector<Piece> row;
            for (std::size_t i = 0; i + 1 < x.size(); ++i) {
                if (x[i].second >= 0) side[static_cast<std::size_t>(x[i].second)] = !side[static_cast<std::size_t>(x[i].second)];
                if (!(x[i + 1].first > x[i].first)) continue;
                Piece p{r, uf.add(), x[i].first, x[i + 1].first, x[i].second, x[i + 1].second, side};
                // one cell with an overlapping piece of the line below when both are bounded by
                // the same two curves, or when a path between them crosses no curve: the vertical
                // segment in the middle of the overlap, or the segment between the two pieces'
                // middles. A curve that ends on another between the lines (a fold curve at a
                // generalised Hopf point), or runs between them nearly level, separates them. A
                // path that is not found makes two cells of one (each then decided on its own),
                // never one of two
                // (a thin slanted cell, as between a fold curve and the Hopf curve it touches,
                // moves by more than its width from line to line: its pieces need not overlap, so
                // the piece of the line below between the same two curves nearest it is joined).
                // Two pieces are joined only on the same side of every curve (the parity of its
                // crossings left of them): where two curves cross between the lines, the pieces
                // before and after the crossing between them lie on opposite sides of both, and
                // the thin cells there (a bistable band where a fold curve crosses the Hopf curve)
                // are not joined across it. A curve's turn in p2 keeps the parity; one that ends
                // between the lines splits a cell in two (each decided on its own)
                const Piece* same = nullptr;
                for (const Piece& q : previous)
                    if (q.left == p.left && q.right == p.right && q.side == p.side &&
                        (!same || std::abs(q.lo + q.hi - p.lo - p.hi) < std::abs(same->lo + same->hi - p.lo - p.hi)))
                        same = &q;
                if (same) uf.unite(p.id, same->id);
                for (const Piece& q : previous) {
                    if (!(q.lo < p.hi && p.lo < q.hi) || q.side != p.side) continue;
                    const double xm = 0.5 * (std::max(p.lo, q.lo) + std::min(p.hi, q.hi)), yq = y - height / o.rows;
                    if (!crosses_vertical(lines, xm, yq, y) || !crosses_segment(lines, 0.5 * (q.lo + q.hi), yq, 0.5 * (p.lo + p.hi), y))
                        uf.unite(p.id, q.id);
                }
                row.push_back(p);
            }
            pieces.insert(pieces.end(), row.begin(), row.end());
            previous = std::move(row);
        }
        std::map<int, std::size_t> index;  // root -> cell
        chart.cells.clear();
        std::vector<double> widest;
        std::vector<int> widest_line;
        for (const Piece& p : pieces) {
            const int root = uf.find(p.id);
            auto it = index.find(root);
            if (it == index.end()) {
                it = index.emplace(root, chart.cells.size()).first;
                chart.cells.emplace_back();
                widest.push_back(-1.0);
                widest_line.push_back(0);
            }
            BistabilityCell& c = chart.cells[it->second];
            const double y = o.from2 + (p.line + 0.5) * height / o.rows;
            c.intervals.push_back({y, p.lo, p.hi});
            if (p.hi - p.lo > widest[it->second]) {
                widest[it->second] = p.hi - p.lo;
                widest_line[it->second] = p.line;
                c.par = 0.5 * (p.lo + p.hi);
                c.par2 = y;
            }
        }
        bool traced = false;
        for (std::size_t k = 0; k < chart.cells.size(); ++k) {
            BistabilityCell& c = chart.cells[k];
            auto found = slices.find(widest_line[k]);
            if (found == slices.end()) {
                found = slices.emplace(widest_line[k], slice_at(c.par2)).first;
                traced = trace_new(found->second) || traced;
            }
            const Slice& s = found->second;
            const double m = c.par;
            // the equilibrium: a stable piece of the branch over m (between two branch points,
            // or a branch point and a Hopf point or fold next to it: a thin cell beside a curve
            // lies within one step of the branch)
            std::vector<BranchNode> nodes;
            for (std::size_t i = 0; i < s.eq.points.size(); ++i) {
                const EquilibriumPoint& a = s.eq.points[i];
                nodes.push_back({static_cast<double>(i), a.par,
                                 a.roots_status != Status::Converged ? BranchNode::Undecided : a.stable ? BranchNode::Stable : BranchNode::Unstable});
            }
            for (const HopfPoint& h : s.eq.hopf)
                nodes.push_back({h.after + 0.5, h.par, h.status == Status::Converged ? BranchNode::Special : BranchNode::Undecided});
            for (const FoldPoint& f : s.eq.folds)
                nodes.push_back({f.after + 0.5, f.par, f.status == Status::Converged ? BranchNode::Special : BranchNode::Undecided});
            const int eq = stable_over(nodes, m);
            c.equilibrium_stable = eq == 1;
            bool orbit_undecided = false;
            // a stable orbit: a stable piece of an orbit branch over m (its Hopf point, folds,
            // period doublings and tori bound the pieces)
            for (std::size_t k = 0; k < s.orbits.size(); ++k) {
                const OrbitBranch& b = s.orbits[k];
                nodes.clear();
                nodes.push_back({-0.5, s.orbit_start[k], BranchNode::Special});
                // a branch that ended at another Hopf point: that point bounds its last piece
                if (b.stop == "hopf" && !b.points.empty())
                    for (const HopfPoint& h : s.eq.hopf)
                        if (h.status == Status::Converged && std::abs(b.points.back().par - h.par) < 0.02 * width) {
                            nodes.push_back({b.points.size() - 0.5, h.par, BranchNode::Special});
                            break;
                        }
                for (std::size_t i = 0; i < b.points.size(); ++i)
                    nodes.push_back({static_cast<double>(i), b.points[i].par,
                                     !b.points[i].undecided.empty() ? BranchNode::Undecided : b.points[i].stable ? BranchNode::Stable : BranchNode::Unstable});
                // (a special point not located: its place is not known, its pieces have no verdict)
                for (const OrbitFold& f : b.folds) nodes.push_back({f.after + 0.5, f.par, f.located ? BranchNode::Special : BranchNode::Undecided});
                for (const OrbitCrossing& x : b.period_doublings)
                    nodes.push_back({x.after + 0.5, x.par, x.located ? BranchNode::Special : BranchNode::Undecided});
                for (const OrbitCrossing& x : b.tori) nodes.push_back({x.after + 0.5, x.par, x.located ? BranchNode::Special : BranchNode::Undecided});
                const int v = stable_over(nodes, m);
                if (v == 1) c.stable_orbit = true;
                else if (v < 0) orbit_undecided = true;
            }
            // no verdict: the equilibrium's, or no stable orbit found beside a piece without one
            const bool undecided = eq < 0 || (orbit_undecided && !c.stable_orbit);
            c.bistable = c.equilibrium_stable && c.stable_orbit;
            if (s.status != Status::Converged) {
                c.status = s.status;
                c.message = s.message;
            } else if (undecided) {
                c.status = Status::NumericalIssue;
                c.message = std::string(eq < 0 ? "the equilibrium" : "an orbit") + " at " + o.parameter + " = " + detail::format_number(m) + ", " +
                            o.parameter2 + " = " + detail::format_number(c.par2) +
                            " has no stability verdict (its roots or multipliers undecided, or two changes of stability within one step)";
            }
        }
        traced = seed_generalised() || traced;
        if (!traced) break;
        if (round == 3) fail(Status::MaxIterations, "slices still met curves not traced after 4 rounds: the cells may be cut wrongly");
    }
    for (const BistabilityCell& c : chart.cells)
        if (c.status != Status::Converged) fail(c.status, "a cell's verdict: " + c.message);
    if (chart.message.empty()) {
        const auto bistable = std::count_if(chart.cells.begin(), chart.cells.end(), [](const BistabilityCell& c) { return c.bistable; });
        chart.message = std::to_string(chart.hopf.curves.size()) + " Hopf curve(s), " + std::to_string(chart.folds.size()) + " fold curve(s) of orbits, " +
                        std::to_string(chart.cells.size()) + " cells (" + std::to_string(bistable) + " bistable) from " + std::to_string(chart.slices) +
                        " slices";
    }
    return chart;
}

}  // namespace ddemap
