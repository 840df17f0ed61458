// Branches of discrete travelling waves in the reduced form (analysis/travelling_wave.hpp): one
// car whatever the ring size, so a 1000-car ring should cost what a 10-car ring costs.
//   bench_waves [--points P] [--intervals L] [--repeats R] [--floquet] MODEL:N:K ...
// MODEL ov (alpha = tau = v0 = h_st = 1, headway from 3.5 down to 2) or idm (th = 1.2, tau = 0.6,
// the other parameters default, gap from 6 up to 40); N cars, wave number K. For each entry: the
// median wall and CPU time of R runs of the whole branch (the Hopf point of ring mode K searched
// on the uniform flow, then P waves), the number of waves, the fold, the largest residual and
// drift |mu|. --floquet: the full ring's multipliers where N <= 10 (off by default: only the
// reduced form is timed).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "ddemap/analysis/bifurcation/travelling_wave.hpp"

using namespace ddemap;

namespace {
using ddemap::bench::median;
}  // namespace

int main(int argc, char** argv) {
    int points = 100, intervals = 40, repeats = 5;
    bool floquet = false;
    std::vector<std::string> entries;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--points" && i + 1 < argc) points = std::atoi(argv[++i]);
        else if (a == "--intervals" && i + 1 < argc) intervals = std::atoi(argv[++i]);
        else if (a == "--repeats" && i + 1 < argc) repeats = std::atoi(argv[++i]);
        else if (a == "--floquet") floquet = true;
        else entries.push_back(a);
    }
    if (entries.empty()) entries = {"ov:10:1", "ov:1000:100", "ov:1000:10"};
    std::printf("| model | N cars | k | waves | median wall [s] | median CPU [s] | fold | max residual | max drift | max defect | intervals used | homotopy steps | Newton its | stop |\n"
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    for (const std::string& e : entries) {
        const std::size_t c1 = e.find(':'), c2 = e.find(':', c1 + 1);
        if (c1 == std::string::npos || c2 == std::string::npos) {
            std::fprintf(stderr, "bench_waves: %s: expected MODEL:N:K\n", e.c_str());
            return 2;
        }
        TravellingWaveOptions o;
        o.model = e.substr(0, c1);
        o.cars = std::atoi(e.substr(c1 + 1, c2 - c1 - 1).c_str());
        o.wave = std::atoi(e.substr(c2 + 1).c_str());
        ParameterMap parameters;
        if (o.model == "ov") {
            o.orbit.parameter = "headway";
            o.orbit.from = 3.5;
            o.orbit.to = 2.0;
        } else {
            parameters = {{"th", 1.2}, {"tau", 0.6}};
            o.orbit.parameter = "gap";
            o.orbit.from = 6.0;
            o.orbit.to = 40.0;
        }
        // long waves (21 to 999 cars per wave): their harmonics are nearly resonant at the Hopf
        // point, the first step must be small; 1000 cars per wave go through the homotopy in K / N
        if (o.cars / o.wave > 20 && o.cars / o.wave < 1000) o.orbit.initial_step = 1e-3;
        o.orbit.max_points = points;
        o.orbit.intervals = intervals;
        o.orbit.floquet = floquet;
        std::vector<double> wall, cpu;
        TravellingWaveBranch w;
        for (int r = 0; r < repeats; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            const std::clock_t c0 = std::clock();
            w = travelling_wave_branch(parameters, o);
            cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
            wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        }
        const OrbitBranch& b = w.branch;
        std::printf("| %s | %d | %d | %zu | %.3f | %.3f | %s | %.1e | %.1e | %.1e | %d | %d | %d | %s |\n", o.model.c_str(), o.cars, o.wave, b.points.size(),
                    median(wall), median(cpu), b.folds.empty() ? "-" : std::to_string(b.folds[0].par).c_str(), b.max_residual, w.max_drift, w.max_defect,
                    b.intervals, w.homotopy_steps, b.newton_iterations, b.stop.c_str());
    }
    return 0;
}
