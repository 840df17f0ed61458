#pragma once
// Synthetic car-following traces for the calibration tests: a follower simulated by
// simulate_platoon (its own equilibrium history, an independent code path from the calibration's
// simulation) behind a given lead, sampled at 10 Hz, with Gaussian noise (white, or AR(1) with
// coefficient phi: the same marginal spread, correlated in time like GNSS errors).
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"

namespace calib_test {

inline ddemap::ParameterMap ovrv(const double (&p)[5]) {
    return {{"k1", p[0]}, {"k2", p[1]}, {"th", p[2]}, {"tau", p[3]}, {"eta", p[4]}};
}

/// the lead of the original test: three frequencies around 20 m/s, `duration` s
inline ddemap::LeadProfile three_sines(double duration) {
    std::vector<double> t, v;
    for (int k = 0; k <= static_cast<int>(duration * 10 + 0.5); ++k) {
        const double x = 0.1 * k;
        t.push_back(x);
        v.push_back(20 + 2 * std::sin(0.1 * x) + 1.5 * std::sin(0.27 * x + 1) + 0.8 * std::sin(0.6 * x));
    }
    return ddemap::LeadProfile(t, v);
}

/// the noise-free trace: lead speed, follower speed and gap at 10 Hz up to `duration`
inline ddemap::Trace clean_trace(const ddemap::ParameterMap& p, const ddemap::LeadProfile& lead, double duration) {
    ddemap::SimOptions o;
    o.t_end = duration;
    o.step = 0.02;
    const ddemap::SimResult r = ddemap::simulate_platoon(lead, {ddemap::SimCar{ddemap::make_model("ovrv", p), 0.0, "x"}}, o);
    ddemap::Trace tr;
    tr.source = "synthetic";
    for (std::size_t k = 0; k < r.time.size(); ++k) {
        tr.t.push_back(r.time[k]);
        tr.lead.push_back(r.speed[0][k]);
        tr.speed.push_back(r.speed[1][k]);
        tr.gap.push_back(r.gap[1][k]);
    }
    return tr;
}

/// adds noise of spread sv [m/s] to the follower speed and sg [m] to the gap, AR(1) with phi
inline ddemap::Trace noisy(ddemap::Trace tr, unsigned seed, double sv = 0.05, double sg = 0.2, double phi = 0.0) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> z(0.0, 1.0);
    const double c = std::sqrt(1.0 - phi * phi);
    double ev = z(rng), eg = z(rng);
    for (std::size_t k = 0; k < tr.t.size(); ++k) {
        if (k > 0) {
            ev = phi * ev + c * z(rng);
            eg = phi * eg + c * z(rng);
        }
        tr.speed[k] += sv * ev;
        tr.gap[k] += sg * eg;
    }
    return tr;
}

/// The coverage tests' fit options: 16 design points and 2 starts (the minimum is easy to find
/// on these traces; the intervals are the point)
inline ddemap::CalibrationOptions coverage_options() {
    ddemap::CalibrationOptions o;
    o.design_points = 16;
    o.starts = 2;
    return o;
}

/// `count` noise draws of `clean` with white noise on all three signals: sv [m/s] on the follower
/// speed and sg [m] on the gap (seeds 1000 + s), sl [m/s] on the lead speed (seeds 77777 + s)
inline std::vector<ddemap::Trace> noisy_with_lead(const ddemap::Trace& clean, int count, double sv = 0.05, double sg = 0.2, double sl = 0.05) {
    std::vector<ddemap::Trace> traces;
    for (int s = 0; s < count; ++s) {
        ddemap::Trace tr = noisy(clean, 1000u + static_cast<unsigned>(s), sv, sg, 0.0);
        std::mt19937 rng(77777u + static_cast<unsigned>(s));
        std::normal_distribution<double> z(0.0, 1.0);
        for (double& v : tr.lead) v += sl * z(rng);
        traces.push_back(std::move(tr));
    }
    return traces;
}

}  // namespace calib_test
