#include "ddemap/analysis/design/verdict_distance.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "core/internal/text.hpp"
#include "root_sensitivity.hpp"
#include "ddemap/analysis/design/design.hpp"
#include "ddemap/analysis/stability/attenuation_margin.hpp"
#include "ddemap/solve/optimize/golden.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/model.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

void VerdictDistanceOptions::validate() const {
    if (over.empty()) throw std::invalid_argument("verdict distance: expected at least one parameter to change");
    for (std::size_t i = 0; i < over.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (over[i] == over[j]) throw std::invalid_argument("verdict distance: parameter " + detail::quoted(over[i]) + " is named twice");
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kProjectionSteps = 60;
constexpr double kBisection = 1e-6;  // relative to the distance

// A scalar function of the parameters with its gradient (NaN: undefined there).
using Smooth = std::function<double(const Eigen::VectorXd&, Eigen::VectorXd*)>;

class Search {
public:
    Search(std::string model, ParameterMap base, std::vector<std::string> over) : m_model(std::move(model)), m_base(std::move(base)), m_over(std::move(over)) {
        const auto n = static_cast<Eigen::Index>(m_over.size());
        m_x0.resize(n);
        m_lo.resize(n);
        m_hi.resize(n);
        for (Eigen::Index j = 0; j < n; ++j) {
            const double v = m_base.at(m_over[static_cast<std::size_t>(j)]);
            m_x0[j] = v;
            m_lo[j] = std::min(v / 10.0, 10.0 * v);
            m_hi[j] = std::max(v / 10.0, 10.0 * v);
        }
    }

    ParameterMap params(const Eigen::VectorXd& x) const {
        ParameterMap p = m_base;
        for (std::size_t j = 0; j < m_over.size(); ++j) p[m_over[j]] = x[static_cast<Eigen::Index>(j)];
        return p;
    }
    Linearisation lin(const Eigen::VectorXd& x) const { return make_model(m_model, params(x))->linearise(); }
    bool inside(const Eigen::VectorXd& x) const {
        for (Eigen::Index j = 0; j < x.size(); ++j)
            if (!(x[j] >= m_lo[j] && x[j] <= m_hi[j])) return false;
        return is_computable(lin(x));
    }
    double distance(const Eigen::VectorXd& x) const { return ((x - m_x0).array() / m_x0.array()).matrix().norm(); }

    // central differences of f at x, step 1e-6 relative
    Eigen::VectorXd partials(const Eigen::VectorXd& x, const std::function<double(const Linearisation&)>& f) const {
        Eigen::VectorXd g(x.size());
        for (Eigen::Index j = 0; j < x.size(); ++j) {
            const double h = 1e-6 * std::abs(x[j]);
            Eigen::VectorXd xp = x, xm = x;
            xp[j] += h;
            xm[j] -= h;
            g[j] = (f(lin(xp)) - f(lin(xm))) / (2.0 * h);
        }
        return g;
    }

    // g(w; x) of attenuation_piece with m2 = 0: < 0 where |Gamma(i w)| > 1 (c2 < 0 at w = 0)
    Smooth piece(double omega) const {
        return [this, omega](const Eigen::VectorXd& x, Eigen::VectorXd* grad) {
            const Linearisation L = lin(x);
            if (!is_computable(L)) return kNaN;
            if (grad) *grad = partials(x, [omega](const Linearisation& l) { return attenuation_piece(l, omega, 0.0); });
            return attenuation_piece(L, omega, 0.0);
        };
    }
    // minus the plant's abscissa (< 0 where the plant is unstable), gradient from the root's sensitivity
    Smooth plant() const {
        return [this](const Eigen::VectorXd& x, Eigen::VectorXd* grad) {
            const Linearisation L = lin(x);
            if (!is_computable(L)) return kNaN;
            RootOptions ro;
            ro.count = 2;
            const RootResult r = rightmost_roots(plant_dde(L), ro);
            if (r.status != Status::Converged || r.roots.empty()) return kNaN;
            const cplx lambda = r.roots.front().value;
            if (grad) *grad = -detail::plant_root_gradient(L, lambda, [&](const auto& f) { return partials(x, f); });  // of -alpha
            return -lambda.real();
        };
    }

    // The nearest point of {f = 0} to x0 by projections onto the linearised level set, from
    // `start`; a step that leaves the box or the computable range is halved. false when it does
    // not settle (to 1e-10 of the distance) in kProjectionSteps steps.
    bool project(const Smooth& f, Eigen::VectorXd start, Eigen::VectorXd& out) const {
        Eigen::VectorXd x = std::move(start), g;
        const Eigen::ArrayXd Minv = m_x0.array().square();  // M^-1 = diag(x0_j^2)
        for (int k = 0; k < kProjectionSteps; ++k) {
            const double v = f(x, &g);
            if (!std::isfinite(v) || !g.allFinite()) return false;
            const double gmg = (g.array() * Minv * g.array()).sum();
            if (!(gmg > 0.0)) return false;
            Eigen::VectorXd y = m_x0 - (Minv * g.array()).matrix() * ((v + g.dot(m_x0 - x)) / gmg);
            int halvings = 0;
            while (!inside(y) && halvings < 40) {
                y = x + 0.5 * (y - x);
                ++halvings;
            }
            if (!inside(y)) return false;
            const double step = ((y - x).array() / m_x0.array()).matrix().norm();
            x = y;
            if (step <= 1e-10 * (1.0 + distance(x))) {
                const double fv = f(x, nullptr);
                out = x;
                return std::isfinite(fv);
            }
        }
        return false;
    }

    // The certified verdict's string stability at x0 + t (x - x0); nullopt: undecided or outside
    std::optional<bool> stable_at(const Eigen::VectorXd& x, double t) const {
        const Eigen::VectorXd y = m_x0 + t * (x - m_x0);
        const Linearisation L = lin(y);
        if (!is_computable(L)) return std::nullopt;
        const StringResult s = analyse_string(L);
        if (s.string_verdict == Verdict::Undecided) return std::nullopt;
        return s.string_verdict == Verdict::Stable;
    }

    std::string m_model;
    ParameterMap m_base;
    std::vector<std::string> m_over;
    Eigen::VectorXd m_x0, m_lo, m_hi;
};

std::string join_names(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s;
}

std::string percent(double d) {
    char b[64];
    std::snprintf(b, sizeof b, "%.4g %%", 100.0 * d);
    return b;
}

}  // namespace

VerdictDistance verdict_distance(const std::string& model, const ParameterMap& parameters, const VerdictDistanceOptions& options) {
    options.validate();
    const auto names = make_model(model, parameters)->law_parameter_names();
    for (const auto& p : options.over) {
        if (std::find(names.begin(), names.end(), p) == names.end())
            throw std::invalid_argument("verdict distance: the " + model + " law has no parameter " + detail::quoted(p));
        if (parameters.at(p) == 0.0)
            throw std::invalid_argument("verdict distance: relative changes of " + p + " = 0 at the car are not defined: expected a nonzero value");
    }
    VerdictDistance r;
    r.over = options.over;
    const Search S(model, parameters, options.over);
    const StringResult own = analyse_string(S.lin(S.m_x0));
    if (own.string_verdict == Verdict::Undecided) {
        r.status = own.plant_roots.status == Status::Converged ? Status::NumericalIssue : own.plant_roots.status;
        r.message = "the car's own string verdict is undecided";
        return r;
    }
    r.from_stable = own.string_verdict == Verdict::Stable;

    Eigen::VectorXd best;
    std::string bound_note;  // parameters on a bound of the box at the point found
    double best_d = std::numeric_limits<double>::infinity();
    int pieces = 0, settled = 0;
    if (r.from_stable) {
        r.method = "projections onto the level sets g(w; x) = 0 of 1 - |Gamma(i w)|^2 (w = 0 and 12 per decade from 1e-4 to 1e3 rad/s, "
                   "the least refined by golden section in log w) and onto the plant's alpha(x) = 0";
        std::vector<double> grid = {0.0};
        for (int k = 0; k <= 84; ++k) grid.push_back(std::pow(10.0, -4.0 + k / 12.0));
        std::vector<double> dist(grid.size(), std::numeric_limits<double>::infinity());
        std::vector<Eigen::VectorXd> at(grid.size());
        for (std::size_t i = 0; i < grid.size(); ++i) {
            ++pieces;
            Eigen::VectorXd x;
            if (S.project(S.piece(grid[i]), S.m_x0, x)) {
                ++settled;
                dist[i] = S.distance(x);
                at[i] = x;
            }
        }
        std::size_t bi = 0;
        for (std::size_t i = 1; i < grid.size(); ++i)
            if (dist[i] < dist[bi]) bi = i;
        if (std::isfinite(dist[bi])) {
            best = at[bi];
            best_d = dist[bi];
            r.omega = grid[bi];
            // refine in log w between the grid's neighbours (w > 0)
            if (bi >= 1) {
                const double a = std::log(bi == 1 ? grid[1] / std::pow(10.0, 1.0 / 12.0) : grid[bi - 1]);
                const double b = std::log(bi + 1 < grid.size() ? grid[bi + 1] : grid[bi] * std::pow(10.0, 1.0 / 12.0));
                Eigen::VectorXd warm = at[bi];
                auto h = [&](double lw) {
                    Eigen::VectorXd x;
                    if (!S.project(S.piece(std::exp(lw)), warm, x)) return std::numeric_limits<double>::infinity();
                    return S.distance(x);
                };
                double value = 0.0;
                int evaluations = 0;
                const double lw = golden_minimize(h, a, b, value, evaluations, 1e-8, 80);
                Eigen::VectorXd x;
                if (value < best_d && S.project(S.piece(std::exp(lw)), warm, x) && S.distance(x) < best_d) {
                    best = x;
                    best_d = S.distance(x);
                    r.omega = std::exp(lw);
                }
            }
            r.boundary = r.omega == 0.0 ? "low-frequency" : "frequency";
        }
        Eigen::VectorXd xp;
        ++pieces;
        if (S.project(S.plant(), S.m_x0, xp)) {
            ++settled;
            if (S.distance(xp) < best_d) {
                best = xp;
                best_d = S.distance(xp);
                r.boundary = "plant";
                r.omega = kNaN;
            }
        }
    } else {
        DesignOptions o;
        o.objective = DesignObjective::Nearest;
        o.free = options.over;
        o.margin = 0.001;
        o.cars = -1;
        const DesignResult d = design_gains(model, parameters, o);
        r.method = "the nearest gains with an attenuation margin of 1 ms (" + d.method + ")";
        pieces = settled = 1;
        if (d.status == Status::Converged && d.margin_met) {
            best = S.m_x0;
            for (std::size_t j = 0; j < options.over.size(); ++j) best[static_cast<Eigen::Index>(j)] = d.parameters.at(options.over[j]);
            best_d = S.distance(best);
            r.omega = d.attenuation.omega_mu;  // the piece of mu that the nearest point meets
            for (const auto& b : d.at_bound) bound_note += (bound_note.empty() ? "" : ", ") + b;
            r.boundary = r.omega == 0.0 ? "low-frequency" : "frequency";
        } else {
            r.status = d.status == Status::Converged ? Status::NumericalIssue : d.status;
            r.message = d.margin_met ? "string-stable parameters found at a change of " + percent(d.change) + ", but not shown to be the nearest: " + d.message
                                     : "the search for the nearest string-stable parameters did not succeed: " + d.message;
            return r;
        }
    }
    if (!std::isfinite(best_d)) {
        r.status = Status::NumericalIssue;
        r.message = "no flip of the verdict found within [x0/10, 10 x0] of " + join_names(options.over) + " (" + std::to_string(settled) + " of " +
                    std::to_string(pieces) + " searches settled)";
        return r;
    }
    // certify on the segment: the car's verdict at t = 0, the other at t_hi (the point found,
    // or a little beyond it when it lies on the boundary itself)
    const bool mine = r.from_stable;
    double t_hi = 0.0;
    for (double t : {1.0, 1.0 + 1e-6, 1.0 + 1e-4, 1.0 + 1e-2}) {
        const auto v = S.stable_at(best, t);
        if (v && *v != mine) {
            t_hi = t;
            break;
        }
    }
    if (t_hi == 0.0) {
        r.status = Status::NumericalIssue;
        r.message = "the point found (a change of " + percent(best_d) + ") does not flip the certified verdict, nor 1 % beyond it";
        return r;
    }
    double t_lo = 0.0;
    while (t_hi - t_lo > kBisection * t_hi) {
        const double t = 0.5 * (t_lo + t_hi);
        const auto v = S.stable_at(best, t);
        if (!v) {
            r.status = Status::NumericalIssue;
            r.message = "the certified verdict is undecided on the segment to the flip";
            return r;
        }
        (*v == mine ? t_lo : t_hi) = t;
    }
    const Eigen::VectorXd flip = S.m_x0 + t_hi * (best - S.m_x0);
    r.distance = S.distance(flip);
    r.at = S.params(flip);
    r.status = Status::Converged;
    r.message = std::string(mine ? "string stable; a change of " : "string unstable; a change of ") + percent(r.distance) + " of " +
                join_names(options.over) + " makes it string " + (mine ? "unstable" : "stable") +
                " (certified verdicts on the segment, bisected to 1e-6 of the distance; the least over " + std::to_string(settled) + " local searches)" +
                (bound_note.empty() ? std::string() : "; " + bound_note + " on a bound of the search box [x0/10, 10 x0]: a flip beyond it is not searched");
    return r;
}

void add_verdict_distances(std::vector<Classification>& rows, const VerdictDistanceOptions& options, const ExecutionPolicy& policy) {
    options.validate();
    parallel_for(static_cast<long>(rows.size()), [&](long i) {
        rows[static_cast<std::size_t>(i)].distance = verdict_distance("ovrv", rows[static_cast<std::size_t>(i)].vehicle.parameters, options);
        rows[static_cast<std::size_t>(i)].has_distance = true;
    }, policy);
}

}  // namespace ddemap
