#include "ddemap/analysis/calibrate.hpp"

#include "ddemap/core/execution.hpp"

#include <exception>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <nlopt.hpp>

#include "ddemap/solve/integrate.hpp"
#include "ddemap/core/text.hpp"

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

std::string nlopt_status(nlopt::result r) {
    switch (r) {
        case nlopt::SUCCESS: return "success";
        case nlopt::STOPVAL_REACHED: return "stopval_reached";
        case nlopt::FTOL_REACHED: return "ftol_reached";
        case nlopt::XTOL_REACHED: return "xtol_reached";
        case nlopt::MAXEVAL_REACHED: return "maxeval_reached";
        case nlopt::MAXTIME_REACHED: return "maxtime_reached";
        default: return "failure";
    }
}

}  // namespace

Trace read_trace_csv(const std::string& text, const std::string& source) {
    detail::CsvReader csv(text, source, "time_s, lead_speed_mps, follower_speed_mps, gap_m");
    const char* cols[4] = {"time_s", "lead_speed_mps", "follower_speed_mps", "gap_m"};
    int idx[4];
    for (int c = 0; c < 4; ++c) idx[c] = csv.column(cols[c]);
    Trace tr;
    tr.source = source;
    std::vector<double>* dest[4] = {&tr.t, &tr.lead, &tr.speed, &tr.gap};
    while (csv.next()) {
        for (int c = 0; c < 4; ++c) dest[c]->push_back(csv.number(idx[c], cols[c]));
        const std::size_t n = tr.t.size();
        if (n > 1 && !(tr.t[n - 1] > tr.t[n - 2])) {
            csv.fail("time_s = " + detail::format_number(tr.t[n - 1]) + " after " + detail::format_number(tr.t[n - 2]) +
                     ": expected increasing times");
        }
    }
    if (tr.t.size() < 100 || tr.t.back() - tr.t.front() < 20.0) {
        throw std::invalid_argument(source + ": " + std::to_string(tr.t.size()) + " rows over " +
                                    detail::format_number(tr.t.empty() ? 0.0 : tr.t.back() - tr.t.front()) +
                                    " s: expected at least 100 rows and 20 s");
    }
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
    if (!(gap_weight >= 0.0 && std::isfinite(gap_weight))) throw std::invalid_argument("gap weight = " + detail::format_number(gap_weight) + ": expected >= 0");
    if (global_evaluations < 0 || local_evaluations < 1) throw std::invalid_argument("evaluation budgets: expected global >= 0, local >= 1");
    if (!(step > 0.0 && step <= 0.5)) throw std::invalid_argument("step = " + detail::format_number(step) + ": expected 0 < step <= 0.5 s");
}

void simulate_follower(const Trace& tr, const ParameterMap& p, double t_a, double t_b, double step, std::vector<double>& speed,
                       std::vector<double>& gap) {
    // OVRV's law parameters in its order (k1, k2, th, tau, eta)
    const double law[5] = {p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"), p.at("eta")};
    const double tau = law[3];
    const double t0 = t_a + tau;
    auto history = [&](double t, double* y) {
        y[0] = interp(tr.t, tr.gap, t);
        y[1] = interp(tr.t, tr.speed, t);
    };
    auto rhs = [&](double t, const double* y, const detail::DdeSolver& sol, double* dy) {
        const double vl = interp(tr.t, tr.lead, t);
        dy[0] = vl - y[1];
        const double sd = tau > 0.0 ? sol.value(0, t - tau) : y[0];
        const double vd = tau > 0.0 ? interp(tr.t, tr.lead, t - tau) : vl;
        const double in[3] = {sd, y[1], vd};
        double a = OvrvModel::law(in, law);
        if (y[1] <= 0.0 && a < 0.0) a = 0.0;  // standing cars do not roll backwards
        dy[1] = a;
    };
    detail::DdeSolver sol(2, t0, history, rhs);
    std::vector<double> marks;
    for (double t : tr.t)
        if (t > t0 && t < t_b) marks.push_back(t);
    if (t_b > t0) sol.integrate(t_b, step, marks);
    speed.clear();
    gap.clear();
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
        const double t = tr.t[k];
        if (t < t_a || t > t_b) continue;
        if (t <= t0) {
            speed.push_back(tr.speed[k]);
            gap.push_back(tr.gap[k]);
        } else {
            speed.push_back(sol.value(1, t));
            gap.push_back(sol.value(0, t));
        }
    }
}

namespace {

/// Errors over the samples of [t_a, t_b] at or after t_from.
FitErrors errors_over(const Trace& tr, const ParameterMap& p, double t_a, double t_b, double t_from, double step,
                      std::vector<double>* sim_speed = nullptr, std::vector<double>* sim_gap = nullptr) {
    std::vector<double> v, s;
    simulate_follower(tr, p, t_a, t_b, step, v, s);
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

}  // namespace

CalibrationResult calibrate(const Trace& tr, const CalibrationOptions& o) {
    o.validate();
    const auto t_start = std::chrono::steady_clock::now();
    const double first = tr.t.front(), last = tr.t.back();
    double a = o.train_start < 0.0 ? first : o.train_start;
    double b = o.train_end < 0.0 ? last : o.train_end;
    if (!(a >= first && b <= last && b - a >= 20.0)) {
        throw std::invalid_argument("training window " + detail::format_number(a) + ":" + detail::format_number(b) + " s: expected at least 20 s within the file's " +
                                    detail::format_number(first) + ":" + detail::format_number(last) + " s");
    }
    // every candidate is scored on the same samples: those after the longest admissible delay
    std::vector<double> lo(5), hi(5), x(5);
    for (int i = 0; i < 5; ++i) {
        const BoundedParameter b = o.bound(names[i]);
        lo[i] = b.lower;
        hi[i] = b.upper;
    }
    const double t_from = a + hi[3];
    CalibrationResult res;
    auto objective = [&](const std::vector<double>& x, std::vector<double>&, void*) -> double {
        ParameterMap p;
        for (int i = 0; i < 5; ++i) p[names[i]] = std::clamp(x[i], lo[i], hi[i]);
        const FitErrors e = errors_over(tr, p, a, b, t_from, o.step);
        ++res.evaluations;
        const double f = e.rmse_speed * e.rmse_speed + o.gap_weight * e.rmse_gap * e.rmse_gap;
        return std::isfinite(f) ? f : 1e30;
    };
    struct Fn {
        decltype(objective)* f;
    } fn{&objective};
    auto thunk = [](const std::vector<double>& x, std::vector<double>& g, void* data) {
        return (*static_cast<Fn*>(data)->f)(x, g, nullptr);
    };
    for (int i = 0; i < 5; ++i) x[i] = 0.5 * (lo[i] + hi[i]);
    double fx = 0.0;
    // bounds with zero width are fixed parameters
    if (o.global_evaluations > 0) {
        nlopt::opt global(nlopt::GN_DIRECT_L, 5);
        global.set_lower_bounds(lo);
        global.set_upper_bounds(hi);
        global.set_min_objective(thunk, &fn);
        global.set_maxeval(o.global_evaluations);
        try {
            global.optimize(x, fx);
        } catch (const std::exception&) {
            // keep the best point found so far (NLopt returns it in x)
        }
    }
    nlopt::opt local(nlopt::LN_BOBYQA, 5);
    local.set_lower_bounds(lo);
    local.set_upper_bounds(hi);
    local.set_min_objective(thunk, &fn);
    local.set_maxeval(o.local_evaluations);
    local.set_xtol_rel(1e-6);
    local.set_ftol_rel(1e-10);
    nlopt::result r = nlopt::FAILURE;
    try {
        r = local.optimize(x, fx);
    } catch (const std::exception&) {
        r = nlopt::FAILURE;
    }
    res.status = nlopt_status(r);
    res.objective = fx;
    for (int i = 0; i < 5; ++i) res.parameters[names[i]] = std::clamp(x[i], lo[i], hi[i]);
    res.train = errors_over(tr, res.parameters, a, b, t_from, o.step);
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
    double best = 1e300;
    for (double d = 0.0; d <= 5.0 + 1e-9; d += 0.1) {
        double s = 0.0;
        int n = 0;
        for (std::size_t k = 0; k < tr.t.size(); ++k) {
            if (tr.t[k] < first + res.parameters.at("tau")) continue;
            const double e = interp(tr.t, tr.lead, tr.t[k] - d) - tr.speed[k];
            s += e * e;
            ++n;
        }
        const double rmse = std::sqrt(s / std::max(n, 1));
        if (rmse < best) {
            best = rmse;
            res.naive_delay = d;
        }
    }
    res.naive.rmse_speed = best;
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

}  // namespace ddemap
