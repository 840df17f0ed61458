// Benchmark: a (k1, k2) sweep of a ring against the plain per-point dense computation, both
// measured in the same run. Usage:
//   bench_sweep [--grid 200] [--cars 22] [--tau 0.5] [--th 1.5] [--repeats 3] [--baseline 400]
// Prints the median wall time of the sweep, points per second, the baseline's points per
// second (per-point collocation of every ring mode and of the plant, plus the transfer-function
// scan, on `baseline` grid points spread over the grid), their ratio, and the largest
// difference in the spectral abscissa between the two on those points.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>


#include "ddemap/core/execution.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "ddemap/study/sweep.hpp"

using namespace ddemap;
using clock_type = std::chrono::steady_clock;

int main(int argc, char** argv) {
    int grid = 200, cars = 22, repeats = 3, baseline = 400;
    double tau = 0.5, th = 1.5;
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        const char* v = argv[i + 1];
        if (k == "--grid") grid = std::atoi(v);
        else if (k == "--cars") cars = std::atoi(v);
        else if (k == "--repeats") repeats = std::atoi(v);
        else if (k == "--baseline") baseline = std::atoi(v);
        else if (k == "--tau") tau = std::atof(v);
        else if (k == "--th") th = std::atof(v);
        else {
            std::fprintf(stderr, "bench_sweep: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    if (grid < 2 || cars < 2 || repeats < 1 || baseline < 1) {
        std::fprintf(stderr, "bench_sweep: expected grid >= 2, cars >= 2, repeats >= 1, baseline >= 1\n");
        return 2;
    }
    SweepSpec spec;
    spec.fixed = {{"th", th}, {"tau", tau}};
    spec.x = parse_axis("k1", "0.01:1:" + std::to_string(grid));
    spec.y = parse_axis("k2", "0.01:1:" + std::to_string(grid));
    spec.cars = cars;

    std::vector<double> times;
    SweepResult result;
    for (int r = 0; r < repeats; ++r) {
        const auto t0 = clock_type::now();
        result = run_sweep(spec);
        times.push_back(std::chrono::duration<double>(clock_type::now() - t0).count());
    }
    std::sort(times.begin(), times.end());
    const double sweep_s = times[times.size() / 2];
    const double n = static_cast<double>(result.points.size());

    // baseline: the plain per-point computation on points spread over the grid
    const std::size_t step = std::max<std::size_t>(1, result.points.size() / baseline);
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < result.points.size() && idx.size() < std::size_t(baseline); i += step) idx.push_back(i);
    std::vector<double> abscissa(idx.size());
    std::vector<int> verdict_ok(idx.size());
    const auto t0 = clock_type::now();
    parallel_for(static_cast<long>(idx.size()), [&](long j) {
        const SweepPoint& p = result.points[idx[j]];
        const Linearisation lin = model_at(spec, p.x, p.y)->linearise();
        const RingResult ring = analyse_ring(lin, cars);
        const StringResult s = analyse_string(lin);
        abscissa[j] = ring.spectral_abscissa;
        verdict_ok[j] = ring.stable == p.ring_stable && s.string_stable == p.string_stable && s.plant_stable == p.plant_stable;
    });
    const double base_s = std::chrono::duration<double>(clock_type::now() - t0).count();
    double max_diff = 0.0;
    int mismatches = 0;
    for (std::size_t j = 0; j < idx.size(); ++j) {
        max_diff = std::max(max_diff, std::abs(abscissa[j] - result.points[idx[j]].spectral_abscissa));
        mismatches += !verdict_ok[j];
    }
    const double base_rate = idx.size() / base_s;
    const int threads = thread_count();
    std::printf("grid %dx%d, ring N=%d, tau=%g, th=%g, threads=%d\n", grid, grid, cars, tau, th, threads);
    std::printf("sweep     median %.3f s over %d runs (min %.3f, max %.3f): %.0f points/s, %d collocation fallbacks, %d uncertified\n",
                sweep_s, repeats, times.front(), times.back(), n / sweep_s, result.fallbacks, result.uncertified);
    std::printf("baseline  %zu points in %.3f s: %.0f points/s (per-point collocation, every mode, plus the transfer scan)\n",
                idx.size(), base_s, base_rate);
    std::printf("ratio     sweep / baseline = %.1fx\n", (n / sweep_s) / base_rate);
    std::printf("check     max |abscissa(sweep) - abscissa(per point)| = %.3g on %zu points, %d verdict mismatches\n",
                max_diff, idx.size(), mismatches);
    return mismatches == 0 && max_diff < 1e-8 ? 0 : 1;
}
