#pragma once
// Two-parameter curves of special points (Hopf curves, fold curves): the curve through a start
// point traced both ways in segments, the normalisation of the defining system renewed between
// segments; and the domain test every such problem shares (delays finite and >= 0).

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/problem/nonlinear_dde.hpp"
#include "ddemap/solve/continuation.hpp"

namespace ddemap::detail {

/// True when the delays at the parameter values p are finite and >= 0 (a continuation's domain).
inline bool delays_valid(const NonlinearDDE& s, const std::vector<double>& p) {
    try {
        const std::vector<double> d = s.delays(p);
        return std::all_of(d.begin(), d.end(), [](double t) { return std::isfinite(t) && t >= 0.0; });
    } catch (const std::invalid_argument&) {
        return false;
    }
}

/// A one-parameter defining system lifted to two parameters: F(z; p) = 0 with z = (x, p_j1, rest)
/// (p_j1 at index n, `size` unknowns and equations) becomes the curve in u = (z, p_j2). F(j, z,
/// out, jac, values) evaluates the system with p_j = z[n] and the other parameters from `values`;
/// the Jacobian's p2 column is the p_j column of the system in j2.
class TwoParameterCurve : public ContinuationProblem {
public:
    using System = std::function<bool(int j, const Eigen::VectorXd& z, Eigen::VectorXd& out, Eigen::MatrixXd* jac, const std::vector<double>& values)>;
    TwoParameterCurve(const NonlinearDDE& s, int j1, int j2, int size, System f) : m_s(s), m_j1(j1), m_j2(j2), m_size(size), m_f(std::move(f)) {}
    int equations() const override { return m_size; }
    /// Every parameter value at u: the held ones, p_j1 = u[n], p_j2 = u[size].
    std::vector<double> values(const Eigen::VectorXd& u) const {
        std::vector<double> p = m_s.parameter_values();
        p[static_cast<std::size_t>(m_j1)] = u[m_s.dimension()];
        p[static_cast<std::size_t>(m_j2)] = u[m_size];
        return p;
    }
    bool residual(const Eigen::VectorXd& u, Eigen::VectorXd& f) const override { return m_f(m_j1, u.head(m_size), f, nullptr, values(u)); }
    bool jacobian(const Eigen::VectorXd& u, Eigen::MatrixXd& j) const override {
        Eigen::VectorXd f1, f2;
        Eigen::MatrixXd j1, j2;
        const std::vector<double> p = values(u);
        Eigen::VectorXd z = u.head(m_size);
        if (!m_f(m_j1, z, f1, &j1, p)) return false;
        z[m_s.dimension()] = u[m_size];
        if (!m_f(m_j2, z, f2, &j2, p)) return false;
        j.resize(m_size, m_size + 1);
        j.leftCols(m_size) = j1;
        j.col(m_size) = j2.col(m_s.dimension());
        return true;
    }
    bool in_domain(const Eigen::VectorXd& u) const override { return delays_valid(m_s, values(u)); }

protected:
    const NonlinearDDE& m_s;
    int m_j1, m_j2, m_size;
    System m_f;
};

/// The continuation options of a two-parameter curve in u (N unknowns, the equilibrium x first,
/// p1 at index i1, p2 at index i2): steps measured with p1, p2 scaled by their box sides and the
/// equilibrium's entries by max(1, |x_start|_inf) (initial/max step 0 = automatic: 0.01 and 0.05
/// of the box), the box [lo1, hi1] x [lo2, hi2] on those two unknowns. (Unscaled, an equilibrium
/// of speeds and gaps of 20 to 30 limited a step to a change of 0.05 m/s in them: the Hopf curve
/// of a 5-car IDM ring took 543 points for a fifth of its box.)
inline ContinuationOptions curve_options(ContinuationOptions co, int N, int i1, double lo1, double hi1, int i2, double lo2, double hi2,
                                         const Eigen::VectorXd& x_start) {
    co.scale = Eigen::VectorXd::Ones(N);
    const double xs = std::max(1.0, x_start.size() > 0 ? x_start.cwiseAbs().maxCoeff() : 0.0);
    co.scale.head(std::min<Eigen::Index>(x_start.size(), N)).setConstant(xs);
    co.scale[i1] = hi1 - lo1;
    co.scale[i2] = hi2 - lo2;
    if (co.initial_step == 0.0) co.initial_step = 0.01;
    if (co.max_step == 0.0) co.max_step = 0.05;
    co.initial_step = std::min(co.initial_step, co.max_step);
    co.min_step = std::min(co.min_step, co.initial_step);
    co.lower = Eigen::VectorXd::Constant(N, -std::numeric_limits<double>::infinity());
    co.upper = Eigen::VectorXd::Constant(N, std::numeric_limits<double>::infinity());
    co.lower[i1] = lo1, co.upper[i1] = hi1, co.lower[i2] = lo2, co.upper[i2] = hi2;
    return co;
}

template <class Problem>
struct TracedCurve {
    struct Sample {
        Eigen::VectorXd u;
        std::shared_ptr<Problem> problem;  ///< the normalisation the point was computed with
    };
    /// The backward pass reversed, the start, the forward pass.
    std::vector<Sample> samples;
    ContinuationStop stops[2] = {ContinuationStop::MaxPoints, ContinuationStop::MaxPoints};  ///< [0] forward, [1] backward
    Status status[2] = {Status::Converged, Status::Converged};
    std::string messages[2];

    bool closed() const { return stops[0] == ContinuationStop::ClosedLoop; }
    static bool regular(ContinuationStop st) {
        return st == ContinuationStop::Bound || st == ContinuationStop::ClosedLoop || st == ContinuationStop::LeftDomain;
    }
    /// Both ends on the box, the domain's edge, or the curve closed.
    bool ended_well() const { return regular(stops[0]) && (closed() || regular(stops[1])); }
    /// Converged when ended_well(); else BudgetExhausted at max_points, or the failing pass's status
    /// (NumericalIssue when that was converged).
    Status end_status() const {
        if (ended_well()) return Status::Converged;
        const int bad = regular(stops[0]) ? 1 : 0;
        return stops[bad] == ContinuationStop::MaxPoints ? Status::BudgetExhausted : converged(status[bad]) ? Status::NumericalIssue : status[bad];
    }
    /// "ended: bound and bound" with the continuation's messages of a badly ended pass.
    std::string end_text() const {
        std::string m = "ended: " + to_string(stops[0]) + (closed() ? "" : " and " + to_string(stops[1]));
        for (int d = 0; d < 2; ++d)
            if (!regular(stops[d]) && !(d == 1 && closed()) && !messages[d].empty()) m += " (" + messages[d] + ")";
        return m;
    }
};

/// The curve through u0 (on the curve of `first`), forward along its tangent then backward, each
/// way in segments of at most `segment` points within `budget` points (the start included); after
/// a full segment renew(u, t) returns the problem of the next one and may rescale the last point u
/// and its tangent t in place (a renewed normalisation). `no_tangent`: the message when the start
/// has no tangent. co.on_point is called for every point added.
template <class Problem, class Renew>
TracedCurve<Problem> trace_both_ways(const std::shared_ptr<Problem>& first, const Eigen::VectorXd& u0, const ContinuationOptions& co,
                                     int segment, int budget, Renew renew, const std::string& no_tangent) {
    TracedCurve<Problem> out;
    std::vector<typename TracedCurve<Problem>::Sample> passes[2];
    for (int d = 0; d < 2; ++d) {
        if (d == 1 && out.closed()) break;  // the forward pass went round
        std::shared_ptr<Problem> pr = first;
        passes[d].push_back({u0, pr});
        Eigen::VectorXd t;
        if (!tangent(*pr, u0, Eigen::VectorXd(), t)) {
            out.stops[d] = ContinuationStop::TangentFailed;
            out.status[d] = Status::NumericalIssue;
            out.messages[d] = no_tangent;
            continue;
        }
        Eigen::VectorXd direction = d == 0 ? t : Eigen::VectorXd(-t);
        Eigen::VectorXd u = u0;
        int left = budget - 1;
        while (true) {
            ContinuationOptions seg = co;
            seg.max_points = std::min(segment, left) + 1;
            const ContinuationResult c = continue_branch(*pr, u, direction, seg);
            for (std::size_t k = 1; k < c.points.size(); ++k) passes[d].push_back({c.points[k], pr});
            left -= static_cast<int>(c.points.size()) - 1;
            out.stops[d] = c.stop;
            out.status[d] = c.status;
            out.messages[d] = c.message;
            if (c.stop != ContinuationStop::MaxPoints || left <= 0 || c.points.size() < 2) break;
            u = c.points.back();
            direction = c.tangents.back();
            pr = renew(u, direction);
            passes[d].back() = {u, pr};
        }
    }
    out.samples.assign(passes[1].rbegin(), passes[1].rend());
    if (!out.samples.empty()) out.samples.pop_back();  // the start again
    out.samples.insert(out.samples.end(), passes[0].begin(), passes[0].end());
    return out;
}

/// The characteristic roots at every sample of a traced curve (the equilibrium u.head(n) at the
/// sample's parameter values): the linearisations formed in order on this thread (the system is
/// evaluated here), their roots in parallel, from 2 roots grown until every root right of the
/// axis is certified found (asking for more at once cost 5 to 20 times as much on the 3-car ov
/// ring at small delays).
struct RootsAlong {
    std::vector<EquilibriumRoots> roots;  ///< one per sample
    int failed = 0;                       ///< samples whose roots did not converge
    /// "the characteristic roots did not converge at N point(s) of the curve", or empty
    std::string message() const {
        return failed == 0 ? std::string() : "the characteristic roots did not converge at " + std::to_string(failed) + " point(s) of the curve";
    }
};
template <class Sample>
RootsAlong roots_along(const NonlinearDDE& s, const std::vector<Sample>& all, RootOptions ro) {
    const int n = s.dimension();
    std::vector<LinearDDE> lins;
    lins.reserve(all.size());
    for (const Sample& sm : all) lins.push_back(linearise(s, sm.u.head(n), sm.problem->values(sm.u)));
    ro.count = 2;
    ro.progress = nullptr;
    RootsAlong out;
    out.roots.resize(all.size());
    parallel_for(static_cast<long>(all.size()),
                 [&](long k) { out.roots[static_cast<std::size_t>(k)] = equilibrium_roots(lins[static_cast<std::size_t>(k)], ro); });
    for (const EquilibriumRoots& r : out.roots) out.failed += converged(r.status) ? 0 : 1;
    return out;
}

}  // namespace ddemap::detail
