#include "ddemap/analysis/bifurcation/fold_curve.hpp"
#include "ddemap/analysis/bifurcation/normal_forms.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <Eigen/Dense>

#include "analysis/bifurcation/internal/chord_zero.hpp"
#include "analysis/bifurcation/internal/curve_trace.hpp"
#include "core/internal/text.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/solve/roots.hpp"

namespace ddemap {

namespace {

/// The fold curve in u = (x, p1, v, p2).
class FoldCurveProblem final : public detail::TwoParameterCurve {
public:
    FoldCurveProblem(const NonlinearDDE& s, int j1, int j2, Eigen::VectorXd v0)
        : TwoParameterCurve(s, j1, j2, 2 * s.dimension() + 1,
                            [&s, v0](int j, const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac, const std::vector<double>& p) {
                                return fold_system(s, j, v0, z, out, jac, p);
                            }),
          m_v0(std::move(v0)) {}
    const Eigen::VectorXd& normalisation() const { return m_v0; }

private:
    Eigen::VectorXd m_v0;
};

/// J = A_0 + ... + A_m from the blocks.
Eigen::MatrixXd summed_jacobian(const std::vector<Eigen::MatrixXd>& a) {
    Eigen::MatrixXd j = a[0];
    for (std::size_t k = 1; k < a.size(); ++k) j += a[k];
    return j;
}

/// sum_k ||A_k||_inf: the size of the linearisation (the shift of null_vector is relative to it).
double block_size(const std::vector<Eigen::MatrixXd>& a) {
    double s = 0.0;
    for (const auto& b : a) s += b.cwiseAbs().rowwise().sum().maxCoeff();
    return s;
}

/// The null vector of J (or of J^T) by three steps of inverse iteration on J + delta I,
/// delta = 1e-12 times the size of the blocks (sum_k ||A_k||_inf, 1 when all vanish): J itself
/// may vanish at a fold; |z| = 1.
Eigen::VectorXd null_vector(const Eigen::MatrixXd& j, bool left, double scale) {
    const Eigen::Index n = j.rows();
    if (!(scale > 0.0) || !std::isfinite(scale)) scale = 1.0;
    const Eigen::MatrixXd m = (left ? Eigen::MatrixXd(j.transpose()) : j) + 1e-12 * scale * Eigen::MatrixXd::Identity(n, n);
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(m);
    Eigen::VectorXd z = Eigen::VectorXd::Ones(n) / std::sqrt(static_cast<double>(n));
    for (int it = 0; it < 3; ++it) {
        z = lu.solve(z);
        const double len = z.norm();
        if (!(len > 0.0) || !std::isfinite(len)) return Eigen::VectorXd();
        z /= len;
    }
    return z;
}

/// The two test functions at a point u of the curve, with w oriented by w . w_ref > 0
/// (w_ref empty: as it comes); w (|w| = 1) returned for the next point's orientation.
struct Tests {
    double cusp = 0.0, bt = 0.0;
    Eigen::VectorXd w;
    bool ok = false;
};
Tests tests_at(const NonlinearDDE& s, const FoldCurveProblem& pr, const Eigen::VectorXd& u, const Eigen::VectorXd& w_ref) {
    Tests t;
    const int n = s.dimension();
    try {
        const std::vector<double> p = pr.values(u);
        const Eigen::VectorXd st = s.stack_constant(u.head(n));
        const std::vector<Eigen::MatrixXd> a = s.jacobians(st, p);
        const Eigen::MatrixXd j = summed_jacobian(a);
        Eigen::VectorXd v = u.segment(n + 1, n);
        const double vn = v.norm();
        if (!(vn > 0.0)) return t;
        v /= vn;
        // w: the bordered system [J v; w_ref^T 0]^T, i.e. [J^T w_ref; v^T 0] [w; s] = [0; 1], keeps
        // the sign of w_ref; without a reference, inverse iteration
        Eigen::VectorXd w;
        if (w_ref.size() == n) {
            Eigen::MatrixXd m(n + 1, n + 1);
            m.topLeftCorner(n, n) = j.transpose();
            m.topRightCorner(n, 1) = v;
            m.bottomLeftCorner(1, n) = w_ref.transpose();
            m(n, n) = 0.0;
            Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + 1);
            rhs[n] = 1.0;
            w = Eigen::PartialPivLU<Eigen::MatrixXd>(m).solve(rhs).head(n);
        } else {
            w = null_vector(j, true, block_size(a));
        }
        const double wn = w.norm();
        if (!(wn > 0.0) || !std::isfinite(wn)) return t;
        w /= wn;
        const std::vector<double> tau = s.delays(p);
        Eigen::VectorXd dv = v;  // Delta'(0) v = (I + sum_k tau_k A_k) v
        for (std::size_t k = 1; k < a.size(); ++k) dv += tau[k - 1] * (a[k] * v);
        const Eigen::VectorXd sv = s.stack_constant(v);
        // D^2 f[S v, S v] at the parameter values p: f(x + e1 S v + e2 S v) in Dual<Dual<double>>
        using D1 = Dual<double>;
        using D2 = NonlinearDDE::Dual2;
        std::vector<D2> U(static_cast<std::size_t>(st.size())), P(p.size()), out(static_cast<std::size_t>(n));
        for (Eigen::Index i = 0; i < st.size(); ++i) U[static_cast<std::size_t>(i)] = D2(D1(st[i], sv[i]), D1(sv[i], 0.0));
        for (std::size_t i = 0; i < p.size(); ++i) P[i] = D2(p[i]);
        s.evaluate(U.data(), P.data(), out.data());
        Eigen::VectorXd b2(n);
        for (int r = 0; r < n; ++r) b2[r] = out[static_cast<std::size_t>(r)].deriv.deriv;
        t.cusp = w.dot(b2);
        t.bt = w.dot(dv);
        t.w = w;
        t.ok = std::isfinite(t.cusp) && std::isfinite(t.bt);
    } catch (const std::invalid_argument&) {
        t.ok = false;
    }
    return t;
}

double fold_residual(const FoldCurveProblem& pr, const Eigen::VectorXd& u) {
    Eigen::VectorXd f;
    return pr.residual(u, f) ? f.cwiseAbs().maxCoeff() : std::numeric_limits<double>::infinity();
}

/// The roots right of the axis (beyond the marginal band) but the one nearest 0: the fold's own
/// root, at 0 to rounding (near a cusp or a Bogdanov-Takens point only to about its square root).
int unstable_besides_zero(const std::vector<cplx>& roots) {
    if (roots.empty()) return 0;
    const auto own = std::min_element(roots.begin(), roots.end(), [](cplx a, cplx b) { return std::abs(a) < std::abs(b); });
    int n = 0;
    for (auto it = roots.begin(); it != roots.end(); ++it)
        if (it != own && it->real() > marginal_band(*it)) ++n;
    return n;
}

/// The count at a point u of the curve (-1 when the roots did not converge), and the roots.
int count_at(const NonlinearDDE& s, const FoldCurveProblem& pr, const Eigen::VectorXd& u, const RootOptions& ro, std::vector<cplx>* roots = nullptr) {
    const EquilibriumRoots er = equilibrium_roots(s, u.head(s.dimension()), pr.values(u), ro);
    if (!converged(er.status)) return -1;
    if (roots) *roots = er.roots;
    return unstable_besides_zero(er.roots);
}

/// A zero-Hopf point between ua and ub (on pr's normalisation) where the count goes from ca to
/// cb = ca +- 2: bisection of the count along the chord, every trial corrected onto the curve,
/// until the bracket is below 1e-13 of the chord (a count that is neither ca nor cb: two events
/// in the step, not located).
FoldCurveSpecialPoint locate_zero_hopf(const NonlinearDDE& s, const FoldCurveProblem& pr, const Eigen::VectorXd& ua, const Eigen::VectorXd& ub,
                                       int ca, int cb, const RootOptions& ro, const NewtonOptions& newton, double residual_tolerance) {
    const int n = s.dimension();
    FoldCurveSpecialPoint z;
    z.kind = "zero_hopf";
    const Eigen::VectorXd d = ub - ua;
    const Eigen::VectorXd dir = d.normalized();
    double lo = 0.0, hi = 1.0;
    Eigen::VectorXd best = ub;
    std::vector<cplx> best_roots;
    z.status = Status::MaxIterations;
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        Eigen::VectorXd u = ua + mid * d;
        const CorrectorResult cr = correct(pr, u, dir, dir.dot(u), newton);
        if (!converged(cr.status)) {
            z.status = cr.status;
            break;
        }
        std::vector<cplx> roots;
        const int c = count_at(s, pr, u, ro, &roots);
        if (c == ca) {
            lo = mid;
        } else if (c == cb) {
            hi = mid;
            best = u;
            best_roots = roots;
        } else {
            z.status = Status::NumericalIssue;  // another count: more than one event in the step
            break;
        }
        if (hi - lo <= 1e-13) {
            z.status = Status::Converged;
            break;
        }
    }
    z.par = best[n];
    z.par2 = best[2 * n + 1];
    z.x = best.head(n);
    // the pair on the axis: the root with Im > 0 nearest it
    double re_min = std::numeric_limits<double>::infinity();
    for (const cplx r : best_roots)
        if (r.imag() > 1e-8 && std::abs(r.real()) < re_min) re_min = std::abs(r.real()), z.omega = r.imag();
    Eigen::VectorXd f;
    z.residual = pr.residual(best, f) ? f.cwiseAbs().maxCoeff() : std::numeric_limits<double>::infinity();
    if (converged(z.status) && z.omega > 0.0) z.zero_hopf = zero_hopf_normal_form(s, z.x, pr.values(best), z.omega);
    if (converged(z.status) && !(z.residual <= residual_tolerance && z.omega > 0.0)) z.status = Status::NumericalIssue;
    return z;
}

/// The curve through the fold `start` of the branch in p1 (at the held p2).
FoldCurve trace_fold_curve(const NonlinearDDE& s, const FoldPoint& start, double held2, const FoldCurveOptions& o) {
    const int j1 = s.parameter_index(o.branch.parameter), j2 = s.parameter_index(o.parameter2);
    const int n = s.dimension();
    FoldCurve curve;
    const double lo1 = std::min(o.branch.from, o.branch.to), hi1 = std::max(o.branch.from, o.branch.to);
    const double lo2 = std::min(o.from2, o.to2), hi2 = std::max(o.from2, o.to2);

    const int N = 2 * n + 2;
    ContinuationOptions co = detail::curve_options(o.continuation, N, n, lo1, hi1, 2 * n + 1, lo2, hi2, start.x);
    const int budget = o.continuation.max_points;

    // the null vector at the start
    std::vector<double> p0 = s.parameter_values();
    p0[static_cast<std::size_t>(j1)] = start.par;
    const std::vector<Eigen::MatrixXd> a0 = s.jacobians(s.stack_constant(start.x), p0);
    const Eigen::VectorXd v = null_vector(summed_jacobian(a0), false, block_size(a0));
    if (v.size() != n) {
        curve.status = Status::NumericalIssue;
        curve.message = "no null vector at the starting fold";
        return curve;
    }
    Eigen::VectorXd u0(N);
    u0 << start.x, start.par, v, held2;

    long traced = 1;  // the start
    if (o.progress)
        co.on_point = [&](const Eigen::VectorXd& u) { o.progress(++traced, 2L * budget - 1, u[n]); };
    // between segments v / |v|^2 becomes v0 (v0 . v = 1 still holds)
    auto renew = [&](Eigen::VectorXd& u, Eigen::VectorXd&) {
        const Eigen::VectorXd vl = u.segment(n + 1, n);
        return std::make_shared<FoldCurveProblem>(s, j1, j2, Eigen::VectorXd(vl / vl.squaredNorm()));
    };
    const detail::TracedCurve<FoldCurveProblem> traced_curve = detail::trace_both_ways(
        std::make_shared<FoldCurveProblem>(s, j1, j2, v), u0, co, o.segment, budget, renew, "no tangent at the starting fold (the fold system is singular there)");
    curve.stop_forward = traced_curve.stops[0];
    curve.stop_backward = traced_curve.stops[1];
    const auto& all = traced_curve.samples;

    // the test functions with w carried along the curve (its sign from the previous point)
    std::vector<Tests> tests;
    Eigen::VectorXd w_prev;
    bool tests_ok = true;
    for (const auto& sm : all) {
        Tests t = tests_at(s, *sm.problem, sm.u, w_prev);
        tests_ok = tests_ok && t.ok;
        if (t.ok) w_prev = t.w;
        FoldCurvePoint pt;
        pt.par = sm.u[n];
        pt.par2 = sm.u[2 * n + 1];
        pt.x = sm.u.head(n);
        pt.cusp_test = t.ok ? t.cusp : std::numeric_limits<double>::quiet_NaN();
        pt.bt_test = t.ok ? t.bt : std::numeric_limits<double>::quiet_NaN();
        pt.residual = fold_residual(*sm.problem, sm.u);
        curve.points.push_back(std::move(pt));
        tests.push_back(std::move(t));
    }
    bool special_ok = true;
    for (std::size_t k = 0; k + 1 < all.size(); ++k) {
        if (!tests[k].ok || !tests[k + 1].ok) continue;
        for (int which = 0; which < 2; ++which) {
            const double fa = which == 0 ? tests[k].cusp : tests[k].bt, fb = which == 0 ? tests[k + 1].cusp : tests[k + 1].bt;
            if (fa == 0.0 || (fa < 0.0) == (fb < 0.0)) continue;
            // both ends on the later sample's normalisation (v0 . v = 1; at a segment's start
            // v0 = v_b / |v_b|^2): the earlier sample's v rescaled (a fold's v is defined up to scale)
            const FoldCurveProblem& pr = *all[k + 1].problem;
            Eigen::VectorXd ua = all[k].u;
            const double sc = pr.normalisation().dot(ua.segment(n + 1, n));
            if (sc != 0.0 && std::isfinite(sc)) ua.segment(n + 1, n) /= sc;
            const Eigen::VectorXd w_ref = tests[k].w;
            const double scale_a = std::max(std::abs(fa), std::abs(fb));
            const detail::ChordZero z = detail::chord_zero(
                pr, ua, all[k + 1].u, fa, fb, o.branch.special,
                [&](const Eigen::VectorXd& uu, double& value) {
                    const Tests tt = tests_at(s, pr, uu, w_ref);
                    if (!tt.ok) return false;
                    value = which == 0 ? tt.cusp : tt.bt;
                    return true;
                },
                [&](const Eigen::VectorXd&, double value) { return std::abs(value) <= 1e-13 * scale_a; });
            FoldCurveSpecialPoint sp;
            sp.kind = which == 0 ? "cusp" : "bogdanov_takens";
            sp.after = static_cast<int>(k);
            sp.status = z.status;
            sp.par = z.u[n];
            sp.par2 = z.u[2 * n + 1];
            sp.x = z.u.head(n);
            const Tests tz = tests_at(s, pr, z.u, w_ref);
            sp.test = tz.ok ? (which == 0 ? tz.cusp : tz.bt) : std::numeric_limits<double>::quiet_NaN();
            sp.other = tz.ok ? (which == 0 ? tz.bt : tz.cusp) : std::numeric_limits<double>::quiet_NaN();
            sp.residual = fold_residual(pr, z.u);
            if (converged(sp.status) && !(sp.residual <= o.branch.special_residual)) sp.status = Status::NumericalIssue;
            if (converged(sp.status)) {
                // the normal form at the located point (DDE-BIFTOOL's normalisation)
                if (which == 0) {
                    const CuspNormalForm nf = cusp_normal_form(s, sp.x, pr.values(z.u));
                    if (nf.status == Status::Converged) {
                        sp.nf_b = nf.b;
                        sp.nf_c = nf.c;
                    }
                } else {
                    const BogdanovTakensNormalForm nf = bogdanov_takens_normal_form(s, sp.x, pr.values(z.u));
                    if (nf.status == Status::Converged) {
                        sp.nf_a = nf.a;
                        sp.nf_b = nf.b;
                    }
                }
            }
            special_ok = special_ok && converged(sp.status);
            curve.special.push_back(std::move(sp));
        }
    }
    // the roots at every point (the linearisations formed in order on this thread, their roots in
    // parallel, from 2 roots grown until every root right of the axis is certified found); where
    // the count changes in a step, the Bogdanov-Takens points located there (+-1 each) and a
    // zero-Hopf point (+-2) must explain it
    bool counts_ok = true;
    std::string counts_message;
    {
        RootOptions ro = o.branch.roots;
        ro.count = 2;
        ro.progress = nullptr;
        const detail::RootsAlong ra = detail::roots_along(s, all, ro);
        for (std::size_t k = 0; k < all.size(); ++k) {
            if (!converged(ra.roots[k].status)) continue;
            curve.points[k].roots = ra.roots[k].roots;
            curve.points[k].unstable = unstable_besides_zero(ra.roots[k].roots);
        }
        if (ra.failed > 0) {
            counts_ok = false;
            counts_message = ra.message();
        }
        for (std::size_t k = 0; k + 1 < all.size(); ++k) {
            const int ca = curve.points[k].unstable, cb = curve.points[k + 1].unstable;
            if (ca < 0 || cb < 0 || ca == cb) continue;
            const int bts = static_cast<int>(std::count_if(curve.special.begin(), curve.special.end(), [&](const FoldCurveSpecialPoint& p) {
                return p.kind == "bogdanov_takens" && p.after == static_cast<int>(k);
            }));
            if (std::abs(cb - ca) == 1 && bts == 1) continue;  // a real root through 0 at the Bogdanov-Takens point
            if (std::abs(cb - ca) == 2 && bts == 0) {
                const FoldCurveProblem& pr = *all[k + 1].problem;
                Eigen::VectorXd ua = all[k].u;
                const double sc = pr.normalisation().dot(ua.segment(n + 1, n));
                if (sc != 0.0 && std::isfinite(sc)) ua.segment(n + 1, n) /= sc;
                FoldCurveSpecialPoint z = locate_zero_hopf(s, pr, ua, all[k + 1].u, ca, cb, ro, o.branch.special, o.branch.special_residual);
                z.after = static_cast<int>(k);
                if (!converged(z.status)) counts_ok = false, counts_message = "a zero-Hopf point was not located (more than one crossing in a step?)";
                curve.special.push_back(std::move(z));
                continue;
            }
            counts_ok = false;
            counts_message = "between points " + std::to_string(k) + " and " + std::to_string(k + 1) + " the count of roots right of the axis changes by " +
                             std::to_string(cb - ca) + " with " + std::to_string(bts) + " Bogdanov-Takens point(s) located there";
        }
    }
    std::sort(curve.special.begin(), curve.special.end(), [](const FoldCurveSpecialPoint& a, const FoldCurveSpecialPoint& b) { return a.after < b.after; });

    curve.status = traced_curve.end_status();
    std::string msg = traced_curve.ended_well() ? std::string() : traced_curve.end_text();
    if (!tests_ok) {
        if (converged(curve.status)) curve.status = Status::NumericalIssue;
        msg += std::string(msg.empty() ? "" : "; ") + "the cusp and Bogdanov-Takens tests could not be evaluated at every point";
    }
    if (!special_ok) {
        if (converged(curve.status)) curve.status = Status::NumericalIssue;
        msg += std::string(msg.empty() ? "" : "; ") + "a cusp or Bogdanov-Takens point was not located";
    }
    if (!counts_ok) {
        if (converged(curve.status)) curve.status = Status::NumericalIssue;
        msg += std::string(msg.empty() ? "" : "; ") + counts_message;
    }
    curve.message = msg.empty() ? std::to_string(curve.points.size()) + " points, both ends on the box or closed" : msg;
    return curve;
}

/// True when the fold point lies on the traced curve (within 1e-6 of the box in p1, p2 and of
/// x's scale, between two consecutive points).
bool on_curve(const FoldCurve& c, const FoldPoint& f, double held2, double side1, double side2) {
    for (const FoldCurvePoint& p : c.points) {
        const double dx = (p.x - f.x).cwiseAbs().maxCoeff() / std::max(1.0, f.x.cwiseAbs().maxCoeff());
        if (std::abs(p.par - f.par) <= 1e-6 * side1 && std::abs(p.par2 - held2) <= 1e-6 * side2 && dx <= 1e-6) return true;
    }
    // between points: the segment crossing p2 = held2 near (f.par, f.x)
    for (std::size_t k = 0; k + 1 < c.points.size(); ++k) {
        const FoldCurvePoint &a = c.points[k], &b = c.points[k + 1];
        if ((a.par2 - held2) * (b.par2 - held2) > 0.0 || a.par2 == b.par2) continue;
        const double s = (held2 - a.par2) / (b.par2 - a.par2);
        const double par = a.par + s * (b.par - a.par);
        const Eigen::VectorXd x = a.x + s * (b.x - a.x);
        const double dx = (x - f.x).cwiseAbs().maxCoeff() / std::max(1.0, f.x.cwiseAbs().maxCoeff());
        if (std::abs(par - f.par) <= 1e-3 * side1 && dx <= 1e-3) return true;
    }
    return false;
}

}  // namespace

FoldCurves fold_curves(const NonlinearDDE& s, const Eigen::VectorXd& guess, const FoldCurveOptions& o) {
    std::string why;
    if (!o.is_valid(&why)) throw std::invalid_argument("fold curve options: " + why);
    s.parameter_index(o.branch.parameter);  // an unknown name is refused here, parameter2 by held_second
    if (!s.has_higher_derivatives())
        throw std::invalid_argument("fold curves: the system gives no second derivatives: expected an expression system or a built-in model (NonlinearDDEOf)");
    const double held2 = o.held_second(s);
    const double lo2 = std::min(o.from2, o.to2), hi2 = std::max(o.from2, o.to2);
    FoldCurves out;
    out.start = equilibrium_branch(s, guess, o.branch);
    std::string msg;
    if (!converged(out.start.status)) {
        out.status = out.start.status;
        msg = "the equilibrium branch in " + o.branch.parameter + ": " + out.start.message;
    }
    const double side1 = std::abs(o.branch.to - o.branch.from), side2 = hi2 - lo2;
    for (std::size_t i = 0; i < out.start.folds.size(); ++i) {
        const FoldPoint& f = out.start.folds[i];
        if (f.kind != "fold" || !converged(f.status)) continue;
        const bool traced = std::any_of(out.curves.begin(), out.curves.end(), [&](const FoldCurve& c) { return on_curve(c, f, held2, side1, side2); });
        if (traced) continue;
        FoldCurve c = trace_fold_curve(s, f, held2, o);
        c.start = static_cast<int>(i);
        if (!converged(c.status)) {
            if (converged(out.status)) out.status = c.status;
            msg += std::string(msg.empty() ? "" : "; ") + "curve " + std::to_string(out.curves.size()) + ": " + c.message;
        }
        out.curves.push_back(std::move(c));
    }
    if (msg.empty()) {
        int cusps = 0, bts = 0, zhs = 0;
        for (const FoldCurve& c : out.curves)
            for (const FoldCurveSpecialPoint& p : c.special) (p.kind == "cusp" ? cusps : p.kind == "bogdanov_takens" ? bts : zhs)++;
        msg = std::to_string(out.curves.size()) + " fold curve" + (out.curves.size() == 1 ? "" : "s") + ", " + std::to_string(cusps) + " cusp" +
              (cusps == 1 ? "" : "s") + ", " + std::to_string(bts) + " Bogdanov-Takens point" + (bts == 1 ? "" : "s") + ", " + std::to_string(zhs) +
              " zero-Hopf point" + (zhs == 1 ? "" : "s") + "; root counts along every curve explained";
    }
    out.message = msg;
    return out;
}

}  // namespace ddemap
