#include "ddemap/analysis/design/design.hpp"

#include <algorithm>
#include <random>
#include <cmath>
#include <limits>
#include <functional>
#include <memory>
#include <stdexcept>

#include "core/internal/text.hpp"
#include "root_sensitivity.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"
#include "ddemap/problem/linear_dde.hpp"
#include "ddemap/solve/optimize/golden.hpp"
#include "ddemap/solve/roots.hpp"
#include "ddemap/traffic/transfer_function.hpp"

namespace ddemap {

std::string to_string(DesignObjective o) {
    switch (o) {
        case DesignObjective::SupGamma: return "sup-gamma";
        case DesignObjective::Peak: return "peak";
        case DesignObjective::Abscissa: return "abscissa";
        case DesignObjective::Nearest: return "nearest";
    }
    return "?";
}

DesignObjective parse_design_objective(const std::string& name) {
    for (DesignObjective o : {DesignObjective::SupGamma, DesignObjective::Peak, DesignObjective::Abscissa, DesignObjective::Nearest})
        if (to_string(o) == name) return o;
    throw std::invalid_argument("objective " + detail::quoted(name) + ": expected sup-gamma, peak, abscissa or nearest");
}

void DesignOptions::validate() const {
    if (free.empty()) throw std::invalid_argument("design: expected at least one free parameter");
    for (std::size_t i = 0; i < free.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (free[i] == free[j]) throw std::invalid_argument("design: free parameter " + detail::quoted(free[i]) + " is named twice");
    if (free.size() > 8) throw std::invalid_argument("design: " + std::to_string(free.size()) + " free parameters: expected at most 8");
    // below a millisecond mu = m^2 is lost in the rounding of its pieces (about 1e-16 of their size)
    if (!(margin >= 1e-3) || !std::isfinite(margin) || margin > 1e3)
        throw std::invalid_argument("design: margin = " + detail::significant(margin, 6) + " s: expected a number of seconds in [0.001, 1000]");
    if (!weights.empty()) {
        if (weights.size() != free.size())
            throw std::invalid_argument("design: " + std::to_string(weights.size()) + " weights for " + std::to_string(free.size()) +
                                        " free parameters: expected one per free parameter");
        for (std::size_t j = 0; j < weights.size(); ++j)
            if (!(weights[j] >= 1e-3) || !std::isfinite(weights[j]) || weights[j] > 1e3)
                throw std::invalid_argument("design: weight of " + free[j] + " = " + detail::significant(weights[j], 6) + ": expected a number in [0.001, 1000]");
    }
    if (cars < -1 || cars == 1) throw std::invalid_argument("design: cars = " + std::to_string(cars) + ": expected -1 (the plant), 0 (N = infinity) or N >= 2");
    if (cars > kWindingMaxCars) throw std::invalid_argument("design: cars = " + std::to_string(cars) + ": expected at most 10^9");
    if (starts < 1 || starts > 64) throw std::invalid_argument("design: starts = " + std::to_string(starts) + ": expected 1 to 64");
    optimizer.validate();
    peak.validate();
    if (robust && !has_covariance)
        throw std::invalid_argument("design: robust design needs the covariance of a calibrated car (a fit file from calibrate): the car has none");
    if (robust_iterations < 1 || robust_iterations > 50)
        throw std::invalid_argument("design: robust_iterations = " + std::to_string(robust_iterations) + ": expected 1 to 50");
    if (uncertainty_samples < 1 || uncertainty_samples > 1000000)
        throw std::invalid_argument("design: uncertainty_samples = " + std::to_string(uncertainty_samples) + ": expected 1 to 1000000");
    validate_bounds(bounds);
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Steps of the sequential QP at most: it converges linearly where the boundary is curved (the
// QP's metric is the distance's alone; measured ratios 0.5 to 0.85 per step on the paper's cars)
constexpr int kSqpSteps = 300;
// 1/s: the nearest search keeps the plant's spectral abscissa below minus this (linearised)
constexpr double kPlantMargin = 1e-3;
// Integrator steps of one ||h||_1 run during a peak search (about 0.05 s)
constexpr long kSearchPeakSteps = 200000;
// Evaluations of one run of the peak search at most
constexpr int kPeakEvaluations = 40;
constexpr long kQpSets = 1000000;  // active sets a QP step of nearest tries at most

std::string join(const std::vector<std::string>& v, const std::string& sep) {
    std::string s;
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
    return s;
}

// The radical inverse of i in base b (Halton sequence).
double halton(int i, int b) {
    double f = 1.0, r = 0.0;
    for (int k = i; k > 0; k /= b) {
        f /= b;
        r += f * (k % b);
    }
    return r;
}

class Problem {
public:
    Problem(std::string model, ParameterMap base, const DesignOptions& o) : m_model(std::move(model)), m_base(std::move(base)), m_opt(o) {}

    std::string m_model;
    ParameterMap m_base;
    /// robust design: the held parameters at which the search evaluates (the car's own and the
    /// worst points of the ellipsoid met so far; an empty map: the car's own), every objective
    /// taken as its worst over them. The result's verdicts are at the car's own (nominal()).
    std::vector<ParameterMap> m_scenarios{ParameterMap{}};
    /// the scenario that lin() evaluates (set by the loops over scenarios, 0 otherwise)
    std::size_t m_active = 0;
    const DesignOptions& m_opt;
    std::vector<double> lo, hi, x0, w;
    int evaluations = 0;
    double rho = 10.0;  // nearest: the penalty weight

    std::size_t n() const { return m_opt.free.size(); }
    ParameterMap params(const Eigen::VectorXd& x) const {
        ParameterMap p = m_base;
        for (std::size_t j = 0; j < n(); ++j) p[m_opt.free[j]] = x[static_cast<Eigen::Index>(j)];
        return p;
    }
    Linearisation lin(const Eigen::VectorXd& x) const {
        const ParameterMap& sc = m_scenarios[m_active];
        if (sc.empty()) return make_model(m_model, params(x))->linearise();
        ParameterMap p = params(x);
        for (const auto& [k, v] : sc) p[k] = v;
        return make_model(m_model, p)->linearise();
    }
    // f() evaluated with lin() at every scenario in turn
    template <class F>
    void for_each_scenario(const F& f) {
        try {
            for (m_active = 0; m_active < m_scenarios.size(); ++m_active) f();
        } catch (...) {
            m_active = 0;
            throw;
        }
        m_active = 0;
    }
    // every scenario's plant stable (abscissa below 0) and, when asked, its margin at least m
    bool meets(const Eigen::VectorXd& x, double m, bool with_margin = true) {
        bool ok = true;
        for_each_scenario([&] {
            if (!ok) return;
            const Linearisation L = lin(x);
            ok = plant(x, L, nullptr) < 0.0 && (!with_margin || attenuation_scan(L).margin >= m);
        });
        return ok;
    }
    // the least attenuation margin m* over the scenarios (no plant check)
    double least_margin(const Eigen::VectorXd& x) {
        double m = kInf;
        for_each_scenario([&] { m = std::min(m, attenuation_scan(lin(x)).margin); });
        return m;
    }
    Linearisation nominal(const Eigen::VectorXd& x) const { return make_model(m_model, params(x))->linearise(); }
    // A difference step of `rel` relative to x_j (to the box's width where x_j = 0)
    double step(std::size_t j, const Eigen::VectorXd& x, double rel = 1e-6) const {
        const double v = std::abs(x[static_cast<Eigen::Index>(j)]);
        return rel * (v > 0.0 ? v : 1e-3 * (hi[j] - lo[j]));
    }
    // d f / d x_j by central differences of step h, forward ones where x_j - h would leave the
    // box's lower side (the law's domain may end there)
    template <class G>
    double difference(std::size_t j, const Eigen::VectorXd& x, double h, const G& f) const {
        Eigen::VectorXd xp = x, xm = x;
        xp[static_cast<Eigen::Index>(j)] += h;
        if (x[static_cast<Eigen::Index>(j)] - h < lo[j]) return (f(xp) - f(x)) / h;
        xm[static_cast<Eigen::Index>(j)] -= h;
        return (f(xp) - f(xm)) / (2.0 * h);
    }
    // x_j = lo + (hi - lo)(1 - cos z)/2
    Eigen::VectorXd x_of(const Eigen::VectorXd& z) const {
        Eigen::VectorXd x(z.size());
        for (std::size_t j = 0; j < n(); ++j) {
            const auto J = static_cast<Eigen::Index>(j);
            x[J] = std::clamp(lo[j] + (hi[j] - lo[j]) * 0.5 * (1.0 - std::cos(z[J])), lo[j], hi[j]);
        }
        return x;
    }
    Eigen::VectorXd z_of(const Eigen::VectorXd& x) const {
        Eigen::VectorXd z(x.size());
        for (std::size_t j = 0; j < n(); ++j) {
            const auto J = static_cast<Eigen::Index>(j);
            const double u = hi[j] > lo[j] ? (x[J] - lo[j]) / (hi[j] - lo[j]) : 0.5;
            z[J] = std::acos(std::clamp(1.0 - 2.0 * u, -1.0, 1.0));
        }
        return z;
    }
    Eigen::VectorXd dx_dz(const Eigen::VectorXd& z) const {
        Eigen::VectorXd d(z.size());
        for (std::size_t j = 0; j < n(); ++j) d[static_cast<Eigen::Index>(j)] = (hi[j] - lo[j]) * 0.5 * std::sin(z[static_cast<Eigen::Index>(j)]);
        return d;
    }
    double distance(const Eigen::VectorXd& x, Eigen::VectorXd* grad) const {
        double s = 0.0;
        for (std::size_t j = 0; j < n(); ++j) {
            const double r = w[j] * (x[static_cast<Eigen::Index>(j)] - x0[j]) / std::abs(x0[j]);
            s += r * r;
        }
        const double d = std::sqrt(s);
        if (grad) {
            grad->setZero(static_cast<Eigen::Index>(n()));
            if (d > 0.0)
                for (std::size_t j = 0; j < n(); ++j)
                    (*grad)[static_cast<Eigen::Index>(j)] = w[j] * w[j] * (x[static_cast<Eigen::Index>(j)] - x0[j]) / (x0[j] * x0[j] * d);
        }
        return d;
    }

    // Central differences of a function of the linearisation at fixed frequency or root.
    template <class F>
    Eigen::VectorXd partials(const Eigen::VectorXd& x, const F& f) const {
        Eigen::VectorXd g(static_cast<Eigen::Index>(n()));
        for (std::size_t j = 0; j < n(); ++j)
            g[static_cast<Eigen::Index>(j)] = difference(j, x, step(j, x), [&](const Eigen::VectorXd& y) { return f(lin(y)); });
        return g;
    }

    // Rightmost root of the plant: its real part, the gradient (when asked), NaN if not converged.
    double plant(const Eigen::VectorXd& x, const Linearisation& L, Eigen::VectorXd* grad) const {
        if (!is_computable(L)) return std::numeric_limits<double>::quiet_NaN();
        RootOptions ro;
        ro.count = 2;
        // near its minimum the abscissa is a nearly double root, whose refined value moves by
        // ~1e-11 between degrees: agreement to 1e-9 (far below the minimiser's resolution) settles
        // at M of a few dozen instead of a few hundred
        ro.dense.agreement_tolerance = 1e-9;
        const RootResult r = rightmost_roots(plant_dde(L), ro);
        if (r.status != Status::Converged || r.roots.empty()) return std::numeric_limits<double>::quiet_NaN();
        const cplx lambda = r.roots.front().value;
        if (grad) *grad = detail::plant_root_gradient(L, lambda, [&](const auto& f) { return partials(x, f); });
        return lambda.real();
    }

    double ring(const Eigen::VectorXd& x, const Linearisation& L, Eigen::VectorXd* grad) const {
        const FastRing fr = analyse_ring_fast(L, m_opt.cars, resolve_ring_method("auto", L), 1);
        if (fr.ring.status != Status::Converged) return std::numeric_limits<double>::quiet_NaN();
        const double a = fr.ring.spectral_abscissa;
        if (!grad) return a;
        *grad = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n()));
        if (fr.ring.abscissa_is_limit) return a;
        if (!fr.ring.roots.empty()) {
            const RingRoot& rr = fr.ring.roots.front();
            const cplx lambda = rr.root.value;
            const cplx zeta = std::polar(1.0, -rr.theta);
            cplx nn, d, dn, dd;
            TransferFunction(L).evaluate(lambda, nn, d, dn, dd);
            const cplx fprime = dd - zeta * dn;
            auto delta = [&](const Linearisation& l) {
                cplx a1, b1;
                TransferFunction(l).evaluate(lambda, a1, b1);
                return b1 - zeta * a1;
            };
            const Eigen::VectorXd re = partials(x, [&](const Linearisation& l) { return delta(l).real(); });
            const Eigen::VectorXd im = partials(x, [&](const Linearisation& l) { return delta(l).imag(); });
            for (Eigen::Index j = 0; j < grad->size(); ++j) (*grad)[j] = (-cplx(re[j], im[j]) / fprime).real();
            return a;
        }
        // no root listed: differences of the abscissa itself
        for (std::size_t j = 0; j < n(); ++j) {
            (*grad)[static_cast<Eigen::Index>(j)] = difference(j, x, step(j, x, 1e-5), [&](const Eigen::VectorXd& y) { return ring(y, lin(y), nullptr); });
        }
        return a;
    }

    // mu's gradient at the frequency where the scan found it (the limit w -> 0: c2 / D(0)^2).
    Eigen::VectorXd mu_gradient(const Eigen::VectorXd& x, const AttenuationScan& s) const {
        if (s.omega_mu == 0.0)
            return partials(x, [](const Linearisation& l) {
                const LowFrequency lf = low_frequency_expansion(l);
                return lf.c2 / (lf.d0 * lf.d0);
            });
        const double wm = s.omega_mu;
        return partials(x, [wm](const Linearisation& l) {
            const TransferFunction tf(l);
            double q = 0.0;
            tf.attenuation(wm, &q);
            return q / std::norm(tf.numerator(cplx(0.0, wm)));
        });
    }
    Eigen::VectorXd sup_gradient(const Eigen::VectorXd& x, const AttenuationScan& s) const {
        if (s.omega_sup == 0.0) return Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n()));
        const double ws = s.omega_sup;
        return partials(x, [ws](const Linearisation& l) { return std::abs(TransferFunction(l)(cplx(0.0, ws))); });
    }

    // sup-gamma: the weighted norm sup |Gamma(i w)| |1 + i m w|, m = margin (Danskin at its frequency)
    double sup_objective(const AttenuationScan& s, const Eigen::VectorXd& x, Eigen::VectorXd* grad) const {
        if (grad) {
            if (s.omega_weighted == 0.0) {
                *grad = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n()));
            } else {
                const double ws = s.omega_weighted, wt = std::hypot(1.0, m_opt.margin * ws);
                *grad = partials(x, [ws, wt](const Linearisation& l) { return std::abs(TransferFunction(l)(cplx(0.0, ws))) * wt; });
            }
        }
        return s.weighted_sup;
    }
    double nearest_objective(const AttenuationScan& s, const Eigen::VectorXd& x, Eigen::VectorXd* grad) const {
        Eigen::VectorXd gd;
        const double d = distance(x, grad ? &gd : nullptr);
        const double viol = 1.0 - s.margin / m_opt.margin;
        if (grad) *grad = gd;
        if (viol <= 0.0) return d;
        if (grad) *grad -= (rho / m_opt.margin) * mu_gradient(x, s) / (2.0 * std::max(std::abs(s.margin), 1e-8));
        return d + rho * viol;
    }
    // ||h||_1 during the search, with at most kSearchPeakSteps steps per run: a design whose step
    // response needs more (a plant that settles slowly) is outside the search's domain, so that
    // no evaluation takes seconds; the result's own verdict uses the full options.
    // With `directions`, its derivatives along them into `gradient` (the sensitivity equations
    // of the step response, peak_stability.hpp).
    double peak_value(const Linearisation& L, double abscissa, const std::vector<Linearisation>& directions = {},
                      std::vector<double>* gradient = nullptr) const {
        PeakOptions o = m_opt.peak;
        o.max_steps = std::min(o.max_steps, kSearchPeakSteps);
        o.tolerance = std::max(o.tolerance, 1e-6);  // the search needs no more
        std::vector<double> g;
        const PeakResult p = peak_string_stability(L, abscissa, o, directions, g);
        if (p.verdict == Verdict::Undecided || !p.finite) return std::numeric_limits<double>::quiet_NaN();
        if (gradient) *gradient = g;
        return p.norm;
    }
    // d lin / d x_j as a direction of peak_string_stability: the coefficients' central
    // differences (forward at the box's lower side) at the delays of `base`; false when a delay
    // moves with x_j (then the norm itself is differenced)
    bool lin_direction(const Eigen::VectorXd& x, std::size_t j, const Linearisation& base, Linearisation& out) const {
        const double h = step(j, x);
        Eigen::VectorXd xp = x, xm = x;
        xp[static_cast<Eigen::Index>(j)] += h;
        const bool forward = x[static_cast<Eigen::Index>(j)] - h < lo[j];
        if (!forward) xm[static_cast<Eigen::Index>(j)] -= h;
        const Linearisation Lp = lin(xp), Lm = lin(xm);
        const double width = forward ? h : 2.0 * h;
        out = Linearisation{};
        const ExpPoly* bases[3] = {&base.gap, &base.own, &base.lead};
        const ExpPoly* plus[3] = {&Lp.gap, &Lp.own, &Lp.lead};
        const ExpPoly* minus[3] = {&Lm.gap, &Lm.own, &Lm.lead};
        ExpPoly* outs[3] = {&out.gap, &out.own, &out.lead};
        for (int k = 0; k < 3; ++k) {
            std::vector<double> delays;
            for (const ExpPoly* e : {bases[k], plus[k], minus[k]})
                for (const auto& t : e->terms()) delays.push_back(t.delay);
            std::sort(delays.begin(), delays.end());
            delays.erase(std::unique(delays.begin(), delays.end()), delays.end());
            auto coef = [](const ExpPoly& e, double d) {
                for (const auto& t : e.terms())
                    if (t.delay == d) return t.coef;
                return 0.0;
            };
            auto has = [](const ExpPoly& e, double d) {
                return std::any_of(e.terms().begin(), e.terms().end(), [d](const auto& t) { return t.delay == d; });
            };
            for (double d : delays) {
                const double dc = (coef(*plus[k], d) - coef(*minus[k], d)) / width;
                if (dc == 0.0) continue;
                if (!has(*bases[k], d)) return false;  // a delay that moves, or a term born at x
                outs[k]->add(dc, d);
            }
        }
        return true;
    }

    // The objective in x (gradient in x when asked); +inf / NaN where undefined.
    std::function<void()> tick;  // after every evaluation of a search (progress)
    long run_evaluations = 0;    // evaluations of the current run that were reported
    double value(const Eigen::VectorXd& x, Eigen::VectorXd* grad, DesignObjective o) {
        ++evaluations;
        if (tick) tick();
        if (m_scenarios.size() == 1) return value_at(x, grad, o);
        // robust: the worst scenario's value and its gradient (a maximum of smooth pieces, as the
        // objectives themselves are: the minimiser is made for that)
        double worst = -kInf;
        Eigen::VectorXd g, gw;
        bool undefined = false;
        for_each_scenario([&] {
            if (undefined) return;
            const double v = value_at(x, grad ? &g : nullptr, o);
            if (std::isnan(v) || v == kInf) {
                undefined = true;
                worst = v;
                return;
            }
            if (v > worst) {
                worst = v;
                gw = g;
            }
        });
        if (grad && !undefined) *grad = gw;
        return worst;
    }
    double value_at(const Eigen::VectorXd& x, Eigen::VectorXd* grad, DesignObjective o) {
        const Linearisation L = lin(x);
        if (!is_computable(L)) return kInf;  // outside the analyses' range: outside the search's domain
        if (o == DesignObjective::Abscissa) return m_opt.cars < 0 ? plant(x, L, grad) : ring(x, L, grad);
        const double a = plant(x, L, nullptr);
        if (!(a < 0.0)) return kInf;
        if (o == DesignObjective::Peak) {
            // the gradient from the sensitivity equations where every free parameter moves only
            // coefficients (k1, k2, th of ovrv); else differences of the norm
            std::vector<Linearisation> directions;
            bool exact = grad != nullptr;
            for (std::size_t j = 0; exact && j < n(); ++j) {
                Linearisation d;
                exact = lin_direction(x, j, L, d);
                directions.push_back(d);
            }
            if (!exact) directions.clear();
            std::vector<double> g;
            const double v = peak_value(L, a, directions, exact ? &g : nullptr);
            if (exact && std::isfinite(v) && g.size() == n() && Eigen::Map<const Eigen::VectorXd>(g.data(), static_cast<Eigen::Index>(n())).allFinite()) {
                *grad = Eigen::Map<const Eigen::VectorXd>(g.data(), static_cast<Eigen::Index>(n()));
                return v;
            }
            if (grad && std::isfinite(v)) {
                *grad = Eigen::VectorXd(static_cast<Eigen::Index>(n()));
                for (std::size_t j = 0; j < n(); ++j) {
                    const double d = difference(j, x, step(j, x, 1e-3), [&](const Eigen::VectorXd& y) {
                        const Linearisation Ly = lin(y);
                        return peak_value(Ly, plant(y, Ly, nullptr));
                    });
                    if (!std::isfinite(d)) return kInf;
                    (*grad)[static_cast<Eigen::Index>(j)] = d;
                }
            }
            return v;
        }
        const AttenuationScan s = attenuation_scan(L, m_opt.margin);
        return o == DesignObjective::SupGamma ? sup_objective(s, x, grad) : nearest_objective(s, x, grad);
    }

    static double margin_piece(const Linearisation& l, double omega, double m2) { return attenuation_piece(l, omega, m2); }

    struct Sqp {
        Status status = Status::MaxIterations;
        std::string message;
        Eigen::VectorXd x;
        int iterations = 0;
        std::vector<Eigen::VectorXd> path;  ///< the start and every step's point
    };

    // min sum_j M_j (y_j - x0_j)^2 subject to A y >= b, by the KKT conditions of every active set
    // of at most n constraints (the problem is convex: the feasible point with multipliers >= 0
    // is its minimum). false when no active set gives one (the constraints are inconsistent).
    bool solve_qp(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& M, const Eigen::VectorXd& c, Eigen::VectorXd& y) const {
        const int k = static_cast<int>(A.rows()), nn = static_cast<int>(A.cols());
        double best = kInf;
        // every active set S of at most n constraints (n <= 4; the robust design's scenarios
        // add rows, so the sets are enumerated as combinations, not as bit masks of all rows)
        std::vector<int> S;
        auto consider = [&] {
            const int size = static_cast<int>(S.size());
            Eigen::VectorXd cand = c, lambda;
            if (size > 0) {
                Eigen::MatrixXd As(size, nn);
                Eigen::VectorXd bs(size);
                for (int i = 0; i < size; ++i) {
                    As.row(i) = A.row(S[static_cast<std::size_t>(i)]);
                    bs[i] = b[S[static_cast<std::size_t>(i)]];
                }
                const Eigen::MatrixXd AMi = As * M.cwiseInverse().asDiagonal();
                const Eigen::MatrixXd K = AMi * As.transpose();
                Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
                if (lu.rank() < size) return;
                lambda = lu.solve(bs - As * c);
                if ((lambda.array() < -1e-12 * (1.0 + lambda.cwiseAbs().maxCoeff())).any()) return;
                cand = c + M.cwiseInverse().asDiagonal() * (As.transpose() * lambda);
            }
            const Eigen::VectorXd slack = A * cand - b;
            for (int i = 0; i < k; ++i)
                if (!(slack[i] >= -1e-10 * (std::abs(b[i]) + A.row(i).cwiseAbs().dot(cand.cwiseAbs()) + 1e-300))) return;  // NaN too
            const double obj = (cand - c).cwiseProduct(M).dot(cand - c);
            if (obj < best) {
                best = obj;
                y = cand;
            }
        };
        // the QP is strictly convex (M > 0): a feasible point with multipliers >= 0 is its unique
        // minimum, so the sets are tried by size (the active sets of the steps have one or two
        // rows) and the first such point ends the search; at most kQpSets sets are tried (the
        // robust design's scenarios add rows), beyond which the step counts as unsolved
        long tried = 0;
        std::function<bool(int, int)> extend = [&](int from, int size) {
            if (static_cast<int>(S.size()) == size) {
                ++tried;
                consider();
                return std::isfinite(best) || tried >= kQpSets;
            }
            for (int i = from; i < k; ++i) {
                S.push_back(i);
                const bool stop = extend(i + 1, size);
                S.pop_back();
                if (stop) return true;
            }
            return false;
        };
        for (int size = 0; size <= nn && !std::isfinite(best) && tried < kQpSets; ++size) extend(0, size);
        return std::isfinite(best);
    }

    // Nearest gains with mu >= margin^2 by sequential quadratic programming on the pieces of mu
    // (a semi-infinite constraint: every local minimum over w, each linearised at its frequency),
    // the box as bounds. Each step solves the convex QP exactly.
    Sqp nearest_sqp(const Eigen::VectorXd& start, int& scans) {
        Sqp out;
        const Eigen::Index nn = static_cast<Eigen::Index>(n());
        Eigen::VectorXd M(nn), c(nn), x = start;
        for (std::size_t j = 0; j < n(); ++j) {
            M[static_cast<Eigen::Index>(j)] = w[j] * w[j] / (x0[j] * x0[j]);
            c[static_cast<Eigen::Index>(j)] = x0[j];
        }
        // aimed 2e-6 above m^2: an iterate accepted to 1e-6 below the aim still meets the margin
        // (the crossing after the walk tests it exactly, and a result on a bound cannot step beyond)
        const double target = m_opt.margin * m_opt.margin * (1.0 + 2e-6);
        out.path.push_back(x);
        std::vector<double> history;  // distances of the iterates that meet the margin
        for (out.iterations = 0; out.iterations < kSqpSteps; ++out.iterations) {
            // the constraints of every scenario: each piece of its margin, linearised at its
            // frequency, and its plant kept stable, -alpha(x) - kPlantMargin >= 0 linearised with
            // the root sensitivity (the margin is not defined where it is not)
            std::vector<Eigen::VectorXd> rows;
            std::vector<double> rhs;
            std::vector<bool> is_piece;
            double least = kInf;
            bool unstable = false;
            for_each_scenario([&] {
                if (unstable) return;
                const Linearisation L = lin(x);
                Eigen::VectorXd ga;
                const double alpha = plant(x, L, &ga);
                if (!(alpha < 0.0)) {
                    unstable = true;
                    return;
                }
                const AttenuationScan sc = attenuation_scan(L);
                ++scans;
                for (const auto& piece : sc.mu_minima) {
                    const double om = piece.omega;
                    const Eigen::VectorXd g = partials(x, [om, target](const Linearisation& l) { return margin_piece(l, om, target); });
                    const double gv = margin_piece(L, om, target);
                    if (!g.allFinite() || !std::isfinite(gv)) continue;  // a piece that cannot be linearised: left out of this step
                    rows.push_back(g);
                    rhs.push_back(-gv + g.dot(x));
                    is_piece.push_back(true);
                    least = std::min(least, piece.mu);
                }
                rows.push_back(-ga);
                rhs.push_back(alpha + kPlantMargin - ga.dot(x));
                is_piece.push_back(false);
            });
            if (unstable) {
                out.status = Status::NumericalIssue;
                out.message = "an iterate has an unstable plant";
                out.x = x;
                return out;
            }
            for (Eigen::Index j = 0; j < nn; ++j) {
                Eigen::VectorXd e = Eigen::VectorXd::Zero(nn);
                e[j] = 1.0;
                rows.push_back(e);
                rhs.push_back(lo[static_cast<std::size_t>(j)]);
                is_piece.push_back(false);
                rows.push_back(-e);
                rhs.push_back(-hi[static_cast<std::size_t>(j)]);
                is_piece.push_back(false);
            }
            const int k = static_cast<int>(rows.size());
            Eigen::MatrixXd A(k, nn);
            Eigen::VectorXd b(k);
            for (int i = 0; i < k; ++i) {
                A.row(i) = rows[static_cast<std::size_t>(i)].transpose();
                b[i] = rhs[static_cast<std::size_t>(i)];
            }
            Eigen::VectorXd y;
            bool solved = solve_qp(A, b, M, c, y);
            // far from the boundary the linearised pieces may contradict each other within the
            // bounds: a restoration step on the most violated piece, x + t M^-1 grad g with t
            // taking its linearisation to 0, clipped to the box (the next step has them all again)
            if (!solved) {
                std::size_t worst = 0;
                double wv = kInf;
                for (std::size_t i = 0; i < is_piece.size(); ++i)
                    if (is_piece[i]) {
                        const double gi = A.row(static_cast<Eigen::Index>(i)).dot(x) - b[static_cast<Eigen::Index>(i)];  // g_i(x)
                        if (gi < wv) {
                            wv = gi;
                            worst = i;
                        }
                    }
                if (wv < 0.0) {
                    const Eigen::VectorXd gr = A.row(static_cast<Eigen::Index>(worst)).transpose();
                    const Eigen::VectorXd d = M.cwiseInverse().cwiseProduct(gr);
                    y = x + (-wv / gr.dot(d)) * d;
                    for (Eigen::Index j = 0; j < nn; ++j) y[j] = std::clamp(y[j], lo[static_cast<std::size_t>(j)], hi[static_cast<std::size_t>(j)]);
                    solved = (y - x).norm() > 0.0;
                }
            }
            if (!solved) {
                out.status = Status::NumericalIssue;
                out.message = "the linearised margin constraint has no solution within the bounds";
                out.x = x;
                return out;
            }
            // a step into the region of unstable plants is halved (the margin is not defined there)
            for (int half = 0; half < 30; ++half) {
                if (meets(y, 0.0, false)) break;
                y = x + 0.5 * (y - x);
            }
            const double step = std::sqrt((y - x).cwiseProduct(M).dot(y - x));
            const double dist = std::sqrt((y - c).cwiseProduct(M).dot(y - c));
            if (least >= target * (1.0 - 1e-6)) history.push_back(std::sqrt((x - c).cwiseProduct(M).dot(x - c)));
            else history.clear();
            x = y;
            out.path.push_back(x);
            // the linearisations come from differences of the law (relative error ~1e-10) at
            // frequencies located to ~1e-12: steps settle at about 1e-10 of the distance
            if (step <= 1e-8 * (1.0 + dist) && least >= target * (1.0 - 1e-6)) {
                out.status = Status::Converged;
                out.message = "sequential QP: the step fell below 1e-8 of the distance with the margin met (" + std::to_string(out.iterations + 1) +
                              " steps)";
                out.x = x;
                return out;
            }
        }
        // steps that keep oscillating at the rounding level of the linearisations while the
        // distance has settled: the last ten feasible iterates agree
        if (history.size() >= 10) {
            const auto [lo_d, hi_d] = std::minmax_element(history.end() - 10, history.end());
            if (*hi_d - *lo_d <= 1e-7 * (1.0 + *hi_d)) {
                out.status = Status::Converged;
                out.message = "sequential QP: the distance settled to 1e-7 over the last 10 of " + std::to_string(kSqpSteps) + " steps (the steps oscillate at the rounding of the linearisations)";
                out.x = x;
                return out;
            }
        }
        out.message = "sequential QP: no convergence in " + std::to_string(kSqpSteps) + " steps";
        out.x = x;
        return out;
    }

    NonsmoothFunction in_z(DesignObjective o) {
        return [this, o](const Eigen::VectorXd& z, Eigen::VectorXd& gz) {
            const Eigen::VectorXd x = x_of(z);
            Eigen::VectorXd gx;
            const double v = value(x, &gx, o);
            if (!std::isfinite(v)) return v;
            gz = gx.cwiseProduct(dx_dz(z));
            return v;
        };
    }
    ParameterMap free_map(const Eigen::VectorXd& x) const {
        ParameterMap m;
        for (std::size_t j = 0; j < n(); ++j) m[m_opt.free[j]] = x[static_cast<Eigen::Index>(j)];
        return m;
    }
};

// For the ovrv law with th and tau held, the low-frequency coefficient is
//     c2 = 2 k1 B,  B = k1 th (th/2 - tau) + k2 (th - tau) - 1,
// linear in (k1, k2): its largest value over a box is at a corner. When B < 0 at every corner,
// no gains of the box are string stable (nor have any attenuation margin). Returns that proof.
std::string ovrv_infeasibility(const std::string& model, const ParameterMap& p, const std::vector<std::string>& free,
                               const std::vector<double>& lo, const std::vector<double>& hi) {
    if (model != "ovrv") return {};
    double k1lo = p.at("k1"), k1hi = k1lo, k2lo = p.at("k2"), k2hi = k2lo;
    for (std::size_t j = 0; j < free.size(); ++j) {
        if (free[j] == "k1") {
            k1lo = lo[j];
            k1hi = hi[j];
        } else if (free[j] == "k2") {
            k2lo = lo[j];
            k2hi = hi[j];
        } else if (free[j] != "eta") {
            return {};
        }
    }
    const double th = p.at("th"), tau = p.at("tau");
    double best = -kInf;
    for (double k1 : {k1lo, k1hi})
        for (double k2 : {k2lo, k2hi}) best = std::max(best, k1 * th * (th / 2.0 - tau) + k2 * (th - tau) - 1.0);
    if (best >= 0.0) return {};
    return "no gains within the bounds are string stable: for ovrv, c2 = 2 k1 B with B = k1 th (th/2 - tau) + k2 (th - tau) - 1, linear in "
           "(k1, k2), is negative at every corner of the box (largest B = " +
           detail::significant(best, 6) + " with th = " + detail::significant(th, 6) + " s, tau = " + detail::significant(tau, 6) +
           " s), so |Gamma(i w)| > 1 at low frequencies for every k1, k2 there" + (th <= tau ? " (th <= tau: free th too)" : "");
}

}  // namespace

WorstMargin worst_attenuation_margin(const ParameterMap& parameters, const Eigen::Matrix<double, 5, 5>& covariance) {
    static const char* order[4] = {"k1", "k2", "th", "tau"};
    WorstMargin w;
    std::vector<int> held;
    for (int i = 0; i < 4; ++i)
        if (covariance(i, i) > 0.0 && std::isfinite(covariance(i, i))) held.push_back(i);
    const int d = static_cast<int>(held.size());
    // m* at a point (-inf where the plant is not stable: no attenuation to speak of)
    auto margin_at = [&](const ParameterMap& p) {
        ++w.evaluations;
        const Linearisation L = make_model("ovrv", p)->linearise();
        if (!is_computable(L)) return -kInf;
        RootOptions ro;
        ro.count = 2;
        const RootResult rr = rightmost_roots(plant_dde(L), ro);
        if (rr.status != Status::Converged || rr.roots.empty() || !(rr.roots.front().value.real() < 0.0)) {
            w.plant_unstable = true;
            return -kInf;
        }
        return attenuation_scan(L).margin;
    };
    w.nominal = margin_at(parameters);
    w.margin = w.nominal;
    for (int i : held) w.held.push_back(order[i]);
    for (int i : held) w.at[order[i]] = parameters.at(order[i]);
    if (d == 0) return w;
    static const double chi2[5] = {0.0, 3.841458820694124, 5.991464547107979, 7.814727903251178, 9.487729036781154};
    w.radius2 = chi2[d];
    Eigen::MatrixXd Ch(d, d);
    for (int a = 0; a < d; ++a)
        for (int b = 0; b < d; ++b) Ch(a, b) = covariance(held[static_cast<std::size_t>(a)], held[static_cast<std::size_t>(b)]);
    const Eigen::LLT<Eigen::MatrixXd> llt(Ch);
    if (llt.info() != Eigen::Success) throw std::invalid_argument("worst attenuation margin: the covariance of the held parameters is not positive definite");
    const Eigen::MatrixXd Lc = llt.matrixL();
    const double r = std::sqrt(w.radius2);
    // the point p0 + s r L u, clipped to the law's domain
    auto point = [&](const Eigen::VectorXd& u, double s) {
        ParameterMap p = parameters;
        const Eigen::VectorXd dp = s * r * (Lc * u);
        for (int a = 0; a < d; ++a) {
            const int i = held[static_cast<std::size_t>(a)];
            double v = parameters.at(order[i]) + dp[a];
            v = std::max(v, i < 2 ? 1e-9 : 0.0);
            p[order[i]] = v;
        }
        return p;
    };
    auto consider = [&](const Eigen::VectorXd& u, double s) {
        const ParameterMap p = point(u, s);
        const double m = margin_at(p);
        if (m < w.margin) {
            w.margin = m;
            for (int i : held) w.at[order[i]] = p.at(order[i]);
        }
        return m;
    };
    std::vector<Eigen::VectorXd> dirs;
    if (d == 1) {
        dirs = {Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, -1.0)};
    } else if (d == 2) {
        for (int k = 0; k < 72; ++k) {
            const double t = 2.0 * M_PI * k / 72.0;
            Eigen::VectorXd u(2);
            u << std::cos(t), std::sin(t);
            dirs.push_back(u);
        }
    } else {
        std::mt19937_64 rng(20261129);
        std::normal_distribution<double> z(0.0, 1.0);
        for (int k = 0; k < 200; ++k) {
            Eigen::VectorXd u(d);
            for (int a = 0; a < d; ++a) u[a] = z(rng);
            dirs.push_back(u.normalized());
        }
    }
    int best = 0;
    double best_m = kInf;
    for (std::size_t k = 0; k < dirs.size(); ++k) {
        consider(dirs[k], 0.5);
        const double m = consider(dirs[k], 1.0);
        if (m < best_m) {
            best_m = m;
            best = static_cast<int>(k);
        }
    }
    if (d == 2 && std::isfinite(best_m)) {
        // golden section in the angle around the least of the grid, on the boundary (consider
        // keeps the least value and its point; the evaluations are counted there)
        const double h = 2.0 * M_PI / 72.0, a = 2.0 * M_PI * best / 72.0 - h;
        auto at_angle = [&](double t) {
            Eigen::VectorXd u(2);
            u << std::cos(t), std::sin(t);
            return consider(u, 1.0);
        };
        double least = 0.0;
        int calls = 0;
        golden_minimize(at_angle, a, a + 2.0 * h, least, calls, 1e-6, 30);
    }
    return w;
}

namespace {
DesignResult design_at(const std::string& model, const ParameterMap& parameters, const DesignOptions& options,
                       const std::vector<ParameterMap>& scenarios, ParameterMap* proof_at = nullptr);
}  // namespace

DesignResult design_gains(const std::string& model, const ParameterMap& parameters, const DesignOptions& options) {
    options.validate();
    if (!options.robust) return design_at(model, parameters, options, {ParameterMap{}});
    // worst-case iteration (an exchange method): design for the car's own held values and every
    // worst point met so far at once, add the new design's worst point of the ellipsoid, repeat
    DesignOptions o = options;
    o.robust = false;
    std::vector<ParameterMap> scenarios{ParameterMap{}};
    ParameterMap proof_at;
    DesignResult r;
    std::vector<DesignResult::RobustStep> steps;
    for (int it = 0; it < options.robust_iterations; ++it) {
        r = design_at(model, parameters, o, scenarios, &proof_at);
        steps.push_back({scenarios.back(), r.gains, r.worst.margin});
        // met; or nothing to iterate on: no gains at all (a proof), a design that did not
        // converge, nothing held, an unstable plant in the ellipsoid, a worst point already in
        // the set (the design does not meet the margin there)
        if (r.worst.margin >= options.margin * (1.0 - 1e-6) || !r.infeasibility_proof.empty() || r.status != Status::Converged || r.worst.held.empty() ||
            r.worst.plant_unstable)
            break;
        ParameterMap next;
        for (const std::string& h : r.worst.held) next[h] = r.worst.at.at(h);
        if (std::find(scenarios.begin(), scenarios.end(), next) != scenarios.end()) break;
        scenarios.push_back(next);
    }
    r.robust = true;
    r.robust_steps = steps;
    r.robust_met = r.worst.margin >= options.margin * (1.0 - 1e-6);
    std::string path;
    for (const auto& st : steps) path += (path.empty() ? "" : ", ") + detail::significant(st.worst_margin, 4) + " s";
    if (!r.infeasibility_proof.empty() && !r.robust_met) {
        const ParameterMap& at = proof_at;
        if (at.empty()) {
            if (r.message.find(r.infeasibility_proof) == std::string::npos) r.message += "; " + r.infeasibility_proof;
            r.message += "; so no robust design either";
        } else {
            // the proof holds at a point of the ellipsoid: no gains of the box are robust
            std::string point;
            for (const auto& [k, v] : at) {
                std::string unit;
                for (const ParameterSpec& sp : model_parameters(model))
                    if (sp.name == k && !sp.unit.empty() && sp.unit != "1") unit = " " + sp.unit;
                point += (point.empty() ? "" : ", ") + k + " = " + detail::significant(v, 6) + unit;
            }
            r.message = "no robust design within the bounds: at " + point + ", a point of the fit's 95 % ellipsoid of " + join(r.worst.held, ", ") +
                        " (the worst for an earlier design), " + r.infeasibility_proof;
        }
    } else if (r.status == Status::Converged && !r.robust_met) {
        r.status = Status::MaxIterations;
        r.message = "robust design: the worst attenuation margin over the fit's 95 % ellipsoid of " + join(r.worst.held, ", ") + " stays below " +
                    detail::significant(options.margin, 6) + " s after " + std::to_string(steps.size()) + " designs (worst margins " + path +
                    (r.worst.plant_unstable ? "; the plant is unstable somewhere in the ellipsoid" : "") + "): not a robust design";
    } else if (r.status == Status::Converged) {
        r.message += "; robust: the worst attenuation margin over the fit's 95 % ellipsoid of " + join(r.worst.held, ", ") + " is " +
                     detail::significant(r.worst.margin, 6) + " s >= " + detail::significant(options.margin, 6) + " s after " + std::to_string(steps.size()) +
                     " design" + (steps.size() == 1 ? "" : "s") + " (worst margins " + path + ")";
    }
    return r;
}

namespace {
DesignResult design_at(const std::string& model, const ParameterMap& parameters, const DesignOptions& options,
                       const std::vector<ParameterMap>& scenarios, ParameterMap* proof_at) {
    const auto car = make_model(model, parameters);  // validates the car itself
    const Linearisation lin0 = car->linearise();
    if (lin0.leaders() > 1) require_single_leader(lin0, "design");
    require_computable(lin0, "the car to design from");
    const std::vector<std::string> names = car->law_parameter_names();
    const std::vector<ParameterSpec> specs = model_parameters(model);
    DesignResult r;
    r.objective = to_string(options.objective);
    r.model = model;
    r.free = options.free;
    r.initial = car->parameters();
    Problem P(model, r.initial, options);
    P.m_scenarios = scenarios;
    // a proof that no gains of the box are string stable at one of the held values the search
    // works at (robust design: the car's own and points of the ellipsoid); where it holds
    auto proof_any = [&] {
        for (const ParameterMap& sc : P.m_scenarios) {
            ParameterMap held = r.initial;
            for (const auto& [k, v] : sc) held[k] = v;
            std::string proof = ovrv_infeasibility(model, held, options.free, P.lo, P.hi);
            if (!proof.empty()) {
                if (proof_at) *proof_at = sc;
                return proof;
            }
        }
        return std::string();
    };
    for (const BoundedParameter& b : options.bounds)
        if (std::find(options.free.begin(), options.free.end(), b.name) == options.free.end())
            throw std::invalid_argument("design: a bound on " + b.name + ", which is not free: expected bounds on the free parameters (" +
                                        join(options.free, ", ") + ") only");
    for (std::size_t j = 0; j < options.free.size(); ++j) {
        const std::string& name = options.free[j];
        if (std::find(names.begin(), names.end(), name) == names.end())
            throw std::invalid_argument("design: free parameter " + detail::quoted(name) + ": expected one of the " + model + " law's parameters (" +
                                        join(names, ", ") + ")");
        const double v = r.initial.at(name);
        const ParameterSpec* spec = nullptr;
        for (const ParameterSpec& s : specs)
            if (s.name == name) spec = &s;
        double lo, hi;
        if (const BoundedParameter* b = find_bound(options.bounds, name)) {
            lo = b->lower;
            hi = b->upper;
        } else {
            if (!(v > 0.0))
                throw std::invalid_argument("design: " + name + " = " + detail::significant(v, 6) + " has no default bound [" + name + "/10, 10 " + name +
                                            "]: give its bounds");
            lo = v / 10.0;
            hi = v * 10.0;
        }
        if (!(hi > lo))
            throw std::invalid_argument("design: bounds of " + name + " = " + detail::significant(lo, 6) + ":" + detail::significant(hi, 6) +
                                        ": expected LO < HI");
        if (spec && (lo < spec->lower || (spec->lower_open && lo <= spec->lower)))
            throw std::invalid_argument("design: lower bound of " + name + " = " + detail::significant(lo, 6) + ": expected " +
                                        (spec->lower_open ? "> " : ">= ") + detail::significant(spec->lower, 6) + " (the law's domain)");
        if (options.objective == DesignObjective::Nearest && v == 0.0)
            throw std::invalid_argument("design: nearest measures relative changes, and " + name + " = 0 at the car: expected a nonzero value");
        P.lo.push_back(lo);
        P.hi.push_back(hi);
        P.x0.push_back(v);
        P.w.push_back(options.weights.empty() ? 1.0 : options.weights[j]);
        r.bounds.push_back({name, lo, hi});
    }
    const std::size_t n = options.free.size();
    Eigen::VectorXd x0(static_cast<Eigen::Index>(n));
    for (std::size_t j = 0; j < n; ++j) x0[static_cast<Eigen::Index>(j)] = P.x0[j];

    StringOptions so;
    so.peak = true;
    so.peak_options = options.peak;
    r.string_initial = analyse_string(lin0, so);
    if (r.string_initial.plant_stable) r.attenuation_initial = attenuation_scan(lin0, options.margin);
    if (options.cars >= 0) r.ring_initial = analyse_ring_fast(lin0, options.cars, resolve_ring_method("auto", lin0), 0).ring;
    r.value_initial = P.value(x0, nullptr, options.objective);
    if (std::isnan(r.value_initial)) r.value_initial = kInf;

    // starts: the car's own values moved a thousandth of the width inside the box, then Halton points
    std::vector<Eigen::VectorXd> starts;
    {
        Eigen::VectorXd s = x0;
        for (std::size_t j = 0; j < n; ++j) {
            // strictly inside: as it is; on or beyond a bound: a millionth of the width inside it
            // (at a bound itself the coordinate z has a zero derivative)
            const double m = 1e-6 * (P.hi[j] - P.lo[j]);
            double& v = s[static_cast<Eigen::Index>(j)];
            if (!(v > P.lo[j] && v < P.hi[j])) v = std::clamp(v, P.lo[j] + m, P.hi[j] - m);
        }
        starts.push_back(s);
        static const int primes[8] = {2, 3, 5, 7, 11, 13, 17, 19};
        for (int i = 1; i < options.starts; ++i) {
            Eigen::VectorXd h(static_cast<Eigen::Index>(n));
            for (std::size_t j = 0; j < n; ++j) h[static_cast<Eigen::Index>(j)] = P.lo[j] + (P.hi[j] - P.lo[j]) * halton(i, primes[j]);
            starts.push_back(h);
        }
    }

    struct Outcome {
        double best = kInf;
        Eigen::VectorXd x;
        Status status = Status::NumericalIssue;
        std::string message = "no start gave a finite objective";
    };
    const bool two_phases = options.objective == DesignObjective::SupGamma;
    // the peak norm is computed to 1e-6 during the search and each evaluation integrates the
    // step response with its sensitivities (4 + 4n states; 1 + 2n norms where a free parameter
    // moves a delay): a looser stationarity test and a budget of kPeakEvaluations per run
    NonsmoothOptions search = options.optimizer;
    if (options.objective == DesignObjective::Peak) {
        search.max_evaluations = std::min(search.max_evaluations, kPeakEvaluations);
        search.stationarity_tolerance = std::max(search.stationarity_tolerance, 1e-4);
    }
    // both are at least 1: reaching 1 is a global minimum, the run stops there
    if (options.objective == DesignObjective::Peak) search.target = 1.0 + std::max(options.peak.tolerance, 1e-6);
    if (options.objective == DesignObjective::SupGamma) search.target = 1.0 + 1e-9;
    // progress in evaluations: every run counts its budget (an upper bound), the runs of
    // nearest (sequential QP) and the second phase of sup-gamma one unit each
    const long per_run = options.objective == DesignObjective::Nearest ? 1 : search.max_evaluations;
    const long total = static_cast<long>(starts.size()) * (per_run + (two_phases ? 1 : 0)) +
                       (options.objective == DesignObjective::Peak ? static_cast<long>(starts.size()) + per_run : 0);
    long done = 0;
    P.tick = [&] {
        if (options.progress && per_run > 1 && P.run_evaluations < per_run) {
            ++P.run_evaluations;
            options.progress(++done, total);
        }
    };
    // one run of the minimiser of objective `o` from every start; the best end
    auto run = [&](DesignObjective o) {
        Outcome out;
        out.x = starts.front();
        for (std::size_t k = 0; k < starts.size(); ++k) {
            DesignStart ds;
            ds.objective = to_string(o);
            ds.start = P.free_map(starts[k]);
            const int ev0 = P.evaluations;
            Eigen::VectorXd z = P.z_of(starts[k]);
            NonsmoothResult nr;
            bool ok = true;
            // the run's path in the free parameters (every stage's iterates, in order)
            auto add_z = [&](const std::vector<Eigen::VectorXd>& zs) {
                for (const Eigen::VectorXd& zz : zs) ds.path.push_back(P.free_map(P.x_of(zz)));
            };
            // an unstable plant first: lower the plant's abscissa below zero
            if (o != DesignObjective::Abscissa) {
                const double a = P.value(P.x_of(z), nullptr, DesignObjective::Abscissa);
                if (!(a < 0.0)) {
                    NonsmoothOptions o1 = search;
                    o1.target = -1e-3;
                    nr = minimize_nonsmooth(P.in_z(DesignObjective::Abscissa), z, o1);
                    add_z(nr.path);
                    if (nr.status == Status::Converged && nr.value < 0.0) {
                        z = nr.x;
                    } else {
                        ok = false;
                        ds.status = nr.status;
                        ds.message = "the plant is unstable here and its abscissa could not be brought below zero (least " +
                                     detail::significant(nr.value, 6) + " 1/s)";
                        ds.value = kInf;
                    }
                }
            }
            if (ok && o == DesignObjective::Nearest && n <= 4) {
                int scans = 0;
                const Problem::Sqp q = P.nearest_sqp(P.x_of(z), scans);
                for (const Eigen::VectorXd& xx : q.path) ds.path.push_back(P.free_map(xx));
                P.evaluations += scans;
                ds.status = q.status;
                ds.message = q.message;
                ds.iterations = q.iterations;
                z = P.z_of(q.x);
                // the distance where feasible (the worst scenario's penalty added where not)
                const double viol = 1.0 - P.least_margin(q.x) / options.margin;
                ds.value = P.distance(q.x, nullptr) + (viol > 0.0 ? P.rho * viol : 0.0);
            } else if (ok) {
                if (o == DesignObjective::Nearest) {
                    P.rho = 10.0;
                    for (int round = 0; round < 4; ++round) {
                        nr = minimize_nonsmooth(P.in_z(o), z, search);
                        add_z(nr.path);
                        if (!std::isfinite(nr.value)) break;
                        z = nr.x;
                        if (P.least_margin(P.x_of(z)) >= options.margin * (1.0 - 1e-6)) break;
                        P.rho *= 10.0;  // the penalty was too weak: the end is outside the set
                    }
                } else {
                    nr = minimize_nonsmooth(P.in_z(o), z, search);
                    add_z(nr.path);
                }
                ds.status = nr.status;
                ds.message = nr.message;
                ds.iterations = nr.iterations;
                ds.value = std::isfinite(nr.value) ? nr.value : kInf;
                z = nr.x;
            }
            const Eigen::VectorXd xe = P.x_of(z);
            ds.end = P.free_map(xe);
            if (ds.path.empty() || ds.path.front() != ds.start) ds.path.insert(ds.path.begin(), ds.start);
            if (ds.path.back() != ds.end) ds.path.push_back(ds.end);
            ds.evaluations = P.evaluations - ev0;
            // nearest: compare the runs by distance among the feasible ends
            double score = ds.value;
            if (o == DesignObjective::Nearest && std::isfinite(score)) {
                const bool feasible = P.meets(xe, options.margin * (1.0 - 1e-6));
                score = feasible ? P.distance(xe, nullptr) : 1e6 + score;
            }
            // ties (the plateau of peak: every non-overshooting design) go to the run that ended
            // nearest the car's own values
            const double tie = std::isfinite(out.best) ? 1e-12 * std::max(1.0, std::abs(out.best)) : 0.0;
            const bool better = !std::isfinite(out.best)
                                    ? score < out.best
                                    : score < out.best - tie || (std::abs(score - out.best) <= tie && P.distance(xe, nullptr) < P.distance(out.x, nullptr));
            if (better) {
                out.best = score;
                out.x = xe;
                out.status = ds.status;
                out.message = ds.message;
            }
            r.starts.push_back(ds);
            // sup-gamma and peak are at least 1: a run that reached 1 found a global minimum,
            // and the remaining starts are not run (their budgets count as done)
            const double floor_tol = o == DesignObjective::Peak ? std::max(options.peak.tolerance, 1e-6) : 1e-9;
            if ((o == DesignObjective::Peak || o == DesignObjective::SupGamma) && out.best <= 1.0 + floor_tol) {
                done += static_cast<long>(starts.size() - k - 1) * per_run;
                k = starts.size();
            }
            // the rest of this run's budget (or its one unit)
            const long unit = o == DesignObjective::Nearest ? 1 : per_run;
            done += std::max(0L, unit - P.run_evaluations);
            P.run_evaluations = 0;
            if (options.progress) options.progress(done, total);
        }
        return out;
    };
    // nearest: the crossing on the segment from the car's own values (infeasible) to the best
    // end, by bisection; false when no run ended feasible
    auto crossing = [&](const Outcome& out, Eigen::VectorXd& x) {
        if (!std::isfinite(out.best) || out.best >= 1e6) return false;
        // x0 + t (x_end - x0) at t = 1 differs from x_end by rounding: an end on a bound (the
        // relative metric often takes the delay to its lower bound) is snapped back onto it
        auto in_box = [&](Eigen::VectorXd& y) {
            for (std::size_t j = 0; j < n; ++j) {
                const auto J = static_cast<Eigen::Index>(j);
                const double slack = 1e-12 * (std::abs(P.lo[j]) + std::abs(P.hi[j]));
                if (y[J] < P.lo[j] && y[J] >= P.lo[j] - slack) y[J] = P.lo[j];
                if (y[J] > P.hi[j] && y[J] <= P.hi[j] + slack) y[J] = P.hi[j];
                if (y[J] < P.lo[j] || y[J] > P.hi[j]) return false;
            }
            return true;
        };
        auto feasible = [&](Eigen::VectorXd y) {
            if (!in_box(y)) return false;
            return P.meets(y, options.margin);
        };
        if (feasible(x0)) {
            x = x0;
            return true;
        }
        double t_in = -1.0;
        for (double t = 1.0; t <= 1.0 + 1e-2; t = 1.0 + 2.0 * (t - 1.0) + 1e-9) {
            Eigen::VectorXd y = x0 + t * (out.x - x0);
            if (!in_box(y)) break;
            if (feasible(y)) {
                t_in = t;
                break;
            }
        }
        if (t_in < 0.0) return false;
        double a = 0.0, b = t_in;  // x0 + a d infeasible (or outside the box), x0 + b d feasible
        for (int it = 0; it < 60 && (b - a) > 1e-13 * b; ++it) {
            const double m = 0.5 * (a + b);
            if (feasible(x0 + m * (out.x - x0))) b = m;
            else a = m;
        }
        x = x0 + b * (out.x - x0);
        in_box(x);  // onto a bound it lies on
        return true;
    };

    // peak: peak stability implies L2 stability. Without L2-stable gains in the box (proved)
    // there is nothing to search; else the search starts also from the nearest L2 design (a
    // cheap sequential QP), inside the set where ||h||_1 can reach 1.
    const std::string l2_proof = proof_any();
    bool skipped = options.objective == DesignObjective::Nearest && !l2_proof.empty();  // nothing to find
    if (options.objective == DesignObjective::Peak) {
        if (!l2_proof.empty()) {
            skipped = true;
        } else {
            const Outcome l2 = run(DesignObjective::Nearest);
            Eigen::VectorXd xn;
            if (crossing(l2, xn)) starts.insert(starts.begin(), xn);
            // a run that reaches ||h||_1 = 1 ends the search (a global minimum), and a run costs
            // up to kPeakEvaluations norms with their gradients: the starts are run in the order
            // of their norm (one norm each; where it cannot be computed within the search's
            // step budget, last, in the order given)
            const auto tick = P.tick;
            P.tick = nullptr;
            std::vector<std::pair<double, std::size_t>> order;
            for (std::size_t k = 0; k < starts.size(); ++k) {
                const double v = P.value(starts[k], nullptr, DesignObjective::Peak);
                order.emplace_back(std::isfinite(v) ? v : kInf, k);
            }
            P.tick = tick;
            std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            std::vector<Eigen::VectorXd> sorted;
            for (const auto& [v, k] : order) sorted.push_back(starts[k]);
            starts = std::move(sorted);
        }
    }
    const Outcome first = skipped ? Outcome{} : run(options.objective);
    Eigen::VectorXd x = skipped ? x0 : first.x;
    Status best_status = skipped ? Status::Converged : first.status;
    std::string best_message = !skipped ? first.message
                               : options.objective == DesignObjective::Peak
                                   ? l2_proof + "; peak (L-infinity) stability implies it, so no gains of the box are peak stable either"
                                   : l2_proof;
    bool infeasible = false, plateau = false;
    const std::size_t n_starts = starts.size();
    if (options.objective == DesignObjective::Nearest) {
        infeasible = skipped || !crossing(first, x);
        if (infeasible && !skipped) {
            // no sequential QP reached the set: look for a point of it by minimising the weighted
            // norm (which is 1 exactly there), then walk its boundary to the car from that point
            const Outcome reach = run(DesignObjective::SupGamma);
            if (reach.best <= 1.0 + 1e-9) {
                starts.assign(1, reach.x);
                const Outcome again = run(DesignObjective::Nearest);
                if (crossing(again, x)) {
                    infeasible = false;
                    best_status = again.status;
                    best_message = again.message;
                } else {
                    // the walk did not converge: the crossing toward the point found, a design
                    // that meets the margin but is not shown to be the nearest
                    Outcome found = reach;
                    found.best = P.distance(reach.x, nullptr);
                    if (crossing(found, x)) {
                        infeasible = false;
                        best_status = again.status == Status::Converged ? Status::MaxIterations : again.status;
                        best_message = "gains with the margin found (the crossing toward a point where the weighted norm is 1), but the walk to the "
                                       "nearest ones did not converge (" + again.message + "): not shown to be the nearest";
                    }
                }
            }
        }
    } else if (two_phases && first.best <= 1.0 + 1e-9) {
        // sup-gamma reached its least value 1: of those gains, the nearest to the car's own,
        // the point that reached it among the starts
        starts.insert(starts.begin(), first.x);
        const Outcome second = run(DesignObjective::Nearest);
        Eigen::VectorXd xn;
        if (crossing(second, xn)) {
            plateau = true;
            x = xn;
            best_status = second.status;
            best_message = second.message;
        }
    } else if (options.objective == DesignObjective::Peak && !skipped && first.best <= 1.0 + std::max(options.peak.tolerance, 1e-6)) {
        // peak reached its least value 1 (no overshoot), on a plateau of such gains; the runs are
        // ordered by their start's norm, so the point may lie far from the car: on the segment
        // from the car's own values to it (the part inside the box), a point peak stable by the
        // result's own verdict, found by bisection on that verdict toward the car (the nearest
        // such point of the segment when those points form one interval; the point itself is
        // kept where that verdict does not confirm it)
        auto stable_at = [&](const Eigen::VectorXd& y) {
            bool ok = true;
            P.for_each_scenario([&] {
                if (!ok) return;
                const Linearisation Ly = P.lin(y);
                const double a = P.plant(y, Ly, nullptr);
                ok = a < 0.0 && peak_string_stability(Ly, a, options.peak).verdict == Verdict::Stable;
            });
            return ok;
        };
        // the segment's points x0 + t (x - x0) inside the box: t >= t_in (x is inside)
        double t_in = 0.0;
        for (std::size_t j = 0; j < n; ++j) {
            const auto J = static_cast<Eigen::Index>(j);
            const double d = x[J] - x0[J];
            if (x0[J] < P.lo[j] && d > 0.0) t_in = std::max(t_in, (P.lo[j] - x0[J]) / d);
            if (x0[J] > P.hi[j] && d < 0.0) t_in = std::max(t_in, (P.hi[j] - x0[J]) / d);
        }
        auto point = [&](double t) {  // on the segment, snapped into the box (rounding at t_in)
            Eigen::VectorXd y = x0 + t * (x - x0);
            for (std::size_t j = 0; j < n; ++j) y[static_cast<Eigen::Index>(j)] = std::clamp(y[static_cast<Eigen::Index>(j)], P.lo[j], P.hi[j]);
            return y;
        };
        if (t_in < 1.0 && stable_at(x)) {
            double lo_t = t_in, hi_t = 1.0;  // point(lo_t) not (or not shown) peak stable, point(hi_t) peak stable
            if (stable_at(point(t_in))) hi_t = t_in;
            for (int it = 0; it < 30 && hi_t - lo_t > 1e-4; ++it) {
                const double m = 0.5 * (lo_t + hi_t);
                if (stable_at(point(m))) hi_t = m;
                else lo_t = m;
            }
            if (hi_t < 1.0) {
                // recorded as a stage of its own, so that the path drawn ends at the result
                DesignStart walk;
                walk.objective = "peak";
                walk.start = P.free_map(x);
                x = point(hi_t);
                walk.end = P.free_map(x);
                walk.path = {walk.start, walk.end};
                const int ev0 = P.evaluations;
                walk.value = P.value(x, nullptr, DesignObjective::Peak);
                walk.evaluations = P.evaluations - ev0;
                walk.message = "bisection on the peak verdict toward the car's own values";
                r.starts.push_back(walk);
                best_message += "; walked back toward the car's own values along the segment to the edge of the gains with no overshoot (bisection on the peak verdict)";
            }
        }
    }
    if (options.progress && done < total) options.progress(total, total);
    if (infeasible) {
        x = x0;  // nothing found: the car's own values, unchanged
        const std::string proof = proof_any();
        best_status = proof.empty() ? Status::BudgetExhausted : Status::Converged;
        best_message = proof.empty() ? "no gains with an attenuation margin of at least " + detail::significant(options.margin, 6) +
                                           " s found within the bounds from " + std::to_string(n_starts) +
                                           " starts (not a proof that none exist: widen the bounds, free more parameters or add starts)"
                                     : proof;
    }

    r.gains = P.free_map(x);
    r.parameters = P.params(x);
    const Linearisation L = P.nominal(x);
    r.value = P.value(x, nullptr, options.objective);
    if (std::isnan(r.value)) r.value = kInf;
    r.change = P.distance(x, nullptr);
    if (options.objective == DesignObjective::Nearest) {  // its objective is the change itself
        r.value_initial = 0.0;
        r.value = r.change;
    }
    for (std::size_t j = 0; j < n; ++j) {
        const double xj = x[static_cast<Eigen::Index>(j)];
        if (xj - P.lo[j] <= 1e-9 * std::max(std::abs(P.lo[j]), std::abs(xj)) || P.hi[j] - xj <= 1e-9 * std::max(std::abs(P.hi[j]), std::abs(xj)))
            r.at_bound.push_back(options.free[j]);
    }
    r.string = analyse_string(L, so);
    if (r.string.plant_stable) {
        r.attenuation = attenuation_scan(L, options.margin);
        r.margin_met = r.attenuation.margin >= options.margin * (1.0 - 1e-9);
    }
    if (options.cars >= 0) {
        const FastRing fr = analyse_ring_fast(L, options.cars, resolve_ring_method("auto", L), 0);
        r.ring = fr.ring;
        r.ring_method = fr.method_used;
    }
    const std::string bfgs = "BFGS with a weak-Wolfe line search, gradient sampling where it stalls (Lewis-Overton)";
    const std::string sqp = n <= 4 ? "sequential quadratic programming on the pieces of the attenuation margin"
                                   : "an exact penalty minimised by " + bfgs;
    r.method = options.objective == DesignObjective::Nearest ? sqp : plateau ? bfgs + "; on its plateau, the nearest gains by " + sqp : bfgs;
    if (options.has_covariance) {
        if (model != "ovrv") throw std::invalid_argument("design: a covariance goes with the ovrv law (k1, k2, th, tau, eta); the car is " + model);
        static const char* order[5] = {"k1", "k2", "th", "tau", "eta"};
        Eigen::Matrix<double, 5, 5> C = options.covariance;
        UncertaintyOptions uo;
        uo.samples = options.uncertainty_samples;
        uo.ring_samples = 0;
        for (const BoundedParameter& b : classification_domain())
            if (std::find(options.free.begin(), options.free.end(), b.name) == options.free.end()) uo.domain.push_back(b);
        for (int i = 0; i < 5; ++i)
            if (std::find(options.free.begin(), options.free.end(), order[i]) != options.free.end()) {
                C.row(i).setZero();
                C.col(i).setZero();
            }
        ParameterMap at_car, at_design;
        for (const char* k : order) {
            at_car[k] = r.initial.at(k);
            at_design[k] = r.parameters.at(k);
        }
        r.uncertainty_initial = classify_with_uncertainty(at_car, C, 22, uo);
        r.uncertainty = classify_with_uncertainty(at_design, C, 22, uo);
        r.worst_initial = worst_attenuation_margin(at_car, C);
        r.worst = worst_attenuation_margin(at_design, C);
        r.has_uncertainty = true;
    }
    r.evaluations = P.evaluations;
    r.infeasibility_proof = proof_any();
    r.status = best_status;
    r.message = best_message;
    const PeakResult& pk = *r.string.peak;
    if (r.status == Status::Converged) {
        if (r.string.string_verdict == Verdict::Undecided) {
            r.status = r.string.plant_roots.status;
            r.message = "the verdict at the result is undecided: " + r.string.plant_roots.message;
        } else if (pk.verdict == Verdict::Undecided) {
            r.status = pk.status;
            r.message = "the peak verdict at the result is undecided: " + pk.message;
        } else if (r.ring && r.ring->status != Status::Converged) {
            r.status = r.ring->status;
            r.message = "the ring verdict at the result is undecided: " + r.ring->reason;
        } else if (infeasible || skipped) {
            r.message = best_message;
        } else if (options.objective == DesignObjective::Nearest || plateau) {
            r.message = std::string(plateau ? "sup |Gamma(i w)| |1 + i m w| reaches its least value 1 (m = " + detail::significant(options.margin, 6) +
                                                  " s); of those gains, the nearest to the car's: a relative change of "
                                            : "the nearest gains found with an attenuation margin of at least " +
                                                  detail::significant(options.margin, 6) + " s: a relative change of ") +
                        detail::significant(r.change, 6) + " (" + std::to_string(r.starts.size()) + " runs of the minimisers)";
        } else if (options.objective != DesignObjective::Abscissa && !r.string.string_stable) {
            const std::string proof = proof_any();
            r.message = proof.empty() ? "no string-stable gains found within the bounds from " + std::to_string(n_starts) +
                                            " starts (not a proof that none exist): the least objective found is " + detail::significant(r.value, 8) +
                                            " (" + best_message + ")"
                                      : proof + "; the least objective found is " + detail::significant(r.value, 8);
        } else {
            r.message = "best of " + std::to_string(r.starts.size()) + " runs: " + best_message;
        }
    }
    return r;
}
}  // namespace

}  // namespace ddemap
