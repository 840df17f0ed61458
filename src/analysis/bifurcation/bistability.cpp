#include "ddemap/analysis/bifurcation/bistability.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
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
    auto fold_lines = [&] {
        std::vector<Polyline> out;
        for (const OrbitFoldCurve& c : chart.folds) {
            Polyline l;
            for (const OrbitFoldCurvePoint& q : c.points) l.emplace_back(q.par, q.par2);
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
                if (!f.located || f.par < o.from || f.par > o.to || on_lines(fold_lines(), f.par, s.par2)) continue;  // (the slices' orbits run beyond the box)
                system.set_parameter(o.parameter2, s.par2);
                chart.folds.push_back(orbit_fold_curve(system, f, fo));
                report(f.par);
                if (chart.folds.back().status != Status::Converged)
                    fail(chart.folds.back().status, "the fold curve through " + o.parameter + " = " + detail::format_number(f.par) + ": " +
                                                        chart.folds.back().message);
                any = true;
            }
        return any;
    };

    // 2. the fold curves through the folds of the orbits at the held p2
    trace_new(slice_at(held));

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
        };
        std::vector<Piece> pieces, previous;
        for (int r = 0; r < o.rows; ++r) {
            const double y = o.from2 + (r + 0.5) * height / o.rows;
            std::vector<std::pair<double, int>> x;
            for (std::size_t k = 0; k < lines.size(); ++k) crossings(lines[k], y, x, static_cast<int>(k));
            x.erase(std::remove_if(x.begin(), x.end(), [&](const std::pair<double, int>& v) { return !(v.first > o.from && v.first < o.to); }), x.end());
            x.emplace_back(o.from, -1);
            x.emplace_back(o.to, -2);
            std::sort(x.begin(), x.end());
            std::vector<Piece> row;
            for (std::size_t i = 0; i + 1 < x.size(); ++i) {
                if (!(x[i + 1].first > x[i].first)) continue;
                Piece p{r, uf.add(), x[i].first, x[i + 1].first, x[i].second, x[i + 1].second};
                // one cell with an overlapping piece of the line below when both are bounded by
                // the same two curves, or when a path between them crosses no curve: the vertical
                // segment in the middle of the overlap, or the segment between the two pieces'
                // middles. A curve that ends on another between the lines (a fold curve at a
                // generalised Hopf point), or runs between them nearly level, separates them. A
                // path that is not found makes two cells of one (each then decided on its own),
                // never one of two
                // (a thin slanted cell, as between a fold curve and the Hopf curve it touches,
                // moves by more than its width from line to line: its pieces need not overlap, so
                // the piece of the line below between the same two curves nearest it is joined)
                const Piece* same = nullptr;
                for (const Piece& q : previous)
                    if (q.left == p.left && q.right == p.right &&
                        (!same || std::abs(q.lo + q.hi - p.lo - p.hi) < std::abs(same->lo + same->hi - p.lo - p.hi)))
                        same = &q;
                if (same) uf.unite(p.id, same->id);
                for (const Piece& q : previous) {
                    if (!(q.lo < p.hi && p.lo < q.hi)) continue;
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
            // the equilibrium: both branch points around m stable
            for (std::size_t i = 0; i + 1 < s.eq.points.size(); ++i) {
                const EquilibriumPoint &a = s.eq.points[i], &b = s.eq.points[i + 1];
                if ((a.par - m) * (b.par - m) <= 0.0 && a.stable && b.stable) c.equilibrium_stable = true;
            }
            // a stable orbit: two neighbouring orbits of a branch around m, both stable
            bool undecided = false;
            for (const OrbitBranch& b : s.orbits)
                for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
                    const PeriodicOrbit &a = b.points[i], &z = b.points[i + 1];
                    if ((a.par - m) * (z.par - m) > 0.0) continue;
                    if (!a.undecided.empty() || !z.undecided.empty()) undecided = true;
                    else if (a.stable && z.stable) c.stable_orbit = true;
                }
            c.bistable = c.equilibrium_stable && c.stable_orbit;
            if (s.status != Status::Converged) {
                c.status = s.status;
                c.message = s.message;
            } else if (undecided) {
                c.status = Status::NumericalIssue;
                c.message = "an orbit at " + o.parameter + " = " + detail::format_number(m) + ", " + o.parameter2 + " = " + detail::format_number(c.par2) +
                            " has no stability verdict";
            }
        }
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
