// Benchmark: (k1, k2) sweeps of rings of N cars with the winding tables (ring method "winding",
// cost independent of N) against today's per-mode certificates (ring method "modes"), measured
// in the same run. Usage:
//   bench_ring_winding [--grid 200] [--ref-grid 50] [--repeats 3] [--tau 0.5] [--th 1.5]
//                      [--cars 22,1000,1000000,inf] [--threads 0]
// For every N it prints the median wall time and points/s of the winding sweep on grid x grid,
// the ring part alone (analyse_ring_winding along the rows, one thread, microseconds per point),
// the per-mode sweep's points/s on ref-grid x ref-grid (skipped above 2000 cars: N/2 + 1 modes
// per point), and on the ref grid the largest abscissa difference and the verdict mismatches
// between the two paths.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "ddemap/analysis/stability/ring_winding.hpp"
#include "ddemap/core/execution.hpp"
#include "ddemap/study/sweep.hpp"

using namespace ddemap;
using clock_type = std::chrono::steady_clock;

namespace {

SweepSpec chart(int grid, int cars, double th, double tau, const std::string& method) {
    SweepSpec spec;
    spec.fixed = {{"th", th}, {"tau", tau}};
    spec.x = parse_axis("k1", "0.01:1:" + std::to_string(grid));
    spec.y = parse_axis("k2", "0.01:1:" + std::to_string(grid));
    spec.cars = cars;
    spec.ring_method = method;
    return spec;
}

using ddemap::bench::median;

}  // namespace

int main(int argc, char** argv) {
    int grid = 200, ref_grid = 50, repeats = 3, threads = 0;
    double tau = 0.5, th = 1.5;
    std::string cars_list = "22,1000,1000000,inf";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string k = argv[i];
        const char* v = argv[i + 1];
        if (k == "--grid") grid = std::atoi(v);
        else if (k == "--ref-grid") ref_grid = std::atoi(v);
        else if (k == "--repeats") repeats = std::atoi(v);
        else if (k == "--threads") threads = std::atoi(v);
        else if (k == "--tau") tau = std::atof(v);
        else if (k == "--th") th = std::atof(v);
        else if (k == "--cars") cars_list = v;
        else {
            std::fprintf(stderr, "bench_ring_winding: unknown option %s\n", k.c_str());
            return 2;
        }
    }
    if (grid < 2 || ref_grid < 2 || repeats < 1 || threads < 0) {
        std::fprintf(stderr, "bench_ring_winding: expected grid >= 2, ref-grid >= 2, repeats >= 1, threads >= 0\n");
        return 2;
    }
    std::vector<int> rings;
    {
        std::stringstream ss(cars_list);
        std::string item;
        while (std::getline(ss, item, ',')) rings.push_back(item == "inf" ? 0 : std::atoi(item.c_str()));
    }
    ExecutionPolicy policy;
    policy.threads = threads;
    std::printf("grid %d x %d, th %g, tau %g, %d threads, median of %d runs\n", grid, grid, th, tau, thread_count(policy), repeats);
    for (int cars : rings) {
        const std::string name = cars == 0 ? "inf" : std::to_string(cars);
        // the winding sweep
        const SweepSpec fast = chart(grid, cars, th, tau, "winding");
        std::vector<double> times;
        SweepResult fr;
        for (int r = 0; r < repeats; ++r) {
            const auto t0 = clock_type::now();
            fr = run_sweep(fast, policy);
            times.push_back(std::chrono::duration<double>(clock_type::now() - t0).count());
        }
        const double n = static_cast<double>(fr.points.size());
        const double fast_s = median(times);
        // the ring part alone, one thread, rows continued as in the sweep
        std::vector<Linearisation> lins;
        for (int iy = 0; iy < grid; ++iy)
            for (int ix = 0; ix < grid; ++ix) lins.push_back(model_at(fast, fast.x.value(ix), fast.y.value(iy))->linearise());
        const auto r0 = clock_type::now();
        long evaluations = 0;
        for (int iy = 0; iy < grid; ++iy) {
            RingWindingGuess g;
            for (int ix = 0; ix < grid; ++ix) {
                const RingWindingResult w = analyse_ring_winding(lins[static_cast<std::size_t>(iy) * grid + ix], cars, {}, g);
                g = w.next;
                evaluations += w.evaluations;
            }
        }
        const double ring_us = std::chrono::duration<double>(clock_type::now() - r0).count() / n * 1e6;
        std::printf("N = %-8s winding  %.3f s (min %.3f, max %.3f): %.0f points/s; %.2f tables and %.0f evaluations per point, "
                    "%d fallbacks, %d uncertified, %d collocation starts; ring part alone %.1f us/point (1 thread)\n",
                    name.c_str(), fast_s, *std::min_element(times.begin(), times.end()), *std::max_element(times.begin(), times.end()),
                    n / fast_s, fr.winding_tables / n, evaluations / n, fr.winding_fallbacks, fr.uncertified, fr.fallbacks, ring_us);
        if (cars > kWindingFallbackCars) {
            std::printf("N = %-8s modes    skipped (%d modes per point)\n", name.c_str(), cars / 2 + 1);
            continue;
        }
        // the per-mode path on the reference grid, and the winding path on the same grid
        const SweepSpec ref = chart(ref_grid, cars, th, tau, "modes");
        const SweepSpec same = chart(ref_grid, cars, th, tau, "winding");
        std::vector<double> rt, st;
        SweepResult rr, sr;
        for (int r = 0; r < repeats; ++r) {
            auto t0 = clock_type::now();
            rr = run_sweep(ref, policy);
            rt.push_back(std::chrono::duration<double>(clock_type::now() - t0).count());
            t0 = clock_type::now();
            sr = run_sweep(same, policy);
            st.push_back(std::chrono::duration<double>(clock_type::now() - t0).count());
        }
        double diff = 0.0;
        int mismatches = 0;
        for (std::size_t i = 0; i < rr.points.size(); ++i) {
            diff = std::max(diff, std::abs(rr.points[i].spectral_abscissa - sr.points[i].spectral_abscissa));
            mismatches += rr.points[i].ring_stable != sr.points[i].ring_stable || rr.points[i].unstable_roots != sr.points[i].unstable_roots;
        }
        const double m = static_cast<double>(rr.points.size());
        std::printf("N = %-8s modes    %.3f s on %d x %d: %.0f points/s; winding on that grid %.0f points/s (%.1fx); "
                    "max |abscissa difference| %.2g, %d verdict or count mismatches\n",
                    name.c_str(), median(rt), ref_grid, ref_grid, m / median(rt), m / median(st), median(rt) / median(st), diff, mismatches);
    }
    return 0;
}
