#include "ddemap/solve/optimize/nonsmooth.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/internal/text.hpp"

namespace ddemap {

bool NonsmoothOptions::is_valid(std::string* why) const {
    auto fail = [&](const std::string& m) {
        if (why) *why = m;
        return false;
    };
    if (max_iterations < 1) return fail("max_iterations = " + std::to_string(max_iterations) + ": expected at least 1");
    if (max_evaluations < 10) return fail("max_evaluations = " + std::to_string(max_evaluations) + ": expected at least 10");
    if (!(stationarity_tolerance > 0.0) || !std::isfinite(stationarity_tolerance))
        return fail("stationarity_tolerance = " + detail::significant(stationarity_tolerance, 6) + ": expected a finite number > 0");
    if (!(sampling_radius > 0.0) || !std::isfinite(sampling_radius))
        return fail("sampling_radius = " + detail::significant(sampling_radius, 6) + ": expected a finite number > 0");
    if (!(final_radius > 0.0) || !(final_radius <= sampling_radius))
        return fail("final_radius = " + detail::significant(final_radius, 6) + ": expected a number in (0, sampling_radius]");
    if (bundle_size < 2) return fail("bundle_size = " + std::to_string(bundle_size) + ": expected at least 2");
    if (!(step_tolerance >= 0.0) || !std::isfinite(step_tolerance))
        return fail("step_tolerance = " + detail::significant(step_tolerance, 6) + ": expected a finite number >= 0");
    if (std::isnan(target)) return fail("target is NaN: expected a number or -infinity");
    return true;
}

void NonsmoothOptions::validate() const {
    std::string why;
    if (!is_valid(&why)) throw std::invalid_argument("nonsmooth options: " + why);
}

namespace {

// Euclidean projection onto the simplex {l >= 0, sum l = 1} (sort-based).
Eigen::VectorXd project_simplex(const Eigen::VectorXd& v) {
    std::vector<double> u(v.data(), v.data() + v.size());
    std::sort(u.begin(), u.end(), std::greater<double>());
    double cum = 0.0, theta = 0.0;
    for (std::size_t i = 0; i < u.size(); ++i) {
        cum += u[i];
        const double t = (cum - 1.0) / static_cast<double>(i + 1);
        if (u[i] - t > 0.0) theta = t;
    }
    return (v.array() - theta).max(0.0).matrix();
}

}  // namespace

Eigen::VectorXd min_norm_in_hull(const Eigen::MatrixXd& G) {
    const Eigen::Index m = G.cols();
    if (m == 0) throw std::invalid_argument("min_norm_in_hull: expected at least one vector");
    if (m == 1) return G.col(0);
    const Eigen::MatrixXd Q = G.transpose() * G;
    const double L = std::max(2.0 * Q.diagonal().sum(), 1e-300);  // >= 2 lambda_max(Q)
    Eigen::VectorXd l = Eigen::VectorXd::Constant(m, 1.0 / static_cast<double>(m));
    Eigen::VectorXd y = l, prev = l;
    double tk = 1.0;
    double best = l.dot(Q * l);
    Eigen::VectorXd best_l = l;
    for (int it = 0; it < 20000; ++it) {  // FISTA on the simplex
        const Eigen::VectorXd next = project_simplex(y - (2.0 * (Q * y)) / L);
        const double tn = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * tk * tk));
        y = next + ((tk - 1.0) / tn) * (next - prev);
        tk = tn;
        const double change = (next - prev).lpNorm<1>();
        prev = next;
        const double val = next.dot(Q * next);
        if (val < best) {
            best = val;
            best_l = next;
        }
        if (change < 1e-14) break;
    }
    return G * best_l;
}

NonsmoothResult minimize_nonsmooth(const NonsmoothFunction& f, const Eigen::VectorXd& x0, const NonsmoothOptions& options) {
    options.validate();
    const Eigen::Index n = x0.size();
    if (n == 0) throw std::invalid_argument("minimize_nonsmooth: expected at least one variable");
    NonsmoothResult r;
    struct Sample {
        Eigen::VectorXd x, g;
    };
    std::deque<Sample> history;  // recent evaluations with finite values (iterates and trial points)
    auto eval = [&](const Eigen::VectorXd& x, Eigen::VectorXd& g) {
        ++r.evaluations;
        g.setZero(n);
        double v = f(x, g);
        if (std::isnan(v)) v = std::numeric_limits<double>::infinity();
        if (std::isfinite(v) && g.size() == n && g.allFinite()) {
            history.push_back({x, g});
            if (history.size() > static_cast<std::size_t>(4 * options.bundle_size)) history.pop_front();
        } else if (std::isfinite(v)) {
            v = std::numeric_limits<double>::infinity();  // a non-finite gradient: treat as outside
        }
        return v;
    };
    auto stationarity = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& g, double radius, Eigen::VectorXd* v) {
        std::vector<const Sample*> near;
        for (auto it = history.rbegin(); it != history.rend() && static_cast<int>(near.size()) < options.bundle_size - 1; ++it)
            if ((it->x - x).norm() <= radius) near.push_back(&*it);
        Eigen::MatrixXd G(n, static_cast<Eigen::Index>(near.size()) + 1);
        G.col(0) = g;
        for (std::size_t k = 0; k < near.size(); ++k) G.col(static_cast<Eigen::Index>(k) + 1) = near[k]->g;
        const Eigen::VectorXd m = min_norm_in_hull(G);
        if (v) *v = m;
        // relative to the largest gradient of the bundle (at least 1): at a kink between a steep
        // and a flat piece the hull's smallest vector is small only relative to the steep one
        return m.norm() / std::max(1.0, G.colwise().norm().maxCoeff());
    };

    Eigen::VectorXd x = x0, g;
    double fx = eval(x, g);
    r.path.push_back(x);
    if (!std::isfinite(fx)) {
        r.status = Status::NumericalIssue;
        r.message = "the objective is not finite at the start";
        r.x = x;
        r.value = fx;
        r.gradient = Eigen::VectorXd::Zero(n);
        return r;
    }
    Eigen::MatrixXd H = Eigen::MatrixXd::Identity(n, n);
    std::mt19937_64 rng(12345);
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> uniform;
    bool scaled = false;
    double radius = options.sampling_radius, test_radius = options.sampling_radius;
    auto finish = [&](Status s, const std::string& msg) {
        r.status = s;
        r.message = msg;
        r.x = x;
        r.value = fx;
        r.gradient = g;
        return r;
    };
    // 0: not stationary at the test radius; 1: stationary there, the radius divided by 10 (test
    // again); 2: stationary at the final radius
    auto stationary_test = [&] {
        r.stationarity = stationarity(x, g, test_radius, nullptr);
        if (r.stationarity > options.stationarity_tolerance) return 0;
        if (test_radius <= options.final_radius) return 2;
        test_radius = std::max(options.final_radius, test_radius / 10.0);
        radius = test_radius;
        return 1;
    };
    auto stationary_message = [&] {
        return "stationary: the smallest vector of the gradients' convex hull within " + detail::significant(test_radius, 3) +
               " has relative norm " + detail::significant(r.stationarity, 3);
    };
    const double c1 = 1e-4, c2 = 0.9;
    for (r.iterations = 0; r.iterations < options.max_iterations; ++r.iterations) {
        if (fx <= options.target) return finish(Status::Converged, "reached the target value " + detail::significant(options.target, 8));
        if (const int t = stationary_test(); t == 1) continue;
        else if (t == 2) return finish(Status::Converged, stationary_message());
        if (r.evaluations >= options.max_evaluations)
            return finish(Status::BudgetExhausted, std::to_string(r.evaluations) + " evaluations (the limit) without meeting the stationarity tolerance (measure " +
                                                       detail::significant(r.stationarity, 3) + ")");
        Eigen::VectorXd d = -H * g;
        double s0 = g.dot(d);
        if (!(s0 < 0.0) || !d.allFinite()) {  // not a descent direction: reset
            H.setIdentity();
            scaled = false;
            d = -g;
            s0 = g.dot(d);
        }
        // weak Wolfe line search (Lewis-Overton): bisection and doubling
        double alpha = 0.0, beta = std::numeric_limits<double>::infinity(), t = 1.0;
        Eigen::VectorXd xt, gt, x_alpha, g_alpha;
        double f_alpha = fx;
        bool wolfe = false;
        for (int ls = 0; ls < 60 && r.evaluations < options.max_evaluations; ++ls) {
            xt = x + t * d;
            const double ft = eval(xt, gt);
            if (!(ft <= fx + c1 * t * s0)) {
                beta = t;
            } else {
                x_alpha = xt;
                g_alpha = gt;
                f_alpha = ft;
                if (gt.dot(d) < c2 * s0) {
                    alpha = t;
                } else {
                    alpha = t;
                    wolfe = true;
                    break;
                }
            }
            if (std::isfinite(beta)) t = 0.5 * (alpha + beta);
            else t = 2.0 * alpha;
            if (std::isfinite(beta) && (beta - alpha) * d.norm() < options.step_tolerance) break;
        }
        if (alpha > 0.0) {
            const Eigen::VectorXd s = x_alpha - x, y = g_alpha - g;
            r.path.push_back(x_alpha);
            x = x_alpha;
            g = g_alpha;
            fx = f_alpha;
            const double sy = s.dot(y);
            if (wolfe && sy > 0.0) {
                if (!scaled) {
                    H = Eigen::MatrixXd::Identity(n, n) * (sy / y.squaredNorm());
                    scaled = true;
                }
                const double rho = 1.0 / sy;
                const Eigen::MatrixXd V = Eigen::MatrixXd::Identity(n, n) - rho * y * s.transpose();
                H = V.transpose() * H * V + rho * s * s.transpose();
            }
            continue;
        }
        // No decrease along d: the iterate sits at (or near) a non-smooth point. Gradient sampling:
        // step along minus the smallest vector of the hull of nearby gradients, shrinking the
        // radius until it is small enough to be stationary or gives descent.
        bool moved = false;
        while (!moved && r.evaluations < options.max_evaluations) {
            // gradients at points drawn uniformly from the ball of this radius about x (fixed
            // seed): the two sides of a kink the iterates themselves may not have visited
            for (int k = 0; k < std::min<int>(static_cast<int>(n) + 1, options.bundle_size - 1) && r.evaluations < options.max_evaluations; ++k) {
                Eigen::VectorXd u(n);
                for (Eigen::Index i = 0; i < n; ++i) u[i] = normal(rng);
                const double len = radius * std::pow(uniform(rng), 1.0 / static_cast<double>(n)) / std::max(u.norm(), 1e-300);
                Eigen::VectorXd gs;
                eval(x + len * u, gs);
            }
            Eigen::VectorXd v;
            const double m = stationarity(x, g, radius, &v);
            if (m <= options.stationarity_tolerance) break;
            double ts = 1.0;
            for (int k = 0; k < 50 && r.evaluations < options.max_evaluations; ++k, ts *= 0.5) {
                const Eigen::VectorXd xs = x - ts * v;
                Eigen::VectorXd gs;
                const double fs = eval(xs, gs);
                if (fs < fx - c1 * ts * m * m) {
                    r.path.push_back(xs);
                    x = xs;
                    g = gs;
                    fx = fs;
                    moved = true;
                    break;
                }
                if (ts * v.norm() < options.step_tolerance) break;
            }
            if (!moved) {
                radius *= 0.1;
                if (radius < 1e-14 * std::max(1.0, x.norm())) break;
            }
        }
        ++r.sampling_steps;
        H.setIdentity();
        scaled = false;
        if (!moved) {
            if (const int t = stationary_test(); t == 1) continue;
            else if (t == 2) return finish(Status::Converged, stationary_message());
            if (r.evaluations >= options.max_evaluations) break;
            const std::string why = "no decrease along any sampled direction down to a radius of " + detail::significant(radius * 10.0, 3) +
                                    "; stationarity measure " + detail::significant(r.stationarity, 3);
            if (r.stationarity <= std::sqrt(options.stationarity_tolerance))
                return finish(Status::Converged, "stationary to rounding (" + why + ")");
            return finish(Status::NumericalIssue, "stalled away from a stationary point (" + why + ")");
        }
        radius = test_radius;
    }
    if (r.evaluations >= options.max_evaluations)
        return finish(Status::BudgetExhausted, std::to_string(r.evaluations) + " evaluations (the limit) without meeting the stationarity tolerance (measure " +
                                                   detail::significant(r.stationarity, 3) + ")");
    return finish(Status::MaxIterations, std::to_string(options.max_iterations) + " iterations (the limit) without meeting the stationarity tolerance (measure " +
                                             detail::significant(r.stationarity, 3) + ")");
}

}  // namespace ddemap
