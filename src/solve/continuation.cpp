#include "ddemap/solve/continuation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>

#include "ddemap/solve/step_control.hpp"

namespace ddemap {

namespace {
constexpr double half_pi = 1.5707963267948966;
}  // namespace

bool ContinuationOptions::is_valid(std::string* why) const {
    const char* w = nullptr;
    std::string message;
    auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
    if (!positive(initial_step)) w = "initial_step: expected a finite value > 0";
    else if (!positive(max_step)) w = "max_step: expected a finite value > 0";
    else if (!positive(min_step)) w = "min_step: expected a finite value > 0";
    else if (!(min_step <= initial_step && initial_step <= max_step)) w = "initial_step: expected min_step <= initial_step <= max_step";
    else if (max_points < 2) w = "max_points: expected an integer >= 2";
    else if (!(std::isfinite(grow_factor) && grow_factor >= 1.0)) w = "grow_factor: expected a finite value >= 1";
    else if (grow_iterations < 0) w = "grow_iterations: expected an integer >= 0";
    else if (!positive(max_jump)) w = "max_jump: expected a finite value > 0";
    else if (!(max_angle > 0.0 && max_angle <= half_pi)) w = "max_angle: expected a value in (0, pi/2]";
    else if (!positive(event_tolerance)) w = "event_tolerance: expected a finite value > 0";
    else if (!newton.is_valid(&message)) message = "newton." + message;
    else if (lower.size() != 0 && lower.array().isNaN().any()) w = "lower: expected numbers (not NaN)";
    else if (upper.size() != 0 && upper.array().isNaN().any()) w = "upper: expected numbers (not NaN)";
    else if (lower.size() != 0 && upper.size() != 0 && lower.size() != upper.size()) w = "upper: expected as many entries as lower";
    else if (lower.size() != 0 && upper.size() != 0 && !(lower.array() <= upper.array()).all()) w = "lower: expected lower <= upper";
    else if (scale.size() != 0 && !(scale.array().isFinite().all() && (scale.array() > 0.0).all())) w = "scale: expected finite entries > 0";
    if (w) message = w;
    if (!message.empty() && why) *why = message;
    return message.empty();
}

std::string to_string(ContinuationStop s) {
    switch (s) {
        case ContinuationStop::MaxPoints: return "max_points";
        case ContinuationStop::Bound: return "bound";
        case ContinuationStop::TerminalEvent: return "terminal_event";
        case ContinuationStop::ClosedLoop: return "closed_loop";
        case ContinuationStop::LeftDomain: return "left_domain";
        case ContinuationStop::StepBelowMinimum: return "step_below_minimum";
        case ContinuationStop::TangentFailed: return "tangent_failed";
    }
    return "unknown";
}

bool central_difference_jacobian(const ContinuationProblem& problem, const Eigen::VectorXd& u, Eigen::MatrixXd& j,
                                 double relative_step) {
    const int m = static_cast<int>(u.size());
    j.resize(problem.equations(), m);
    for (int c = 0; c < m; ++c) {
        const double h = relative_step * std::max(1.0, std::abs(u(c)));
        Eigen::VectorXd up = u, um = u, fp, fm;
        up(c) += h;
        um(c) -= h;
        const bool plus = problem.residual(up, fp), minus = problem.residual(um, fm);
        if (plus && minus) {
            j.col(c) = (fp - fm) / (2.0 * h);
            continue;
        }
        // within h of the edge of the problem's domain (e.g. a gain of 0): the one-sided
        // second-order difference (-3 f(u) + 4 f(u + s h) - f(u + 2 s h)) / (2 s h), s = +-1
        if (!plus && !minus) return false;
        const double s = plus ? 1.0 : -1.0;
        Eigen::VectorXd u2 = u, f0, f2;
        u2(c) += 2.0 * s * h;
        if (!problem.residual(u, f0) || !problem.residual(u2, f2)) return false;
        j.col(c) = (4.0 * (plus ? fp : fm) - 3.0 * f0 - f2) / (2.0 * s * h);
    }
    return true;
}

CorrectorResult correct(const ContinuationProblem& problem, Eigen::VectorXd& u, const Eigen::VectorXd& a, double b,
                        const NewtonOptions& options) {
    const int m = problem.unknowns();
    if (u.size() != m || a.size() != m) throw std::invalid_argument("correct: expected u and a with n + 1 entries");
    Eigen::VectorXd f, rhs(m);
    Eigen::MatrixXd j, bordered(m, m);
    auto step = [&](const Eigen::VectorXd& x, Eigen::VectorXd& dx) {
        if (!problem.residual(x, f) || !problem.jacobian(x, j)) return NewtonStep::Singular;
        bordered.topRows(m - 1) = j;
        bordered.row(m - 1) = a.transpose();
        rhs.head(m - 1) = f;
        rhs(m - 1) = a.dot(x) - b;
        dx = bordered.fullPivLu().solve(rhs);
        return NewtonStep::Ok;
    };
    const NewtonSummary s = newton(u, step, options);
    CorrectorResult r;
    r.status = s.status;
    r.iterations = s.iterations;
    if (converged(r.status)) {
        if (problem.residual(u, f)) r.residual = f.norm();
        else r.status = Status::NumericalIssue;
    }
    return r;
}

bool tangent(const ContinuationProblem& problem, const Eigen::VectorXd& u, const Eigen::VectorXd& reference,
             Eigen::VectorXd& t) {
    Eigen::MatrixXd j;
    if (!problem.jacobian(u, j) || !j.allFinite()) return false;
    const int n = static_cast<int>(j.rows()), m = n + 1;
    Eigen::MatrixXd bordered(m, m);
    bordered.topRows(n) = j;
    if (reference.size() == m) {
        bordered.row(n) = reference.transpose();
        const Eigen::FullPivLU<Eigen::MatrixXd> lu(bordered);
        if (!lu.isInvertible()) return false;
        t = lu.solve(Eigen::VectorXd::Unit(m, n));
    } else {
        const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Eigen::MatrixXd(j.transpose()));
        if (qr.rank() < n) return false;
        t = qr.householderQ() * Eigen::VectorXd::Unit(m, n);
        bordered.row(n) = t.transpose();
        if (bordered.fullPivLu().determinant() < 0.0) t = -t;
    }
    const double size = t.norm();
    if (!(size > 0.0) || !std::isfinite(size)) return false;
    t /= size;
    return true;
}

namespace {

/// The problem in the unknowns v = u / c: F~(v) = F(c .* v), J~(v) = J(c .* v) diag(c).
class Scaled final : public ContinuationProblem {
public:
    Scaled(const ContinuationProblem& p, const Eigen::VectorXd& c) : m_p(p), m_c(c) {}
    int equations() const override { return m_p.equations(); }
    bool residual(const Eigen::VectorXd& v, Eigen::VectorXd& f) const override { return m_p.residual(u(v), f); }
    bool jacobian(const Eigen::VectorXd& v, Eigen::MatrixXd& j) const override {
        if (!m_p.jacobian(u(v), j)) return false;
        j = j * m_c.asDiagonal();
        return true;
    }
    bool in_domain(const Eigen::VectorXd& v) const override { return m_p.in_domain(u(v)); }
    Eigen::VectorXd u(const Eigen::VectorXd& v) const { return m_c.cwiseProduct(v); }
    /// a tangent in v as a unit tangent in u
    Eigen::VectorXd u_tangent(const Eigen::VectorXd& t) const {
        const Eigen::VectorXd w = m_c.cwiseProduct(t);
        return w / w.norm();
    }

private:
    const ContinuationProblem& m_p;
    Eigen::VectorXd m_c;
};

/// Distance to the start, in steps, below which a branch of more than 8 steps has closed.
constexpr double closure_fraction = 0.75;
constexpr int closure_min_steps = 8;
/// Slack (in scaled unknowns) for the other coordinates of a point located on a bound.
constexpr double bound_slack = 1e-12;

}  // namespace

ContinuationResult continue_branch(const ContinuationProblem& problem, const Eigen::VectorXd& u0,
                                   const Eigen::VectorXd& direction, const ContinuationOptions& options,
                                   const std::vector<TestFunction>& tests) {
    std::string why;
    if (!options.is_valid(&why)) throw std::invalid_argument(why);
    const int n = problem.equations(), m = n + 1;
    if (n < 1) throw std::invalid_argument("problem: expected at least one equation");
    const std::string entries = ": expected " + std::to_string(m) + " entries (the unknowns)";
    if (u0.size() != m) throw std::invalid_argument("u0" + entries);
    if (direction.size() != m) throw std::invalid_argument("direction" + entries);
    if (options.lower.size() != 0 && options.lower.size() != m) throw std::invalid_argument("lower" + entries);
    if (options.upper.size() != 0 && options.upper.size() != m) throw std::invalid_argument("upper" + entries);
    if (options.scale.size() != 0 && options.scale.size() != m) throw std::invalid_argument("scale" + entries);
    for (std::size_t k = 0; k < tests.size(); ++k)
        if (!tests[k].value) throw std::invalid_argument("tests[" + std::to_string(k) + "].value: expected a function");

    const double inf = std::numeric_limits<double>::infinity();
    const Eigen::VectorXd c = options.scale.size() ? options.scale : Eigen::VectorXd::Ones(m);
    const Scaled sp(problem, c);
    const Eigen::VectorXd lo = options.lower.size() ? Eigen::VectorXd(options.lower.cwiseQuotient(c)) : Eigen::VectorXd::Constant(m, -inf);
    const Eigen::VectorXd hi = options.upper.size() ? Eigen::VectorXd(options.upper.cwiseQuotient(c)) : Eigen::VectorXd::Constant(m, inf);
    const NewtonOptions& newton_options = options.newton;

    ContinuationResult r;
    auto finish = [&](ContinuationStop stop, Status status, std::string message) {
        r.stop = stop;
        r.status = status;
        r.message = std::move(message);
        return std::move(r);
    };
    auto add_point = [&](const Eigen::VectorXd& v, const Eigen::VectorXd& tv, double residual) {
        r.points.push_back(sp.u(v));
        r.tangents.push_back(sp.u_tangent(tv));
        r.max_residual = std::max(r.max_residual, residual);
        if (options.on_point && r.points.size() > 1) options.on_point(r.points.back());
    };
    auto test_values = [&](const Eigen::VectorXd& v, const Eigen::VectorXd& tv) {
        std::vector<double> g(tests.size());
        const Eigen::VectorXd uu = sp.u(v), tu = sp.u_tangent(tv);
        for (std::size_t k = 0; k < tests.size(); ++k) g[k] = tests[k].value(uu, tu);
        return g;
    };

    const Eigen::VectorXd start = u0.cwiseQuotient(c);
    Eigen::VectorXd u = start, t, f;
    if (!sp.residual(u, f)) return finish(ContinuationStop::TangentFailed, Status::NumericalIssue, "F cannot be evaluated at the start");
    if (!tangent(sp, u, direction.cwiseQuotient(c), t))
        return finish(ContinuationStop::TangentFailed, Status::NumericalIssue, "no tangent at the start (J rank deficient)");
    add_point(u, t, f.norm());
    std::vector<double> g = test_values(u, t);

    // the zero of test k between u (s = 0, value g0) and the accepted point v (s = s1, value g1),
    // by Illinois regula falsi on s -> g(w(s)), w(s) corrected from u + s t
    auto locate = [&](std::size_t k, double g0, double g1, const Eigen::VectorXd& v, const Eigen::VectorXd& tv,
                      double s1, double& s_at) {
        ContinuationEvent e;
        e.kind = ContinuationEvent::Kind::Test;
        e.index = static_cast<int>(k);
        e.after = static_cast<int>(r.points.size()) - 1;
        e.located = false;
        Eigen::VectorXd w_best = std::abs(g0) <= std::abs(g1) ? u : v, t_best = std::abs(g0) <= std::abs(g1) ? t : tv;
        s_at = std::abs(g0) <= std::abs(g1) ? 0.0 : s1;
        double a = 0.0, fa = g0, b = s1, fb = g1, previous = inf;
        int side = 0;
        for (int it = 0; it < 200; ++it) {
            const double s = (fa * b - fb * a) / (fa - fb);
            Eigen::VectorXd w = u + s * t, tw;
            const CorrectorResult cr = correct(sp, w, t, t.dot(w), newton_options);
            r.newton_iterations += cr.iterations;
            if (!converged(cr.status) || !tangent(sp, w, t, tw)) break;
            const double fs = tests[k].value(sp.u(w), sp.u_tangent(tw));
            w_best = w;
            t_best = tw;
            s_at = s;
            if (fs == 0.0 || std::abs(s - previous) <= options.event_tolerance || b - a <= options.event_tolerance) {
                e.located = true;
                break;
            }
            previous = s;
            if ((fs < 0.0) == (fb < 0.0)) {
                b = s;
                fb = fs;
                if (side == -1) fa *= 0.5;
                side = -1;
            } else {
                a = s;
                fa = fs;
                if (side == 1) fb *= 0.5;
                side = 1;
            }
        }
        e.u = sp.u(w_best);
        e.t = sp.u_tangent(t_best);
        Eigen::VectorXd fe;
        e.residual = sp.residual(w_best, fe) ? fe.norm() : inf;
        return e;
    };

    StepControlOptions so;
    so.initial_step = options.initial_step;
    so.min_step = options.min_step;
    so.max_step = options.max_step;
    so.grow_factor = options.grow_factor;
    so.max_jump = options.max_jump;
    so.shrink_factor = 0.5;  // h halved after a rejection (not an option of the engine)
    StepControl step(so);
    Status last_failure = Status::MaxIterations;
    while (static_cast<int>(r.points.size()) < options.max_points) {
        const double h = step.h();
        // true when the step fell below min_step
        auto reject = [&](Status failure) {
            ++r.rejected_steps;
            last_failure = failure;
            return !step.reject();
        };
        // the first face of the box crossed along u -> x (face -1: x is inside the box)
        auto first_face = [&](const Eigen::VectorXd& x, int& face, double& bound) {
            face = -1;
            double first = inf;
            for (int i = 0; i < m; ++i) {
                if (x(i) >= lo(i) && x(i) <= hi(i)) continue;
                const double edge = x(i) < lo(i) ? lo(i) : hi(i);
                const double fraction = (edge - u(i)) / (x(i) - u(i));
                if (fraction < first) {
                    first = fraction;
                    face = i;
                    bound = edge;
                }
            }
        };
        // the branch's point on that face, corrected with the face's coordinate held at the bound
        auto locate_on_face = [&](int face, double bound, Eigen::VectorXd& w, CorrectorResult& cb) {
            w = u;
            w(face) = bound;
            cb = correct(sp, w, Eigen::VectorXd::Unit(m, face), bound, newton_options);
            r.newton_iterations += cb.iterations;
            bool ok = converged(cb.status) && (w - u).norm() <= step.jump_limit();
            for (int i = 0; i < m && ok; ++i)
                ok = i == face || (w(i) >= lo(i) - bound_slack && w(i) <= hi(i) + bound_slack);
            return ok;
        };
        int face = -1;
        double bound = 0.0;
        Eigen::VectorXd w, tw;
        CorrectorResult cb;

        Eigen::VectorXd v = u + h * t;
        const CorrectorResult cr = correct(sp, v, t, t.dot(v), newton_options);
        r.newton_iterations += cr.iterations;
        if (!converged(cr.status) || step.jumped((v - u).norm())) {
            // A predictor beyond a face of the box where the corrector failed (the problem may not
            // be defined beyond it, e.g. a gain below 0): the face's point is tried before the
            // step is halved, so a branch ends on the face rather than min_step short of it.
            first_face(u + h * t, face, bound);
            const bool landed = !converged(cr.status) && face >= 0 && locate_on_face(face, bound, w, cb);
            if (!landed) {
                if (reject(converged(cr.status) ? Status::NumericalIssue : cr.status))
                    return finish(ContinuationStop::StepBelowMinimum, last_failure, "the step fell below min_step");
                continue;
            }
        } else {
            // a face of the box crossed: the first one along u -> v, located exactly on it
            first_face(v, face, bound);
            if (face >= 0 && !locate_on_face(face, bound, w, cb))
                return finish(ContinuationStop::Bound, converged(cb.status) ? Status::Converged : cb.status,
                              "crossed the bound of unknown " + std::to_string(face) + " where the crossing could not be located");
        }
        if (face >= 0) {
            const std::string which = "the bound of unknown " + std::to_string(face);
            if (!tangent(sp, w, t, tw)) tw = t;
            ContinuationEvent e;
            e.kind = ContinuationEvent::Kind::Bound;
            e.index = face;
            e.after = static_cast<int>(r.points.size()) - 1;
            add_point(w, tw, cb.residual);
            e.u = r.points.back();
            e.t = r.tangents.back();
            e.residual = cb.residual;
            r.events.push_back(std::move(e));
            return finish(ContinuationStop::Bound, Status::Converged, "reached " + which);
        }
        if (!sp.in_domain(v)) return finish(ContinuationStop::LeftDomain, Status::Converged, "the next point is outside the domain");

        Eigen::VectorXd tv;
        if (!tangent(sp, v, t, tv)) return finish(ContinuationStop::TangentFailed, Status::NumericalIssue, "no tangent (J rank deficient)");
        if (std::acos(std::clamp(tv.dot(t), -1.0, 1.0)) > options.max_angle) {
            if (reject(Status::NumericalIssue)) return finish(ContinuationStop::StepBelowMinimum, last_failure, "the step fell below min_step");
            continue;
        }

        // test functions: zeros between u and v, in the order of the arclength
        const std::vector<double> gv = test_values(v, tv);
        std::vector<std::pair<double, ContinuationEvent>> found;
        for (std::size_t k = 0; k < tests.size(); ++k) {
            if (!((g[k] < 0.0 && gv[k] >= 0.0) || (g[k] > 0.0 && gv[k] <= 0.0))) continue;
            double s = 0.0;
            ContinuationEvent e = locate(k, g[k], gv[k], v, tv, t.dot(v - u), s);
            found.emplace_back(s, std::move(e));
        }
        std::stable_sort(found.begin(), found.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        for (auto& [s, e] : found) {
            const bool terminal = tests[static_cast<std::size_t>(e.index)].terminal;
            r.events.push_back(e);
            if (!terminal) continue;
            r.points.push_back(e.u);
            r.tangents.push_back(e.t);
            r.max_residual = std::max(r.max_residual, e.residual);
            if (options.on_point) options.on_point(r.points.back());
            return finish(ContinuationStop::TerminalEvent, Status::Converged, "test function '" + tests[static_cast<std::size_t>(e.index)].name + "' vanished");
        }

        add_point(v, tv, cr.residual);
        if (static_cast<int>(r.points.size()) > closure_min_steps + 1 && (v - start).norm() < closure_fraction * h)
            return finish(ContinuationStop::ClosedLoop, Status::Converged, "the branch returned to its start");
        u = v;
        t = tv;
        g = gv;
        step.accept(cr.iterations <= options.grow_iterations);
    }
    return finish(ContinuationStop::MaxPoints, Status::BudgetExhausted, "max_points points");
}

}  // namespace ddemap
