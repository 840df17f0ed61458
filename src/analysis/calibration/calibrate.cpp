#include "ddemap/analysis/calibration/calibrate.hpp"

#include "ddemap/core/execution.hpp"

#include <exception>

#include <algorithm>
#include <atomic>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <random>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

/// linear interpolation of samples (constant outside)
double interp(const std::vector<double>& t, const std::vector<double>& y, double x) {
    if (x <= t.front()) return y.front();
    if (x >= t.back()) return y.back();
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
    const double s = (x - t[k]) / (t[k + 1] - t[k]);
    return y[k] + s * (y[k + 1] - y[k]);
}

const char* names[5] = {"k1", "k2", "th", "tau", "eta"};

}  // namespace

namespace {

/// The checks every trace passes: physical values, a sampling step a car-following fit can use,
/// enough data.
void check_trace(const Trace& tr, const std::string& first_bad_gap = "") {
    const std::size_t n = tr.t.size();
    for (std::size_t i = 0; i < n; ++i) {
        const auto fail = [&](const std::string& what, double x, const std::string& hint) {
            throw std::invalid_argument(tr.source + ": sample " + std::to_string(i + 1) + " (time_s = " + detail::format_number(tr.t[i]) + "): " +
                                        what + " = " + detail::format_number(x) + ": expected " + hint);
        };
        if (tr.lead[i] < 0.0) fail("lead_speed_mps", tr.lead[i], ">= 0 m/s");
        if (tr.speed[i] < 0.0) fail("follower_speed_mps", tr.speed[i], ">= 0 m/s");
        if (tr.speed[i] > kMaxRoadSpeed || tr.lead[i] > kMaxRoadSpeed)
            fail(tr.speed[i] > kMaxRoadSpeed ? "follower_speed_mps" : "lead_speed_mps", std::max(tr.speed[i], tr.lead[i]),
                 "at most 100 m/s (360 km/h; a speed in km/h? divide by 3.6)");
        // a gap beyond 10 km is not car following; one below -100 m is not a sensor's reading of a cut-in
        if (tr.gap[i] > 1e4 || tr.gap[i] < -100.0)
            fail("gap_m", tr.gap[i], tr.gap[i] > 0 ? "at most 10000 m (a gap in mm or cm? convert it to m)" : "a gap above -100 m (at most 1 % of the gaps may be 0 or less, e.g. during a cut-in)");
    }
    // gaps <= 0: a collision, or a sensor's reading during a cut-in; a few (at most 1 % of the
    // samples, as at the start of an OpenACC handling run) are kept, more are refused
    const auto bad_gaps = static_cast<std::size_t>(std::count_if(tr.gap.begin(), tr.gap.end(), [](double g) { return !(g > 0.0); }));
    if (bad_gaps > n / 100) {
        const auto first = static_cast<std::size_t>(std::find_if(tr.gap.begin(), tr.gap.end(), [](double g) { return !(g > 0.0); }) - tr.gap.begin());
        throw std::invalid_argument((first_bad_gap.empty() ? tr.source + ": sample " + std::to_string(first + 1) + " (time_s = " +
                                                                 detail::format_number(tr.t[first]) + "): gap_m = " + detail::format_number(tr.gap[first])
                                                           : first_bad_gap) +
                                    " and " + std::to_string(bad_gaps - 1) + " more gaps <= 0 of " + std::to_string(n) +
                                    " samples: expected gaps > 0 m (a gap of 0 or less is a collision; at most 1 % of the samples may be, e.g. during a cut-in)");
    }
    if (n >= 2) {
        std::vector<double> dt(n - 1);
        for (std::size_t i = 0; i + 1 < n; ++i) dt[i] = tr.t[i + 1] - tr.t[i];
        std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
        const double median = dt[dt.size() / 2];
        const double largest = *std::max_element(dt.begin(), dt.end());
        // the limits with a relative allowance for the rounding of decimal times (0.001 - 0 > 1e-3 - 1e-18)
        if (median < 1e-3 * (1 - 1e-9) || median > 10.0 * (1 + 1e-9)) {
            std::string hint = "a sampling step of 1 ms to 10 s";
            if (median > 10.0 && median / 1000.0 >= 1e-3 && median / 1000.0 <= 10.0)
                hint += " (time_s looks like milliseconds: divide the column by 1000)";
            throw std::invalid_argument(tr.source + ": time_s: a median sampling step of " + detail::format_number(median) + " s: expected " + hint);
        }
        if (largest > 10.0)
            throw std::invalid_argument(tr.source + ": time_s: a gap of " + detail::format_number(largest) +
                                        " s between two samples: expected at most 10 s (split the trace into runs at the break)");
    }
    if (n < 100 || tr.t.back() - tr.t.front() < 20.0) {
        throw std::invalid_argument(tr.source + ": " + std::to_string(n) + " rows over " +
                                    detail::format_number(n == 0 ? 0.0 : tr.t.back() - tr.t.front()) +
                                    " s: expected at least 100 rows and 20 s");
    }
}

}  // namespace

Trace platoon_trace(const PlatoonSeries& platoon, int follower) {
    if (follower < 1 || follower > platoon.followers())
        throw std::invalid_argument(platoon.source + ": follower " + std::to_string(follower) + ": expected 1 to " + std::to_string(platoon.followers()));
    const auto f = static_cast<std::size_t>(follower);
    Trace tr;
    tr.source = platoon.source + ":" + std::to_string(follower);
    tr.t = platoon.time;
    tr.lead = platoon.speed[f - 1];
    tr.speed = platoon.speed[f];
    tr.gap = platoon.gap[f];
    check_trace(tr);
    return tr;
}

std::vector<Trace> read_traces_csv(const std::string& text, const std::string& source, int follower) {
    if (!is_platoon_csv(text)) return {read_trace_csv(text, source, follower)};
    const PlatoonSeries p = read_platoon_csv(text, source);
    if (follower > p.followers())
        throw std::invalid_argument(source + ": follower " + std::to_string(follower) + ": expected 1 to " + std::to_string(p.followers()));
    std::vector<Trace> out;
    for (int k = follower ? follower : 1; k <= (follower ? follower : p.followers()); ++k) out.push_back(platoon_trace(p, k));
    return out;
}

Trace read_trace_csv(const std::string& text, const std::string& source, int follower) {
    if (is_platoon_csv(text)) {
        const PlatoonSeries p = read_platoon_csv(text, source);
        if (follower == 0 && p.followers() > 1)
            throw std::invalid_argument(source + " is a platoon of " + std::to_string(p.followers()) +
                                        " followers (simulate's CSV): name the follower to fit (1 to " + std::to_string(p.followers()) + ")");
        return platoon_trace(p, follower == 0 ? 1 : follower);
    }
    if (follower != 0)
        throw std::invalid_argument(source + ": follower " + std::to_string(follower) +
                                    ": a follower is picked only from a platoon CSV (simulate's); this file is one trace");
    detail::CsvReader csv(text, source, "time_s, lead_speed_mps, follower_speed_mps, gap_m");
    const char* cols[4] = {"time_s", "lead_speed_mps", "follower_speed_mps", "gap_m"};
    int idx[4];
    for (int c = 0; c < 4; ++c) idx[c] = csv.column(cols[c]);
    Trace tr;
    tr.source = source;
    std::vector<double>* dest[4] = {&tr.t, &tr.lead, &tr.speed, &tr.gap};
    std::string first_bad_gap;  // "SOURCE:LINE: gap_m = X" of the first gap <= 0
    while (csv.next()) {
        for (int c = 0; c < 4; ++c) dest[c]->push_back(csv.number(idx[c], cols[c]));
        for (int c = 1; c < 3; ++c)
            if (dest[c]->back() < 0.0) csv.fail(std::string(cols[c]) + " = " + detail::format_number(dest[c]->back()) + ": expected >= 0 m/s");
        if (tr.gap.back() <= 0.0 && first_bad_gap.empty()) first_bad_gap = csv.where() + ": gap_m = " + detail::format_number(tr.gap.back());
        const std::size_t n = tr.t.size();
        if (n > 1 && !(tr.t[n - 1] > tr.t[n - 2])) {
            csv.fail("time_s = " + detail::format_number(tr.t[n - 1]) + " after " + detail::format_number(tr.t[n - 2]) +
                     ": expected increasing times");
        }
    }
    check_trace(tr, first_bad_gap);
    return tr;
}

const std::vector<std::string>& calibration_parameter_names() {
    static const std::vector<std::string> n = {"k1", "k2", "th", "tau", "eta"};
    return n;
}

ParameterBounds paper_calibration_bounds() {
    return {{"k1", 0.0, 1.0}, {"k2", 0.0, 1.0}, {"th", 0.0, 3.0}, {"tau", 0.0, 1.0}, {"eta", 5.0, 15.0}};
}

BoundedParameter CalibrationOptions::bound(const std::string& name) const {
    const ParameterBounds paper = paper_calibration_bounds();
    const BoundedParameter* fallback = find_bound(paper, name);
    if (!fallback) throw std::invalid_argument("bounds for '" + name + "': unknown parameter, expected one of k1, k2, th, tau, eta");
    const BoundedParameter* b = find_bound(bounds, name);
    return b ? *b : *fallback;
}

void CalibrationOptions::set_bounds(const std::string& name, double lower, double upper) {
    if (BoundedParameter* b = find_bound(bounds, name)) {
        b->lower = lower;
        b->upper = upper;
    } else {
        bounds.push_back({name, lower, upper});
    }
}

void CalibrationOptions::validate() const {
    validate_bounds(bounds, calibration_parameter_names());
    for (const auto& b : bounds)
        if (b.lower < 0.0)
            throw std::invalid_argument("bounds for '" + b.name + "' = " + detail::format_number(b.lower) + ":" + detail::format_number(b.upper) +
                                        ": expected lower >= 0");
    const double tau_max = bound("tau").upper;
    if (tau_max > 5.0) throw std::invalid_argument("bounds for 'tau': upper = " + detail::format_number(tau_max) + ": expected at most 5 s");
    // W MSE(gap) must stay a finite number for gaps of kilometres: W at most 1e6 (the default 0.02)
    if (!(gap_weight >= 0.0 && gap_weight <= 1e6))
        throw std::invalid_argument("gap weight = " + detail::format_number(gap_weight) + ": expected a number from 0 to 1e6 [1/s^2]");
    if (!(step > 0.0 && step <= 0.5)) throw std::invalid_argument("step = " + detail::format_number(step) + ": expected 0 < step <= 0.5 s");
    if (design_points < 1) throw std::invalid_argument("design points = " + std::to_string(design_points) + ": expected at least 1");
    if (starts < 1 || starts > design_points)
        throw std::invalid_argument("starts = " + std::to_string(starts) + ": expected 1 to design points (" + std::to_string(design_points) + ")");
    if (max_iterations < 1) throw std::invalid_argument("max iterations = " + std::to_string(max_iterations) + ": expected at least 1");
    for (double tol : {gradient_tolerance, function_tolerance, step_tolerance})
        if (!(tol >= 0.0 && std::isfinite(tol))) throw std::invalid_argument("tolerance = " + detail::format_number(tol) + ": expected a finite value >= 0");
    for (std::size_t i = 0; i < profile.size(); ++i) {
        const auto& n = calibration_parameter_names();
        if (std::find(n.begin(), n.end(), profile[i]) == n.end())
            throw std::invalid_argument("profile '" + profile[i] + "': unknown parameter, expected one of k1, k2, th, tau, eta");
        if (std::find(profile.begin(), profile.begin() + static_cast<std::ptrdiff_t>(i), profile[i]) != profile.begin() + static_cast<std::ptrdiff_t>(i))
            throw std::invalid_argument("profile '" + profile[i] + "' is requested twice");
        const BoundedParameter b = bound(profile[i]);
        if (!(b.upper > b.lower)) throw std::invalid_argument("profile '" + profile[i] + "': the parameter is fixed by its bounds");
    }
    if (!(std::isfinite(lead_noise) && lead_noise <= 10.0))
        throw std::invalid_argument("lead noise = " + detail::format_number(lead_noise) + ": expected at most 10 m/s (0: the lead speed is exact; negative: estimated)");
    if (lead_noise_draws < 20 || lead_noise_draws > 100000)
        throw std::invalid_argument("lead noise draws = " + std::to_string(lead_noise_draws) + ": expected 20 to 100000");
    if (!profile.empty() && profile_points < 3)
        throw std::invalid_argument("profile points = " + std::to_string(profile_points) + ": expected at least 3");
}

bool CalibrationOptions::is_valid() const {
    try {
        validate();
        return true;
    } catch (const std::exception&) {
        return false;
    }
}

void simulate_follower(const Trace& tr, const ParameterMap& p, double t_a, double t_b, double step, std::vector<double>& speed,
                       std::vector<double>& gap) {
    CalibrationVector theta;
    for (int i = 0; i < 5; ++i) theta[i] = p.at(names[i]);
    FollowerTrajectory f = simulate_follower(tr, theta, t_a, t_b, step, false);
    speed = std::move(f.speed);
    gap = std::move(f.gap);
}


namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// One run of a (joint) least-squares problem: residuals (speeds, then sqrt(w) gaps) at the
/// samples t_j >= t_from of the window [a, b] of its trace.
struct Segment {
    const Trace* tr = nullptr;   // what the simulation reads: the run with its history smoothed
    const Trace* raw = nullptr;  // the run as measured: what the residuals compare with
    double a = 0.0, b = 0.0, t_from = 0.0;
    std::size_t first = 0;             // data index of the trajectory's first row
    std::vector<std::size_t> rows;     // trajectory rows of the residual samples
    int samples() const { return static_cast<int>(rows.size()); }
    // the lead-noise bias correction: `imp` is `tr` with lead sample rows[1] raised by 1 m/s
    // (null: no correction for this run); `sigma` the run's lead noise [m/s]
    const Trace* imp = nullptr;
    double sigma = 0.0;
    // penalty residuals of the run: sigma sqrt(N_l) g(l) for the lags l = 0 .. samples() - 2
    int lags() const { return imp ? samples() - 1 : 0; }
};

/// The least-squares problem on the training windows of one or more runs: the residual vector
/// is the runs' blocks one after the other, each block (speeds, then sqrt(w) gaps) of its run.
struct LsqProblem {
    std::vector<Segment> seg;
    double step = 0.05, wg = 0.0;
    CalibrationVector lo, hi;
    mutable std::atomic<int> evaluations{0}, jacobians{0};
    /// the traces the segments point to: each run with its history smoothed (smoothed_history),
    /// and the copies with one lead sample raised (Segment::imp)
    std::vector<std::unique_ptr<Trace>> owned;
    /// runs (their sources) with lead noise whose uneven sampling ruled out the correction
    std::vector<std::string> uneven;

    int samples() const {
        int n = 0;
        for (const auto& s : seg) n += s.samples();
        return n;
    }
    int per_sample() const { return wg > 0.0 ? 2 : 1; }
    int residuals() const { return samples() * per_sample(); }
    /// the penalty residuals rho of the lead-noise correction, |rho|^2 = P(theta)
    int penalty_residuals() const {
        int n = 0;
        for (const auto& s : seg) n += s.lags() * per_sample();
        return n;
    }
    bool corrects() const { return penalty_residuals() > 0; }

    /// r (and J if asked); with `rho`, also the penalty residuals of the lead-noise correction
    /// (and their Jacobian `Jrho` when J is asked): rho_l = sigma sqrt(N_l) g(l), where the
    /// response g(l) to one lead sample is the difference of the run with that sample raised by
    /// 1 m/s and the run itself (exact: the model is linear in the lead speed), N_l = n - l the
    /// residual samples that are l samples or more after the first (lags from the second sample:
    /// the raised sample's hat starts at a residual time, after the history). False when a
    /// simulation is not finite.
    bool eval(const CalibrationVector& th, Eigen::VectorXd& r, Eigen::MatrixXd* J, Eigen::VectorXd* rho = nullptr,
              Eigen::MatrixXd* Jrho = nullptr) const {
        r.resize(residuals());
        if (J) J->resize(residuals(), 5);
        if (rho) rho->resize(penalty_residuals());
        if (rho && J && Jrho) Jrho->resize(penalty_residuals(), 5);
        Eigen::Index off = 0, poff = 0;
        bool finite = true;
        for (const Segment& sg : seg) {
            const Trace& tr = *sg.raw;
            const FollowerTrajectory f = simulate_follower(*sg.tr, th, sg.a, sg.b, step, J != nullptr, sg.t_from);
            ++evaluations;
            if (J) ++jacobians;
            const int n = sg.samples();
            for (int j = 0; j < n; ++j) {
                const std::size_t k = sg.rows[static_cast<std::size_t>(j)], d = sg.first + k;
                r[off + j] = f.speed[k] - tr.speed[d];
                if (J) J->row(off + j) = f.dspeed.row(static_cast<Eigen::Index>(k));
                if (wg > 0.0) {
                    r[off + n + j] = wg * (f.gap[k] - tr.gap[d]);
                    if (J) J->row(off + n + j) = wg * f.dgap.row(static_cast<Eigen::Index>(k));
                }
            }
            off += static_cast<Eigen::Index>(n) * per_sample();
            if (rho && sg.imp) {
                const FollowerTrajectory fi = simulate_follower(*sg.imp, th, sg.a, sg.b, step, J != nullptr, sg.t_from);
                ++evaluations;
                if (J) ++jacobians;
                const int L = sg.lags();
                for (int l = 0; l < L; ++l) {
                    const std::size_t k = sg.rows[static_cast<std::size_t>(l + 1)];
                    const double c = sg.sigma * std::sqrt(static_cast<double>(n - l));
                    (*rho)[poff + l] = c * (fi.speed[k] - f.speed[k]);
                    if (J && Jrho) Jrho->row(poff + l) = c * (fi.dspeed.row(static_cast<Eigen::Index>(k)) - f.dspeed.row(static_cast<Eigen::Index>(k)));
                    if (wg > 0.0) {
                        (*rho)[poff + L + l] = c * wg * (fi.gap[k] - f.gap[k]);
                        if (J && Jrho)
                            Jrho->row(poff + L + l) = c * wg * (fi.dgap.row(static_cast<Eigen::Index>(k)) - f.dgap.row(static_cast<Eigen::Index>(k)));
                    }
                }
                poff += static_cast<Eigen::Index>(L) * per_sample();
            }
        }
        if (rho) finite = finite && rho->allFinite() && (!(J && Jrho) || Jrho->allFinite());
        return finite && r.allFinite() && (!J || J->allFinite());
    }
    double ssr(const CalibrationVector& th) const {
        Eigen::VectorXd r;
        return eval(th, r, nullptr) ? r.squaredNorm() : kInf;
    }
    /// |r|^2 - |rho|^2 with the lead-noise correction (`corrected`), else |r|^2
    double cost(const CalibrationVector& th, bool corrected) const {
        if (!corrected) return ssr(th);
        Eigen::VectorXd r, rho;
        return eval(th, r, nullptr, &rho) ? r.squaredNorm() - rho.squaredNorm() : kInf;
    }
};

struct LmResult {
    CalibrationVector theta;
    double ssr = kInf;
    Status status = Status::NumericalIssue;
    std::string message;
    int iterations = 0;
};

/// Levenberg-Marquardt with bounds on the free parameters `free` (the others stay at theta0):
/// z = (theta - lo) / (hi - lo) in [0, 1]; a parameter on a bound whose gradient points
/// outwards is held (active set); steps are projected onto the box; Nielsen's damping update.
/// With `corrected` (a problem with the lead-noise correction) the cost is |r|^2 - |rho|^2 and
/// the Gauss-Newton model uses J^T J - J_rho^T J_rho (its expectation is J^T J of an exact lead);
/// a damped matrix that is not positive definite is damped further.
LmResult levenberg_marquardt(const LsqProblem& pb, const CalibrationVector& theta0, const std::vector<int>& free,
                             const CalibrationOptions& o, bool corrected = false) {
    const int p = static_cast<int>(free.size());
    LmResult res;
    res.theta = theta0;
    Eigen::VectorXd w(p), z(p);
    for (int i = 0; i < p; ++i) {
        const int k = free[static_cast<std::size_t>(i)];
        w[i] = pb.hi[k] - pb.lo[k];
        z[i] = std::clamp((theta0[k] - pb.lo[k]) / w[i], 0.0, 1.0);
    }
    auto theta_of = [&](const Eigen::VectorXd& zz) {
        CalibrationVector th = theta0;
        for (int i = 0; i < p; ++i) {
            const int k = free[static_cast<std::size_t>(i)];
            th[k] = std::clamp(pb.lo[k] + zz[i] * w[i], pb.lo[k], pb.hi[k]);
        }
        return th;
    };
    auto scaled = [&](const Eigen::MatrixXd& J) {
        Eigen::MatrixXd S(J.rows(), p);
        for (int i = 0; i < p; ++i) S.col(i) = J.col(free[static_cast<std::size_t>(i)]) * w[i];
        return S;
    };
    // cost, Gauss-Newton matrix and gradient (in z) at theta; false when not finite
    // (DD: the diagonal of the plain J^T J, positive, which scales the damping also when the
    // corrected matrix has a diagonal entry <= 0)
    auto evaluate = [&](const CalibrationVector& th, double& c, Eigen::MatrixXd& AA, Eigen::VectorXd& gg, Eigen::VectorXd& DD) {
        Eigen::VectorXd r, rho;
        Eigen::MatrixXd Jf, Jrho;
        if (!pb.eval(th, r, &Jf, corrected ? &rho : nullptr, corrected ? &Jrho : nullptr)) return false;
        const Eigen::MatrixXd J = scaled(Jf);
        c = r.squaredNorm();
        AA = J.transpose() * J;
        DD = AA.diagonal();
        gg = J.transpose() * r;
        if (corrected) {
            const Eigen::MatrixXd Jr = scaled(Jrho);
            c -= rho.squaredNorm();
            AA -= Jr.transpose() * Jr;
            gg -= Jr.transpose() * rho;
        }
        return std::isfinite(c);
    };
    res.theta = theta_of(z);
    Eigen::MatrixXd A, A_new;
    Eigen::VectorXd g, g_new, D, D_new;
    double cost = kInf;
    if (!evaluate(res.theta, cost, A, g, D)) {
        res.message = "the simulation is not finite at the start";
        return res;
    }
    res.ssr = cost;
    if (p == 0) {
        res.status = Status::Converged;
        res.message = "no free parameter";
        return res;
    }
    double mu = 1e-3 * std::max(D.maxCoeff(), 1e-300), nu = 2.0;
    res.status = Status::MaxIterations;
    res.message = "the iteration limit (" + std::to_string(o.max_iterations) + ") was reached";
    for (int it = 0; it < o.max_iterations; ++it) {
        if (o.progress) o.progress(it, o.max_iterations);
        res.iterations = it + 1;
        // first-order optimality on the box
        double pg = 0.0;
        for (int i = 0; i < p; ++i) pg = std::max(pg, std::abs(std::clamp(z[i] - g[i], 0.0, 1.0) - z[i]));
        if (pg <= o.gradient_tolerance * (1.0 + std::abs(cost))) {
            res.status = Status::Converged;
            res.message = "projected gradient below tolerance";
            break;
        }
        std::vector<int> act;  // free in this iteration
        for (int i = 0; i < p; ++i)
            if (!((z[i] <= 0.0 && g[i] > 0.0) || (z[i] >= 1.0 && g[i] < 0.0))) act.push_back(i);
        const int q = static_cast<int>(act.size());
        if (q == 0) {
            res.status = Status::Converged;
            res.message = "every parameter held at a bound";
            break;
        }
        Eigen::MatrixXd Aq(q, q);
        Eigen::VectorXd gq(q), dg(q);
        const double dmax = D.maxCoeff();
        for (int i = 0; i < q; ++i) {
            gq[i] = g[act[static_cast<std::size_t>(i)]];
            for (int j = 0; j < q; ++j) Aq(i, j) = A(act[static_cast<std::size_t>(i)], act[static_cast<std::size_t>(j)]);
            dg[i] = std::max(D[act[static_cast<std::size_t>(i)]], 1e-9 * dmax + 1e-300);
        }
        bool accepted = false, stop = false;
        while (!accepted) {
            Eigen::MatrixXd M = Aq;
            M.diagonal() += mu * dg;
            const Eigen::LLT<Eigen::MatrixXd> llt(M);
            // more damping (Nielsen); false with the status and message given when at its limit
            auto damp_more = [&](Status at_limit, const char* why) {
                mu *= nu;
                nu *= 2.0;
                if (mu < 1e30) return true;
                res.status = at_limit;
                res.message = why;
                stop = true;
                return false;
            };
            if (llt.info() != Eigen::Success) {  // the corrected matrix is indefinite here: damp more
                if (!damp_more(Status::NumericalIssue, "the corrected normal matrix stays indefinite at any damping")) break;
                continue;
            }
            const Eigen::VectorXd dq = llt.solve(-gq);
            Eigen::VectorXd d = Eigen::VectorXd::Zero(p);
            for (int i = 0; i < q; ++i) d[act[static_cast<std::size_t>(i)]] = dq[i];
            Eigen::VectorXd z_new = (z + d).cwiseMax(0.0).cwiseMin(1.0);
            d = z_new - z;
            if (!d.allFinite() || d.lpNorm<Eigen::Infinity>() <= o.step_tolerance) {
                res.status = Status::Converged;
                res.message = "step below tolerance";
                stop = true;
                break;
            }
            const double pred = -(g.dot(d) + 0.5 * d.dot(A * d));
            const CalibrationVector th_new = theta_of(z_new);
            double cost_new = kInf;
            const bool ok = evaluate(th_new, cost_new, A_new, g_new, D_new);
            if (!ok) cost_new = kInf;
            const double rho = pred > 0.0 ? (cost - cost_new) / pred : -1.0;
            if (ok && cost_new < cost && rho > 1e-4) {
                const double decrease = cost - cost_new;
                z = z_new;
                A.swap(A_new);
                g.swap(g_new);
                D.swap(D_new);
                cost = cost_new;
                res.theta = th_new;
                res.ssr = cost;
                mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
                nu = 2.0;
                accepted = true;
                if (decrease <= o.function_tolerance * std::abs(cost)) {
                    res.status = Status::Converged;
                    res.message = "relative decrease of the objective below tolerance";
                    stop = true;
                }
            } else if (!damp_more(Status::Converged, "no descent step left (damping at its limit)")) {
                break;
            }
        }
        if (stop) break;
    }
    return res;
}

/// Latin hypercube in [0, 1]^p: n points, one in each of the n slices of every axis (fixed seed;
/// a portable generator and no std distribution, so the design is the same on every platform).
std::vector<Eigen::VectorXd> latin_hypercube(int n, int p, unsigned seed) {
    std::mt19937 rng(seed);
    auto uniform = [&] { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; };
    std::vector<Eigen::VectorXd> pts(static_cast<std::size_t>(n), Eigen::VectorXd(p));
    std::vector<int> perm(static_cast<std::size_t>(n));
    for (int j = 0; j < p; ++j) {
        std::iota(perm.begin(), perm.end(), 0);
        for (int i = n - 1; i > 0; --i) std::swap(perm[static_cast<std::size_t>(i)], perm[static_cast<std::size_t>(rng() % static_cast<unsigned>(i + 1))]);
        for (int i = 0; i < n; ++i) pts[static_cast<std::size_t>(i)][j] = (perm[static_cast<std::size_t>(i)] + uniform()) / n;
    }
    return pts;
}

/// Errors over the samples of [t_a, t_b] at or after t_from.
/// The simulation starts at max(t_start, t_a + tau).
/// (`simulated`: the trace the simulation reads, e.g. with its history smoothed; default `tr`)
FitErrors errors_over(const Trace& tr, const ParameterMap& p, double t_a, double t_b, double t_from, double step,
                      std::vector<double>* sim_speed = nullptr, std::vector<double>* sim_gap = nullptr, double t_start = -1e300,
                      const Trace* simulated = nullptr) {
    CalibrationVector theta;
    for (int i = 0; i < 5; ++i) theta[i] = p.at(names[i]);
    FollowerTrajectory f = simulate_follower(simulated ? *simulated : tr, theta, t_a, t_b, step, false, t_start);
    const std::vector<double>& v = f.speed;
    const std::vector<double>& s = f.gap;
    FitErrors e;
    double sv = 0.0, sg = 0.0;
    std::size_t j = 0;
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
        const double t = tr.t[k];
        if (t < t_a || t > t_b) continue;
        if (t >= t_from) {
            const double dv = v[j] - tr.speed[k], dg = s[j] - tr.gap[k];
            sv += dv * dv;
            sg += dg * dg;
            ++e.samples;
        }
        ++j;
    }
    if (e.samples > 0) {
        e.rmse_speed = std::sqrt(sv / e.samples);
        e.rmse_gap = std::sqrt(sg / e.samples);
    }
    if (sim_speed) *sim_speed = v;
    if (sim_gap) *sim_gap = s;
    return e;
}

/// autocorrelation of x at lags 0..max_lag (normalised by the lag-0 sum)
std::vector<double> autocorrelation(const Eigen::VectorXd& x, int max_lag) {
    const Eigen::Index n = x.size();
    const Eigen::VectorXd c = x.array() - x.mean();
    const double c0 = c.squaredNorm();
    std::vector<double> rho(static_cast<std::size_t>(max_lag + 1), 0.0);
    rho[0] = 1.0;
    if (!(c0 > 0.0)) return rho;
    for (int l = 1; l <= max_lag && l < n; ++l) rho[static_cast<std::size_t>(l)] = c.head(n - l).dot(c.tail(n - l)) / c0;
    return rho;
}

/// first lag at which the autocorrelation falls below 0.05 (computed lag by lag up to cap)
int decorrelation_lag(const Eigen::VectorXd& x, int cap) {
    const Eigen::Index n = x.size();
    const Eigen::VectorXd c = x.array() - x.mean();
    const double c0 = c.squaredNorm();
    if (!(c0 > 0.0)) return 1;
    for (int l = 1; l <= cap && l < n; ++l)
        if (c.head(n - l).dot(c.tail(n - l)) / c0 < 0.05) return l;
    return cap;
}

std::string fmt(double x) { return detail::format_number(x); }

std::string fmt3(double x) { return detail::significant(x, 3); }

/// The Bartlett (Newey-West) long-run sum of the rows g_t of G with bandwidth L,
///     Omega = sum_{|l| <= L} (1 - |l|/(L+1)) sum_t g_t g_(t-l)^T = 1/(L+1) sum_j S_j S_j^T,
/// S_j the sum of the rows in the window [j, j + L] (windows that reach past either end take
/// the rows inside): each pair of rows l apart shares L + 1 - l windows. O((n + L) p^2).
Eigen::MatrixXd bartlett_long_run(const Eigen::MatrixXd& G, int L) {
    const Eigen::Index n = G.rows(), p = G.cols();
    Eigen::MatrixXd prefix = Eigen::MatrixXd::Zero(n + 1, p);
    for (Eigen::Index t = 0; t < n; ++t) prefix.row(t + 1) = prefix.row(t) + G.row(t);
    Eigen::MatrixXd Omega = Eigen::MatrixXd::Zero(p, p);
    for (Eigen::Index j = -L; j < n; ++j) {
        const Eigen::Index lo = std::max<Eigen::Index>(j, 0), hi = std::min<Eigen::Index>(j + L + 1, n);
        const Eigen::RowVectorXd S = prefix.row(hi) - prefix.row(lo);
        Omega.noalias() += S.transpose() * S;
    }
    return Omega / (L + 1);
}

}  // namespace

double lead_noise_estimate(const Trace& tr, double t_a, double t_b) {
    std::vector<double> z;
    const std::size_t n = tr.t.size();
    for (std::size_t k = 1; k + 1 < n; ++k) {
        if (tr.t[k - 1] < t_a || tr.t[k + 1] > t_b) continue;
        const double h0 = tr.t[k] - tr.t[k - 1], h1 = tr.t[k + 1] - tr.t[k];
        if (!(h0 > 0.0 && h1 > 0.0)) continue;
        const double a = h1 / (h0 + h1), b = h0 / (h0 + h1);  // v_k ~ a v_(k-1) + b v_(k+1)
        z.push_back(std::abs(tr.lead[k] - a * tr.lead[k - 1] - b * tr.lead[k + 1]) / std::sqrt(1.0 + a * a + b * b));
    }
    if (z.size() < 10) return 0.0;
    auto mid = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2);
    std::nth_element(z.begin(), mid, z.end());
    return 1.4826 * *mid;
}

namespace {

/// The problem of `calibrate` (one run) or `calibrate_joint` (several): bounds, each run's
/// training window and residual samples (t >= t_a + tau_max).
/// The trace with its follower speed and gap at the history's samples (times in [a, t_from],
/// where the simulation takes the data as its initial function) replaced by a quadratic
/// least-squares fit to the samples in [a, t_from + 2 s]: the simulation starts from the data at
/// t_from, and measurement noise there is an initial error that the fit would otherwise bend
/// the parameters to follow (0.1 m of gap noise moved tau of a stiff car by 20 %). Over 3 s of
/// car following a quadratic is close to the motion (a relative jerk j leaves about
/// j (1.5 s)^3 / 15 in the gap); 30 samples at 10 Hz divide the noise by about 3.
Trace smoothed_history(const Trace& tr, double a, double t_from) {
    Trace out = tr;
    const double c = 0.5 * (a + t_from + 2.0), w = 0.5 * (t_from + 2.0 - a);
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < tr.t.size(); ++k)
        if (tr.t[k] >= a && tr.t[k] <= t_from + 2.0) rows.push_back(k);
    if (rows.size() < 8) return out;  // too few samples to smooth (a sampling step above 0.4 s)
    Eigen::MatrixXd X(static_cast<Eigen::Index>(rows.size()), 3);
    Eigen::MatrixXd Y(static_cast<Eigen::Index>(rows.size()), 2);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const double x = (tr.t[rows[i]] - c) / w;
        X.row(static_cast<Eigen::Index>(i)) << 1.0, x, x * x;
        Y.row(static_cast<Eigen::Index>(i)) << tr.speed[rows[i]], tr.gap[rows[i]];
    }
    const Eigen::MatrixXd beta = X.colPivHouseholderQr().solve(Y);
    for (std::size_t k : rows) {
        if (tr.t[k] > t_from) break;
        const double x = (tr.t[k] - c) / w;
        const Eigen::RowVector3d phi(1.0, x, x * x);
        out.speed[k] = phi * beta.col(0);
        out.gap[k] = phi * beta.col(1);
    }
    return out;
}

void set_up(LsqProblem& pb, const std::vector<const Trace*>& traces, const CalibrationOptions& o) {
    for (int i = 0; i < 5; ++i) {
        const BoundedParameter bd = o.bound(names[i]);
        pb.lo[i] = bd.lower;
        pb.hi[i] = bd.upper;
    }
    pb.step = o.step;
    pb.wg = std::sqrt(o.gap_weight);
    for (const Trace* trp : traces) {
        const Trace& tr = *trp;
        const double first = tr.t.front(), last = tr.t.back();
        const double a = o.train_start < 0.0 ? first : o.train_start;
        const double b = o.train_end < 0.0 ? last : o.train_end;
        if (!(a >= first && b <= last && b - a >= 20.0)) {
            throw std::invalid_argument((traces.size() > 1 ? tr.source + ": " : std::string()) + "training window " + detail::format_number(a) + ":" +
                                        detail::format_number(b) + " s: expected at least 20 s within the file's " + detail::format_number(first) +
                                        ":" + detail::format_number(last) + " s");
        }
        // every candidate is scored on the same samples: those after the longest admissible delay
        Segment sg;
        pb.owned.push_back(std::make_unique<Trace>(smoothed_history(tr, a, a + pb.hi[3])));
        sg.tr = pb.owned.back().get();
        sg.raw = trp;
        sg.a = a;
        sg.b = b;
        sg.t_from = a + pb.hi[3];
        sg.first = static_cast<std::size_t>(std::lower_bound(tr.t.begin(), tr.t.end(), a) - tr.t.begin());
        for (std::size_t k = sg.first; k < tr.t.size() && tr.t[k] <= b; ++k)
            if (tr.t[k] >= sg.t_from) sg.rows.push_back(k - sg.first);
        sg.sigma = o.lead_noise >= 0.0 ? o.lead_noise : lead_noise_estimate(*sg.tr, a, b);
        if (o.lead_noise_correction && sg.sigma > 0.0 && sg.rows.size() >= 3) {
            // the correction takes the response to a lead sample as the same at every sample
            // (time invariance): the samples from the first residual on must be evenly spaced
            const std::size_t d0 = sg.first + sg.rows.front(), d1 = sg.first + sg.rows.back();
            const double h = (tr.t[d1] - tr.t[d0]) / static_cast<double>(d1 - d0);
            bool even = true;
            for (std::size_t d = d0; d < d1 && even; ++d) even = std::abs(tr.t[d + 1] - tr.t[d] - h) <= 0.01 * h;
            if (even) {
                pb.owned.push_back(std::make_unique<Trace>(*sg.tr));
                pb.owned.back()->lead[sg.first + sg.rows[1]] += 1.0;
                sg.imp = pb.owned.back().get();
            } else {
                pb.uneven.push_back(traces.size() > 1 ? tr.source : std::string());
            }
        }
        pb.seg.push_back(std::move(sg));
    }
}

/// The naive predictor v(t) = v_lead(t - d) at the samples t >= t_from, the best constant d in
/// [0, 5] s: the RMSE per d on the 0.1 s grid (sum of squares and count, for pooling runs)
void naive_sums(const Trace& tr, double t_from, std::vector<double>& sum, std::vector<int>& count) {
    sum.assign(51, 0.0);
    count.assign(51, 0);
    for (int id = 0; id <= 50; ++id) {
        const double d = 0.1 * id;
        for (std::size_t k = 0; k < tr.t.size(); ++k) {
            if (tr.t[k] < t_from) continue;
            const double e = interp(tr.t, tr.lead, tr.t[k] - d) - tr.speed[k];
            sum[static_cast<std::size_t>(id)] += e * e;
            ++count[static_cast<std::size_t>(id)];
        }
    }
}

/// the fit of a problem: design, Levenberg-Marquardt starts, the uncertainty at the optimum,
/// profiles and the warnings that do not depend on the whole-file errors
CalibrationResult fit_problem(const LsqProblem& pb, const CalibrationOptions& o) {
    const int n = pb.samples();
    std::vector<int> free;
    for (int i = 0; i < 5; ++i)
        if (pb.hi[i] > pb.lo[i]) free.push_back(i);
    const int p = static_cast<int>(free.size());
    CalibrationResult res;
    // 1. the design: Latin hypercube (plus the centre of the box), scored by the objective
    CalibrationVector centre = 0.5 * (pb.lo + pb.hi);
    std::vector<CalibrationVector> design(1, centre);
    for (const auto& u : latin_hypercube(o.design_points - 1, p, o.seed)) {
        CalibrationVector th = centre;
        for (int i = 0; i < p; ++i) {
            const int k = free[static_cast<std::size_t>(i)];
            th[k] = pb.lo[k] + u[i] * (pb.hi[k] - pb.lo[k]);
        }
        design.push_back(th);
    }
    // with the lead-noise correction every stage minimises |r|^2 - P(theta): least squares
    // first and the correction after it can stay in least squares' minimum at tau = 0
    const bool corrected = pb.corrects();
    std::vector<double> score(design.size());
    ExecutionPolicy design_policy;
    design_policy.progress = o.progress;
    parallel_for(static_cast<long>(design.size()), [&](long i) { score[i] = pb.cost(design[i], corrected); }, design_policy);
    std::vector<std::size_t> order(design.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return score[x] < score[y]; });
    // 2. Levenberg-Marquardt from the best design points; keep the best end point
    const int n_starts = std::min<int>(o.starts, static_cast<int>(design.size()));
    std::vector<LmResult> fits(static_cast<std::size_t>(n_starts));
    parallel_for(n_starts, [&](long s) { fits[s] = levenberg_marquardt(pb, design[order[s]], free, o, corrected); });
    std::size_t best = 0;
    for (std::size_t s = 1; s < fits.size(); ++s)
        if (fits[s].ssr < fits[best].ssr) best = s;
    LmResult fit = fits[best];
    res.starts = n_starts;
    if (!std::isfinite(fit.ssr)) {
        // no start could be simulated: report the best design point
        fit.theta = design[order[0]];
        fit.ssr = score[order[0]];
    }
    res.lead_noise_corrected = corrected;
    res.status_code = fit.status;
    res.status = to_string(fit.status);
    res.message = fit.message;
    const CalibrationVector theta = fit.theta;
    for (int i = 0; i < 5; ++i) res.parameters[names[i]] = theta[i];
    res.k1 = theta[0];
    res.k2 = theta[1];
    res.th = theta[2];
    res.tau = theta[3];
    res.eta = theta[4];

    // 3. uncertainty at the optimum
    Eigen::VectorXd r, rho;
    Eigen::MatrixXd J, Jrho;
    const bool finite = pb.eval(theta, r, &J, corrected ? &rho : nullptr, corrected ? &Jrho : nullptr);
    res.objective = (finite ? r.squaredNorm() : fit.ssr) / std::max(n, 1);  // the plain objective, also of a corrected fit
    res.minimised_objective = (finite ? r.squaredNorm() - (corrected ? rho.squaredNorm() : 0.0) : fit.ssr) / std::max(n, 1);
    CalibrationMatrix cov = CalibrationMatrix::Zero(), cov_iid = CalibrationMatrix::Zero(), cov_exact = CalibrationMatrix::Zero();
    std::vector<bool> undetermined(5, false);
    double sigma2 = 0.0;
    if (finite && p > 0 && n > p) {
        const int m = static_cast<int>(r.size());
        Eigen::MatrixXd JF(m, p);
        for (int i = 0; i < p; ++i) JF.col(i) = J.col(free[static_cast<std::size_t>(i)]);
        Eigen::MatrixXd H = JF.transpose() * JF;
        if (corrected) {
            // the corrected normal matrix: J^T J less the lead noise's expected share of it
            Eigen::MatrixXd JR(Jrho.rows(), p);
            for (int i = 0; i < p; ++i) JR.col(i) = Jrho.col(free[static_cast<std::size_t>(i)]);
            H -= JR.transpose() * JR;
        }
        Eigen::VectorXd D = H.diagonal().cwiseSqrt();
        for (int i = 0; i < p; ++i)
            if (!(D[i] > 0.0)) D[i] = 1.0;
        const Eigen::MatrixXd Hs = D.asDiagonal().inverse() * H * D.asDiagonal().inverse();
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hs);
        const Eigen::VectorXd lam = es.eigenvalues();
        const double lmax = lam.maxCoeff();
        res.condition_number = lam.minCoeff() > 0.0 ? lmax / lam.minCoeff() : kInf;
        // pseudo-inverse: directions below 1e-12 lmax are not determined
        Eigen::MatrixXd Hinv_s = Eigen::MatrixXd::Zero(p, p);
        for (int k = 0; k < p; ++k) {
            if (lam[k] > 1e-12 * lmax) {
                Hinv_s += es.eigenvectors().col(k) * es.eigenvectors().col(k).transpose() / lam[k];
            } else {
                for (int i = 0; i < p; ++i)
                    if (std::abs(es.eigenvectors()(i, k)) >= 0.3) undetermined[static_cast<std::size_t>(free[static_cast<std::size_t>(i)])] = true;
            }
        }
        const Eigen::MatrixXd Hinv = D.asDiagonal().inverse() * Hinv_s * D.asDiagonal().inverse();
        sigma2 = r.squaredNorm() / (m - p);
        // per run: scores per sample time (speed and gap residual of the same time together),
        // the bandwidth from the run's residual autocorrelation and its Newey-West sum; runs are
        // independent, so Omega is the sum over runs (no cross-run lags)
        Eigen::MatrixXd Omega = Eigen::MatrixXd::Zero(p, p);
        double b_max = 0.0, eff = 0.0;
        // the scores g_t = J_t^T r_t of a run's samples (speed and gap residual of the same time together)
        auto scores = [&](const Eigen::VectorXd& rr, Eigen::Index off, int ns) {
            Eigen::MatrixXd G(ns, p);
            for (int t = 0; t < ns; ++t) {
                G.row(t) = JF.row(off + t) * rr[off + t];
                if (pb.wg > 0.0) G.row(t) += JF.row(off + ns + t) * rr[off + ns + t];
            }
            return G;
        };
        std::vector<int> bandwidths;  // per run, -1 for a run too short for scores
        Eigen::Index off = 0;
        for (const Segment& sg : pb.seg) {
            const int ns = sg.samples();
            const Eigen::Index ms = static_cast<Eigen::Index>(ns) * pb.per_sample();
            if (ns < 2) {
                bandwidths.push_back(-1);
                off += ms;
                continue;
            }
            const Eigen::VectorXd rv = r.segment(off, ns);
            const Eigen::MatrixXd G = scores(r, off, ns);
            // bandwidth: five times the lag at which the residuals decorrelate (the slower stream)
            const int cap = std::max(1, ns / 4);
            int lag = decorrelation_lag(rv, cap);
            if (pb.wg > 0.0) lag = std::max(lag, decorrelation_lag(r.segment(off + ns, ns), cap));
            const int L = std::min(5 * lag, cap);
            bandwidths.push_back(L);
            res.bandwidth = std::max(res.bandwidth, L);
            b_max = std::max(b_max, static_cast<double>(L) / ns);
            Omega += bartlett_long_run(G, L);
            const std::vector<double> rho = autocorrelation(rv, L);
            double f = 1.0;
            for (int l = 1; l <= L; ++l) f += 2.0 * (1.0 - static_cast<double>(l) / (L + 1)) * rho[static_cast<std::size_t>(l)];
            eff += ns / std::max(f, 1.0);
            off += ms;
        }
        res.effective_samples = eff;
        // fixed-b critical value of the Bartlett HAC t-statistic (Kiefer & Vogelsang 2005, the
        // 97.5 % quantile as a cubic in b = L / n; the largest b over the runs): wider than 1.96
        // when the bandwidth is a sizeable part of the trace, as it is for 10 Hz residuals
        const double bb = b_max;
        res.critical_value = 1.96 + 2.9694 * bb + 0.4160 * bb * bb - 0.5324 * bb * bb * bb;
        const Eigen::MatrixXd Cx = Hinv * Omega * Hinv;
        // the lead speed's noise (errors in variables): r = B e - eps at the truth, B = dr/d(lead);
        // the sandwich needs Cov(J^T r) = J^T (B Sigma_e B^T + Sigma_eps) J. The Newey-West sum
        // estimates it well for the stationary, quickly decorrelating eps, but the response B e
        // is correlated over the car's time constants (and the gap integrates e), beyond what
        // the bandwidth sees. Monte Carlo over draws e_m of white noise at the fit (the model is
        // linear in the lead, so B e_m = r(lead + e_m) - r(lead)): add E[s s^T] (s = J^T B e_m)
        // and subtract what the Newey-West sum with the same bandwidth makes of B e_m on average.
        res.lead_noise.assign(pb.seg.size(), 0.0);
        for (std::size_t i = 0; i < pb.seg.size(); ++i) res.lead_noise[i] = pb.seg[i].sigma;
        Eigen::MatrixXd Omega_lead = Eigen::MatrixXd::Zero(p, p);
        if (std::any_of(res.lead_noise.begin(), res.lead_noise.end(), [](double x) { return x > 0.0; })) {
            const int M = o.lead_noise_draws;
            std::vector<Eigen::MatrixXd> part(static_cast<std::size_t>(M));
            parallel_for(M, [&](long m) {
                // the draw's own copies of the traces, each lead speed with its noise added
                std::mt19937_64 rng(0x5eedULL * (o.seed + 1) + static_cast<std::uint64_t>(m));
                std::normal_distribution<double> z(0.0, 1.0);
                std::vector<Trace> copies;
                copies.reserve(pb.seg.size());
                LsqProblem noisy;
                noisy.step = pb.step;
                noisy.wg = pb.wg;
                noisy.lo = pb.lo;
                noisy.hi = pb.hi;
                noisy.seg = pb.seg;
                for (std::size_t i = 0; i < pb.seg.size(); ++i) {
                    copies.push_back(*pb.seg[i].tr);
                    for (double& v : copies.back().lead) v += res.lead_noise[i] * z(rng);
                }
                for (std::size_t i = 0; i < pb.seg.size(); ++i) noisy.seg[i].tr = &copies[i];
                Eigen::VectorXd rm;
                Eigen::MatrixXd acc = Eigen::MatrixXd::Zero(p, p);
                if (noisy.eval(theta, rm, nullptr)) {
                    rm -= r;  // B e_m
                    Eigen::Index o2 = 0;
                    for (std::size_t i = 0; i < pb.seg.size(); ++i) {
                        const int ns = pb.seg[i].samples();
                        if (bandwidths[i] >= 0 && res.lead_noise[i] > 0.0) {
                            const Eigen::MatrixXd Gm = scores(rm, o2, ns);
                            const Eigen::RowVectorXd sm = Gm.colwise().sum();
                            acc += sm.transpose() * sm - bartlett_long_run(Gm, bandwidths[i]);
                        }
                        o2 += static_cast<Eigen::Index>(ns) * pb.per_sample();
                    }
                } else {
                    acc.setConstant(std::numeric_limits<double>::quiet_NaN());
                }
                part[static_cast<std::size_t>(m)] = acc;
            });
            for (const auto& a : part) Omega_lead += a / M;  // in draw order: the same sum on any thread count
        }
        Eigen::MatrixXd C0 = Cx;
        if (Omega_lead.allFinite() && !Omega_lead.isZero(0.0)) {
            // Omega + Omega_lead is a covariance estimate: negative eigenvalues (Monte Carlo
            // scatter where the lead's share is small) are set to 0
            Eigen::MatrixXd Ot = Omega + Omega_lead;
            Ot = 0.5 * (Ot + Ot.transpose()).eval();
            Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eo(Ot);
            Ot = eo.eigenvectors() * eo.eigenvalues().cwiseMax(0.0).asDiagonal() * eo.eigenvectors().transpose();
            C0 = Hinv * Ot * Hinv;
        } else if (!Omega_lead.allFinite()) {
            res.warnings.push_back("the lead speed's noise could not be simulated at the fit: the intervals take the lead speed as exact");
        }
        // symmetric by construction; symmetrised so that rounding does not make C(i, j) != C(j, i)
        const Eigen::MatrixXd C = 0.5 * (C0 + C0.transpose());
        const Eigen::MatrixXd Cxs = 0.5 * (Cx + Cx.transpose());
        const Eigen::MatrixXd Ci = 0.5 * sigma2 * (Hinv + Hinv.transpose());
        for (int i = 0; i < p; ++i)
            for (int j = 0; j < p; ++j) {
                cov(free[static_cast<std::size_t>(i)], free[static_cast<std::size_t>(j)]) = C(i, j);
                cov_exact(free[static_cast<std::size_t>(i)], free[static_cast<std::size_t>(j)]) = Cxs(i, j);
                cov_iid(free[static_cast<std::size_t>(i)], free[static_cast<std::size_t>(j)]) = Ci(i, j);
            }
    }
    res.covariance = cov;
    res.covariance_independent = cov_iid;
    res.covariance_exact_lead = cov_exact;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            const double d = std::sqrt(cov(i, i) * cov(j, j));
            res.correlation(i, j) = i == j ? 1.0 : (d > 0.0 ? cov(i, j) / d : 0.0);
        }
    for (int i = 0; i < 5; ++i) {
        ParameterEstimate& e = res.estimates[static_cast<std::size_t>(i)];
        e.name = names[i];
        e.value = theta[i];
        e.fixed = !(pb.hi[i] > pb.lo[i]);
        const double width = pb.hi[i] - pb.lo[i];
        e.at_bound = !e.fixed && (theta[i] - pb.lo[i] <= 1e-6 * width || pb.hi[i] - theta[i] <= 1e-6 * width);
        e.standard_error = e.fixed ? 0.0 : (undetermined[static_cast<std::size_t>(i)] || !finite ? kInf : std::sqrt(std::max(cov(i, i), 0.0)));
        e.lower95 = e.value - res.critical_value * e.standard_error;
        e.upper95 = e.value + res.critical_value * e.standard_error;
    }

    // 5. profile likelihoods on request
    for (const std::string& name : o.profile) {
        const int k = static_cast<int>(std::find(names, names + 5, name) - names);
        ProfileLikelihood pl;
        pl.parameter = name;
        const double se = res.estimates[static_cast<std::size_t>(k)].standard_error;
        double lo = pb.lo[k], hi = pb.hi[k];
        if (std::isfinite(se) && se > 0.0) {
            lo = std::max(lo, theta[k] - 4.0 * se);
            hi = std::min(hi, theta[k] + 4.0 * se);
        }
        const int K = o.profile_points;
        pl.values.resize(static_cast<std::size_t>(K));
        pl.objective.assign(static_cast<std::size_t>(K), kInf);
        for (int j = 0; j < K; ++j) pl.values[static_cast<std::size_t>(j)] = lo + (hi - lo) * j / (K - 1);
        std::vector<int> others;
        for (int i : free)
            if (i != k) others.push_back(i);
        // walk outwards from the optimum, each point started from its neighbour's solution
        const int j0 = static_cast<int>(std::lower_bound(pl.values.begin(), pl.values.end(), theta[k]) - pl.values.begin());
        for (int dir : {-1, 1}) {
            CalibrationVector start = theta;
            for (int j = dir < 0 ? j0 - 1 : j0; j >= 0 && j < K; j += dir) {
                start[k] = pl.values[static_cast<std::size_t>(j)];
                const LmResult lm = levenberg_marquardt(pb, start, others, o, corrected);
                if (std::isfinite(lm.ssr)) start = lm.theta;
                pl.objective[static_cast<std::size_t>(j)] = lm.ssr / std::max(n, 1);
            }
        }
        const double var_ratio = cov_iid(k, k) > 0.0 ? std::max(cov(k, k) / cov_iid(k, k), 1.0) : 1.0;
        const double threshold = res.critical_value * res.critical_value * sigma2 * var_ratio / std::max(n, 1);
        // the profiles minimise what the fit minimised (corrected or not)
        const double fit_objective = res.minimised_objective;
        const double omin = std::min(fit_objective, *std::min_element(pl.objective.begin(), pl.objective.end()));
        if (omin < fit_objective * (1.0 - 1e-9))
            res.warnings.push_back("the profile of " + name + " found a lower objective (" + fmt3(omin) + " < " + fmt3(fit_objective) +
                                   "): the fit is not the global minimum");
        int jm = static_cast<int>(std::min_element(pl.objective.begin(), pl.objective.end()) - pl.objective.begin());
        auto crossing = [&](int dir, double& out, bool& open) {
            int j = jm;
            while (j + dir >= 0 && j + dir < K && pl.objective[static_cast<std::size_t>(j + dir)] - omin <= threshold) j += dir;
            if (j + dir < 0 || j + dir >= K) {
                out = pl.values[static_cast<std::size_t>(j)];
                open = true;
                return;
            }
            const double f0 = pl.objective[static_cast<std::size_t>(j)] - omin, f1 = pl.objective[static_cast<std::size_t>(j + dir)] - omin;
            const double s = std::isfinite(f1) && f1 > f0 ? (threshold - f0) / (f1 - f0) : 0.0;
            out = pl.values[static_cast<std::size_t>(j)] + s * (pl.values[static_cast<std::size_t>(j + dir)] - pl.values[static_cast<std::size_t>(j)]);
        };
        crossing(-1, pl.lower95, pl.lower_open);
        crossing(1, pl.upper95, pl.upper_open);
        res.profiles.push_back(pl);
    }

    // 6. warnings
    for (const std::string& src : pb.uneven)
        res.warnings.push_back((src.empty() ? std::string() : src + ": ") +
                               "the samples are not evenly spaced: the fit is not corrected for the bias of the lead speed's noise (only its intervals allow for it)");
    if (!converged(res.status_code)) res.warnings.push_back("the fit did not converge (" + res.status + "): " + res.message);
    if (!finite) res.warnings.push_back("the simulation at the fitted parameters is not finite: no uncertainty");
    for (const auto& e : res.estimates) {
        const int i = static_cast<int>(&e - res.estimates.data());
        if (e.at_bound) {
            const bool upper = pb.hi[i] - e.value <= e.value - pb.lo[i];
            res.warnings.push_back(e.name + " = " + fmt3(e.value) + " is at its " + (upper ? "upper" : "lower") + " bound (" +
                                   fmt(upper ? pb.hi[i] : pb.lo[i]) + "): the best fit may lie outside the bounds; its interval is not reliable");
        }
        if (!e.fixed && finite && !(e.upper95 - e.lower95 <= pb.hi[i] - pb.lo[i]))
            res.warnings.push_back(e.name + " is not determined by this trace: its 95 % interval " +
                                   (std::isfinite(e.lower95) && std::isfinite(e.upper95) ? "[" + fmt3(e.lower95) + ", " + fmt3(e.upper95) + "]"
                                                                                          : std::string("(unbounded: the trace does not inform it)")) +
                                   " is wider than its bounds [" + fmt(pb.lo[i]) + ", " + fmt(pb.hi[i]) + "]");
        else if (!e.fixed && finite && !e.at_bound && (e.lower95 < pb.lo[i] || e.upper95 > pb.hi[i]))
            res.warnings.push_back(e.name + "'s 95 % interval [" + fmt3(e.lower95) + ", " + fmt3(e.upper95) + "] reaches beyond its bounds [" +
                                   fmt(pb.lo[i]) + ", " + fmt(pb.hi[i]) +
                                   "]: the values outside are not physical or not searched, and the interval (a local, Gaussian approximation) is not "
                                   "reliable there");
    }
    for (const Segment& sg : pb.seg) {
        const Trace& tr = *sg.raw;
        std::size_t bad = 0, first = 0;
        for (std::size_t k = 0; k < tr.gap.size(); ++k)
            if (!(tr.gap[k] > 0.0) && bad++ == 0) first = k;
        if (bad > 0)
            res.warnings.push_back(tr.source + ": " + std::to_string(bad) + " of " + std::to_string(tr.gap.size()) + " gaps are 0 m or less (the first at sample " +
                                   std::to_string(first + 1) + ", time_s = " + fmt(tr.t[first]) + ": gap_m = " + fmt(tr.gap[first]) +
                                   "): kept as a sensor's reading (e.g. during a cut-in), but no car follows at such a gap; fit a window without them (--train)");
    }
    if (res.condition_number > 1e8) {
        std::string which;
        for (int i = 0; i < 5; ++i)
            if (undetermined[static_cast<std::size_t>(i)]) which += (which.empty() ? "" : ", ") + std::string(names[i]);
        res.warnings.push_back("J^T J is nearly singular (condition number " +
                               (std::isfinite(res.condition_number) ? fmt3(res.condition_number) : std::string("beyond double range: singular")) + ")" +
                               (which.empty() ? std::string(": the parameters are strongly correlated") : ": " + which + " not determined by this trace"));
    }
    res.evaluations = pb.evaluations;
    res.jacobian_evaluations = pb.jacobians;
    return res;
}

/// the naive predictor's warning (appended once the whole-file errors are known)
void warn_naive(CalibrationResult& res) {
    if (!(res.all.rmse_speed < res.naive.rmse_speed))
        res.warnings.push_back("the model (speed RMSE " + fmt3(res.all.rmse_speed) + " m/s) is no better than the naive predictor v(t) = v_lead(t - " +
                               fmt3(res.naive_delay) + " s) (" + fmt3(res.naive.rmse_speed) + " m/s)");
}

}  // namespace

double calibration_objective(const Trace& tr, const ParameterMap& p, const CalibrationOptions& o) {
    o.validate();
    LsqProblem pb;
    set_up(pb, {&tr}, o);
    CalibrationVector theta;
    for (int i = 0; i < 5; ++i) theta[i] = p.at(names[i]);
    return pb.ssr(theta) / std::max(pb.samples(), 1);
}

double lead_noise_penalty(const Trace& tr, const ParameterMap& p, const CalibrationOptions& o) {
    o.validate();
    CalibrationOptions oc = o;
    oc.lead_noise_correction = true;
    LsqProblem pb;
    set_up(pb, {&tr}, oc);
    CalibrationVector theta;
    for (int i = 0; i < 5; ++i) theta[i] = p.at(names[i]);
    Eigen::VectorXd r, rho;
    if (!pb.eval(theta, r, nullptr, &rho)) return std::numeric_limits<double>::quiet_NaN();
    return rho.squaredNorm() / std::max(pb.samples(), 1);
}

double calibration_objective(const std::vector<Trace>& runs, const ParameterMap& p, const CalibrationOptions& o) {
    o.validate();
    if (runs.empty()) throw std::invalid_argument("joint objective: expected at least one run");
    LsqProblem pb;
    std::vector<const Trace*> ptr;
    for (const auto& t : runs) ptr.push_back(&t);
    set_up(pb, ptr, o);
    CalibrationVector theta;
    for (int i = 0; i < 5; ++i) theta[i] = p.at(names[i]);
    return pb.ssr(theta) / std::max(pb.samples(), 1);
}

FitEvaluation evaluate_fit(const Trace& tr, const ParameterMap& p, double step) {
    FitEvaluation ev;
    const double first = tr.t.front(), last = tr.t.back(), t_from = first + p.at("tau");
    ev.errors = errors_over(tr, p, first, last, t_from, step, &ev.sim_speed, &ev.sim_gap);
    std::vector<double> sum;
    std::vector<int> count;
    naive_sums(tr, t_from, sum, count);
    double best = kInf;
    for (std::size_t id = 0; id < sum.size(); ++id) {
        const double rmse = std::sqrt(sum[id] / std::max(count[id], 1));
        if (rmse < best) {
            best = rmse;
            ev.naive_delay = 0.1 * static_cast<double>(id);
        }
    }
    ev.naive.rmse_speed = best;
    ev.naive.samples = ev.errors.samples;
    return ev;
}

CalibrationResult calibrate(const Trace& tr, const CalibrationOptions& o) {
    o.validate();
    const auto t_start = std::chrono::steady_clock::now();
    const double first = tr.t.front(), last = tr.t.back();
    LsqProblem pb;
    set_up(pb, {&tr}, o);
    const double a = pb.seg[0].a, b = pb.seg[0].b;
    CalibrationResult res = fit_problem(pb, o);
    // 4. errors and the naive predictor
    res.train = errors_over(tr, res.parameters, a, b, pb.seg[0].t_from, o.step, nullptr, nullptr, pb.seg[0].t_from, pb.seg[0].tr);  // as the objective
    res.all = errors_over(tr, res.parameters, first, last, first + res.parameters.at("tau"), o.step, &res.sim_speed, &res.sim_gap);
    // the test part: the file outside the training window, each piece simulated from its own start
    FitErrors test;
    double sv = 0.0, sg = 0.0;
    for (auto [ta, tb] : {std::pair{first, a}, std::pair{b, last}}) {
        if (tb - ta < 5.0) continue;
        const FitErrors e = errors_over(tr, res.parameters, ta, tb, ta + res.parameters.at("tau"), o.step);
        sv += e.rmse_speed * e.rmse_speed * e.samples;
        sg += e.rmse_gap * e.rmse_gap * e.samples;
        test.samples += e.samples;
    }
    if (test.samples > 0) {
        test.rmse_speed = std::sqrt(sv / test.samples);
        test.rmse_gap = std::sqrt(sg / test.samples);
    }
    res.test = test;
    // the naive predictor v(t) = v_lead(t - d), best constant d in [0, 5] s, same samples as `all`
    const FitEvaluation naive = evaluate_fit(tr, res.parameters, o.step);
    res.naive = naive.naive;
    res.naive_delay = naive.naive_delay;
    res.rmse_speed = res.all.rmse_speed;
    res.rmse_gap = res.all.rmse_gap;
    res.naive_rmse_speed = res.naive.rmse_speed;
    res.runs.push_back({res.all, res.naive, res.naive_delay, res.sim_speed, res.sim_gap});
    warn_naive(res);
    res.evaluations = pb.evaluations;
    res.jacobian_evaluations = pb.jacobians;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return res;
}

CalibrationResult calibrate_joint(const std::vector<Trace>& runs, const CalibrationOptions& o) {
    o.validate();
    if (runs.empty()) throw std::invalid_argument("joint calibration: expected at least one run");
    const auto t_start = std::chrono::steady_clock::now();
    LsqProblem pb;
    std::vector<const Trace*> ptr;
    for (const auto& t : runs) ptr.push_back(&t);
    set_up(pb, ptr, o);
    CalibrationResult res = fit_problem(pb, o);
    // pooled errors: train as the objective (each run's window), all and naive over whole files
    double tv = 0.0, tg = 0.0, av = 0.0, ag = 0.0, nv = 0.0;
    for (const Segment& sg : pb.seg) {
        const FitErrors e = errors_over(*sg.raw, res.parameters, sg.a, sg.b, sg.t_from, o.step, nullptr, nullptr, sg.t_from, sg.tr);
        tv += e.rmse_speed * e.rmse_speed * e.samples;
        tg += e.rmse_gap * e.rmse_gap * e.samples;
        res.train.samples += e.samples;
        const FitEvaluation ev = evaluate_fit(*sg.raw, res.parameters, o.step);
        av += ev.errors.rmse_speed * ev.errors.rmse_speed * ev.errors.samples;
        ag += ev.errors.rmse_gap * ev.errors.rmse_gap * ev.errors.samples;
        res.all.samples += ev.errors.samples;
        res.runs.push_back(ev);
    }
    // the naive predictor pooled over the runs: one delay d for all of them
    std::vector<double> total(51, 0.0);
    std::vector<int> cnt(51, 0);
    for (const Trace& tr : runs) {
        std::vector<double> sum;
        std::vector<int> count;
        naive_sums(tr, tr.t.front() + res.tau, sum, count);
        for (std::size_t id = 0; id < sum.size(); ++id) {
            total[id] += sum[id];
            cnt[id] += count[id];
        }
    }
    nv = kInf;
    for (std::size_t id = 0; id < total.size(); ++id) {
        const double rmse = std::sqrt(total[id] / std::max(cnt[id], 1));
        if (rmse < nv) {
            nv = rmse;
            res.naive_delay = 0.1 * static_cast<double>(id);
        }
    }
    if (res.train.samples > 0) {
        res.train.rmse_speed = std::sqrt(tv / res.train.samples);
        res.train.rmse_gap = std::sqrt(tg / res.train.samples);
    }
    if (res.all.samples > 0) {
        res.all.rmse_speed = std::sqrt(av / res.all.samples);
        res.all.rmse_gap = std::sqrt(ag / res.all.samples);
    }
    res.naive.rmse_speed = nv;
    res.naive.samples = res.all.samples;
    res.rmse_speed = res.all.rmse_speed;
    res.rmse_gap = res.all.rmse_gap;
    res.naive_rmse_speed = nv;
    warn_naive(res);
    res.evaluations = pb.evaluations;
    res.jacobian_evaluations = pb.jacobians;
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return res;
}

std::vector<CalibrationResult> calibrate_many(const std::vector<Trace>& traces, const CalibrationOptions& options,
                                             const ExecutionPolicy& policy) {
    options.validate();
    std::vector<CalibrationResult> fits(traces.size());
    // an error in any trace is rethrown here (the lowest index first), never inside the loop
    parallel_for(static_cast<long>(traces.size()), [&](long i) { fits[i] = calibrate(traces[i], options); }, policy);
    return fits;
}

std::vector<CarCalibration> calibrate_cars(const std::vector<CarRuns>& cars, const CalibrationOptions& options,
                                           const ExecutionPolicy& policy, const CarFinished& finished) {
    options.validate();
    for (const CarRuns& c : cars) {
        if (c.train.empty()) throw std::invalid_argument("car " + detail::quoted(c.car) + ": expected at least one training run");
        if (c.test_types.size() != c.test.size())
            throw std::invalid_argument("car " + detail::quoted(c.car) + ": " + std::to_string(c.test_types.size()) + " test types for " +
                                        std::to_string(c.test.size()) + " test runs: expected one per test run");
    }
    std::vector<CarCalibration> out(cars.size());
    std::mutex lock;
    long done = 0;
    parallel_for(
        static_cast<long>(cars.size()),
        [&](long i) {
            const CarRuns& c = cars[static_cast<std::size_t>(i)];
            CarCalibration& r = out[static_cast<std::size_t>(i)];
            r.car = c.car;
            for (const Trace& t : c.train) r.train_sources.push_back(t.source);
            r.fit = c.train.size() == 1 ? calibrate(c.train[0], options) : calibrate_joint(c.train, options);
            for (std::size_t k = 0; k < c.test.size(); ++k)
                r.tests.push_back({c.test[k].source, c.test_types[k], evaluate_fit(c.test[k], r.fit.parameters, options.step)});
            if (finished) {
                std::lock_guard<std::mutex> guard(lock);
                finished(r, ++done, static_cast<long>(cars.size()));
            }
        },
        policy);
    return out;
}

}  // namespace ddemap
