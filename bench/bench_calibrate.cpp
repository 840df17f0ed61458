// Benchmark: calibration with uncertainty. Usage:
//   bench_calibrate [--repeats 5] [--duration 300] [FILE.csv ...]
// 1. A synthetic 300 s trace at 10 Hz (a follower simulated with simulate_platoon behind a lead
//    of three sines, noise 0.05 m/s on the speed and 0.2 m on the gap, AR(1) 0.9) fitted with
//    the default options: the median wall time of one fit (with covariance and intervals), the
//    starts, the evaluations (simulations) and those with sensitivities.
// Wall times and the process's CPU time (all threads): on a shared machine the wall time
// depends on the load, the CPU time much less.
// 2. The CPU time of one objective-and-Jacobian evaluation (the simulation with the forward
//    sensitivities) against one plain simulation of the same trace (medians of 50 calls).
// 3. With files: calibrate_many over them (in parallel over the files), the median wall time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "ddemap/analysis/calibration/calibrate.hpp"
#include "ddemap/analysis/simulation/simulate.hpp"
#include "ddemap/core/execution.hpp"

using namespace ddemap;
using clock_type = std::chrono::steady_clock;

namespace {

using ddemap::bench::median;

double cpu_now(clockid_t id) {
    timespec ts{};
    clock_gettime(id, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// wall seconds of f(); the CPU seconds (all threads of the process) in *cpu
template <class F>
double seconds(F&& f, double* cpu = nullptr, clockid_t id = CLOCK_PROCESS_CPUTIME_ID) {
    const double c0 = cpu_now(id);
    const auto t0 = clock_type::now();
    f();
    const double wall = std::chrono::duration<double>(clock_type::now() - t0).count();
    if (cpu) *cpu = cpu_now(id) - c0;
    return wall;
}

Trace synthetic(double duration) {
    std::vector<double> t, v;
    for (int k = 0; k <= static_cast<int>(duration * 10 + 0.5); ++k) {
        const double x = 0.1 * k;
        t.push_back(x);
        v.push_back(20 + 2 * std::sin(0.1 * x) + 1.5 * std::sin(0.27 * x + 1) + 0.8 * std::sin(0.6 * x));
    }
    const ParameterMap p = {{"k1", 0.05}, {"k2", 0.3}, {"th", 1.2}, {"tau", 0.43}, {"eta", 8.0}};
    SimOptions so;
    so.t_end = duration;
    so.step = 0.02;
    const SimResult r = simulate_platoon(LeadProfile(t, v), {SimCar{make_model("ovrv", p), 0.0, "x"}}, so);
    Trace tr;
    tr.source = "synthetic";
    std::mt19937 rng(7);
    std::normal_distribution<double> z(0.0, 1.0);
    double ev = z(rng), eg = z(rng);
    const double c = std::sqrt(1.0 - 0.81);
    for (std::size_t k = 0; k < r.time.size(); ++k) {
        if (k > 0) {
            ev = 0.9 * ev + c * z(rng);
            eg = 0.9 * eg + c * z(rng);
        }
        tr.t.push_back(r.time[k]);
        tr.lead.push_back(r.speed[0][k]);
        tr.speed.push_back(r.speed[1][k] + 0.05 * ev);
        tr.gap.push_back(r.gap[1][k] + 0.2 * eg);
    }
    return tr;
}

}  // namespace

int main(int argc, char** argv) {
    int repeats = 5;
    double duration = 300.0;
    std::vector<std::string> files;
    for (int i = 1; i < argc; ++i) {
        const std::string k = argv[i];
        if (k == "--repeats" && i + 1 < argc) repeats = std::atoi(argv[++i]);
        else if (k == "--duration" && i + 1 < argc) duration = std::atof(argv[++i]);
        else if (!k.empty() && k[0] == '-') {
            std::fprintf(stderr, "bench_calibrate: unknown option %s\n", k.c_str());
            return 2;
        } else files.push_back(k);
    }
    if (repeats < 1 || !(duration >= 30.0)) {
        std::fprintf(stderr, "bench_calibrate: expected --repeats >= 1 and --duration >= 30\n");
        return 2;
    }
    std::printf("threads %d\n", thread_count());
    const Trace tr = synthetic(duration);
    const CalibrationOptions o;
    CalibrationResult fit;
    std::vector<double> tf, cf;
    for (int r = 0; r < repeats; ++r) {
        double c = 0.0;
        tf.push_back(seconds([&] { fit = calibrate(tr, o); }, &c));
        cf.push_back(c);
    }
    std::printf("synthetic %.0f s trace (%zu samples): fit with uncertainty median %.3f s wall over %d runs (min %.3f, max %.3f), CPU %.3f s\n",
                duration, tr.t.size(), median(tf), repeats, *std::min_element(tf.begin(), tf.end()), *std::max_element(tf.begin(), tf.end()),
                median(cf));
    std::printf("  design points %d, starts %d, evaluations %d (with sensitivities %d), status %s\n", o.design_points, fit.starts,
                fit.evaluations, fit.jacobian_evaluations, fit.status.c_str());
    CalibrationVector theta;
    theta << fit.k1, fit.k2, fit.th, fit.tau, fit.eta;
    const double t_from = tr.t.front() + o.bound("tau").upper;
    std::vector<double> plain, jac;
    for (int r = 0; r < 50; ++r) {
        double c = 0.0;
        (void)seconds([&] { (void)simulate_follower(tr, theta, tr.t.front(), tr.t.back(), o.step, false, t_from); }, &c, CLOCK_THREAD_CPUTIME_ID);
        plain.push_back(c);
        (void)seconds([&] { (void)simulate_follower(tr, theta, tr.t.front(), tr.t.back(), o.step, true, t_from); }, &c, CLOCK_THREAD_CPUTIME_ID);
        jac.push_back(c);
    }
    std::printf("  CPU time of one plain simulation %.3f ms, one simulation with sensitivities (objective and Jacobian) %.3f ms, ratio %.2f\n",
                1e3 * median(plain), 1e3 * median(jac), median(jac) / median(plain));
    if (!files.empty()) {
        std::vector<Trace> traces;
        for (const auto& f : files) {
            std::ifstream in(f);
            std::stringstream ss;
            ss << in.rdbuf();
            traces.push_back(read_trace_csv(ss.str(), f));
        }
        std::vector<double> tm, cm;
        std::vector<CalibrationResult> fits;
        for (int r = 0; r < repeats; ++r) {
            double c = 0.0;
            tm.push_back(seconds([&] { fits = calibrate_many(traces, o); }, &c));
            cm.push_back(c);
        }
        long ev = 0, jv = 0;
        for (const auto& f : fits) {
            ev += f.evaluations;
            jv += f.jacobian_evaluations;
        }
        std::printf("%zu files: calibrate_many median %.3f s wall over %d runs (min %.3f, max %.3f), CPU %.3f s; evaluations %ld (with sensitivities %ld)\n",
                    files.size(), median(tm), repeats, *std::min_element(tm.begin(), tm.end()), *std::max_element(tm.begin(), tm.end()), median(cm), ev, jv);
    }
    return 0;
}
