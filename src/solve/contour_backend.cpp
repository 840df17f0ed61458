// The contour backend of rightmost_roots: the argument principle on a scalar characteristic
// function D = det Delta (problem/characteristic_function.hpp). The strip floor alpha is lowered
// (bisection) until at least `count` zeros lie in [alpha, beta] x [-R(alpha), R(alpha)] (no root
// with Re >= alpha lies outside it, root_bounds.hpp); the rectangle is split into cells with
// their counts until each holds one zero, which Newton on D finds. The listed roots are then
// certified complete by the count.

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/internal/text.hpp"
#include "ddemap/solve/argument_principle.hpp"
#include "internal/backends.hpp"

namespace ddemap::detail {

namespace {

bool finite(cplx z) { return std::isfinite(z.real()) && std::isfinite(z.imag()); }

using Count = ZeroCount;

/// A cell of the search: [x0, x1] x [y0, y1], or for an axis cell [x0, x1] x [-y1, y1].
struct Cell {
    double x0, x1, y0, y1;
    bool axis;
    int zeros;
};

class Locator {
public:
    Locator(const CharacteristicFunction& det, const ContourRootOptions& o, const BranchProgress& progress)
        : m_det(det), m_o(o), m_progress(progress) {}

    /// Count of a cell (false when a zero lies on its boundary or a budget ran out).
    bool count(Cell& c) {
        if (exhausted()) return false;
        ++m_counts;
        const auto r = c.axis ? count_zeros_symmetric(m_det, c.x0, c.x1, c.y1, m_o.max_arg_step)
                              : count_zeros(m_det, c.x0, c.x1, c.y0, c.y1, m_o.max_arg_step);
        m_evaluations += r.evaluations;
        c.zeros = r.zeros;
        if (m_progress) m_progress(m_counts, m_o.max_cells, c.x0);  // may throw Cancelled (caught by rightmost_roots)
        return r.ok;
    }

    /// The cell-count or evaluation budget is used up.
    bool exhausted() const {
        return m_counts >= m_o.max_cells || static_cast<double>(m_evaluations) * m_det.evaluation_cost() > m_o.max_type_evaluations;
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

    /// Newton on D from z (the one Newton loop, step D/D'); true when converged.
    bool newton(cplx z, bool real, cplx& out, double& step_out) {
        out = z;
        const NewtonSummary s = ddemap::newton(
            out,
            [&](const cplx& x, cplx& dx) {
                const cplx d = m_det.log_derivative(x);
                if (d == 0.0) return NewtonStep::Singular;  // D' = 0: a critical point, not a root
                if (!finite(d)) return NewtonStep::Exact;   // D = 0 to working precision makes D'/D infinite
                dx = 1.0 / d;
                if (real) dx.imag(0.0);
                return NewtonStep::Ok;
            },
            m_o.newton);
        m_iterations += s.iterations;
        step_out = s.last_step;
        if (s.status == Status::NumericalIssue) return false;
        return step_out <= 1e-8 * scale_of(out);
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
    int iterations() const { return m_iterations; }
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

    const CharacteristicFunction& m_det;
    const ContourRootOptions& m_o;
    const BranchProgress& m_progress;
    int m_iterations = 0;
    std::vector<Found> m_found;
    int m_counts = 0;
    long m_evaluations = 0;
};

}  // namespace

std::string contour_why_not(const RootProblem& problem, const RootOptions& options) {
    if (!problem.characteristic)
        return "method 'contour' needs a scalar characteristic function det Delta (e.g. a ring whose cars react to one or two cars "
               "ahead); this problem has none: expected auto, dense or shift_invert";
    if (!problem.characteristic->is_real())
        return "method 'contour' counts zeros of a real characteristic function; this one is complex: expected auto or dense";
    if (options.degree > 0)
        return "degree = " + std::to_string(options.degree) +
               " with method 'contour': the product path has no collocation degree (it counts the zeros of det Delta); "
               "expected 0 (or the dense or shift_invert method)";
    return {};
}

RootWorkEstimate contour_estimate(const RootProblem& problem, const RootOptions& options) {
    // measured on rings of ACC cars (2 car types): about 100 counts and 7e5 evaluations of D for
    // the default count, whatever the ring's size; an evaluation costs about 0.3 us per unit of
    // evaluation_cost. More roots asked, more counts.
    const double cost = problem.characteristic ? problem.characteristic->evaluation_cost() : 1.0;
    const double scale = std::max(1.0, options.count / 7.0);
    RootWorkEstimate e;
    e.units = 100.0 * scale;
    e.seconds = 7e5 * scale * 3e-7 * cost;
    e.bytes = 1e7;
    std::ostringstream os;
    os.precision(3);
    os << "about " << e.units << " contour counts of det Delta";
    e.basis = os.str();
    return e;
}

RootResult contour_roots(const RootProblem& problem, const RootOptions& options) {
    const CharacteristicFunction& det = *problem.characteristic;
    const LinearDDE& dde = problem.dde;
    const RootBounds& bounds = dde.bounds();
    const double tau = dde.max_delay();
    const double beta = bounds.right_bound();
    RootResult result;
    result.right_bound = beta;
    Locator loc(det, options.contour, options.progress);
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
        result.status = loc.exhausted() ? Status::BudgetExhausted : Status::NumericalIssue;
        result.message = why;
        result.contour_counts = loc.counts();
        result.evaluations = loc.evaluations();
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
        if (!count_from(a_lo, lo)) return fail("the argument principle failed on a strip (Re >= " + format_number(a_lo) + ")");
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
        r.eigenvalue = f.value;
        r.newton_step = f.step;
        r.residual = relative_residual(dde, f.value, det.null_vector(f.value));
        result.roots.push_back(r);
        if (f.value.imag() > 0.0) {
            r.value = r.eigenvalue = std::conj(f.value);
            result.roots.push_back(r);
            listed += f.multiplicity;
        }
    }
    std::stable_sort(result.roots.begin(), result.roots.end(), rightmost_first);
    const std::vector<Root> all = result.roots;
    result.roots = cut_rightmost(all, options.count);
    if (result.roots.size() < all.size() && !result.roots.empty())
        result.strip_floor = std::max(result.strip_floor, result.roots.back().value.real());
    double max_residual = 0.0;
    int bad = 0;
    for (const auto& r : result.roots) {
        max_residual = std::max(max_residual, r.residual);
        bad += r.residual <= options.residual_tolerance ? 0 : 1;
    }
    result.contour_counts = loc.counts();
    result.evaluations = loc.evaluations();
    result.newton_iterations = loc.iterations();
    std::ostringstream os;
    os.precision(3);
    if (!located || listed != lo.zeros) {
        result.status = loc.exhausted() ? Status::BudgetExhausted : Status::NumericalIssue;
        os << "the argument principle counts " << lo.zeros << " roots with Re >= " << lo.x0 << " but " << listed
           << " were located (" << loc.counts() << " contour counts)";
    } else if (bad > 0 || clusters > 0) {
        result.status = Status::MaxDegreeReached;
        os << bad << " roots above the residual tolerance, " << clusters << " clusters of coincident roots";
    } else {
        os << "all " << lo.zeros << " roots of " << det.description() << " with Re >= " << lo.x0
           << " located (argument principle on [" << lo.x0 << ", " << beta << "] x [-" << lo.y1 << ", " << lo.y1
           << "], no root lies outside it; " << loc.counts() << " contour counts, " << loc.evaluations() << " evaluations"
           << det.cost_description() << "); each refined by Newton on D (max residual " << max_residual << ")";
    }
    result.message = os.str();
    return result;
}

}  // namespace ddemap::detail
