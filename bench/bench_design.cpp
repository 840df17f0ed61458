// Benchmark: `design --objective nearest` against a brute-force grid search of the same answer.
// Usage: bench_design [--repeats 3] [--car C_max] [--grid 25,50,100,200]
// For the car's (k1, k2) with th and tau held, the nearest gains with an attenuation margin of
// at least 0.1 s:
// 1. design_gains (sequential QP from 4 starts): median wall time of `repeats` runs, and its
//    relative change d*;
// 2. the grid: G x G points of the default box [k/10, 10 k] (logarithmic in each gain), the
//    points taken in order of increasing relative change until the first whose plant is stable
//    and whose attenuation margin is at least 0.1 s (one plant analysis and one scan each; the
//    most favourable order for a grid): its wall time, the points scanned and its error d_G - d*
//    (never below 0; it falls like the spacing).
// The time ratio at equal accuracy compares design with the grid whose error is closest to
// design's own (about 1e-8 relative: no practical grid gets there; the table says how far each
// grid is).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "ddemap/analysis/design/design.hpp"
#include "ddemap/traffic/vehicles.hpp"

using namespace ddemap;
using clock_type = std::chrono::steady_clock;

namespace {
using ddemap::bench::median;
double seconds_since(clock_type::time_point t0) { return std::chrono::duration<double>(clock_type::now() - t0).count(); }
}  // namespace

int main(int argc, char** argv) {
    int repeats = 3;
    std::string car_name = "C_max";
    std::vector<int> grids{25, 50, 100, 200};
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--car") && i + 1 < argc) car_name = argv[++i];
        else if (!std::strcmp(argv[i], "--grid") && i + 1 < argc) {
            grids.clear();
            std::stringstream ss(argv[++i]);
            std::string item;
            while (std::getline(ss, item, ',')) grids.push_back(std::atoi(item.c_str()));
        } else {
            std::fprintf(stderr, "usage: bench_design [--repeats 3] [--car C_max] [--grid 25,50,100,200]\n");
            return 2;
        }
    }
    ParameterMap car = builtin_vehicle(car_name).parameters;
    car["speed"] = 20.0;
    DesignOptions o;
    o.objective = DesignObjective::Nearest;
    std::vector<double> times;
    double best = 0.0;
    for (int r = 0; r < repeats; ++r) {
        const auto t0 = clock_type::now();
        const DesignResult d = design_gains("ovrv", car, o);
        times.push_back(seconds_since(t0));
        best = d.change;
    }
    std::printf("car %s, nearest gains with an attenuation margin >= %g s\n", car_name.c_str(), o.margin);
    std::printf("design: relative change %.10f, median %.3f s of %d runs\n", best, median(times), repeats);
    std::printf("%8s %12s %14s %14s %10s\n", "grid", "scanned", "change", "error", "time [s]");
    const double k1 = car.at("k1"), k2 = car.at("k2");
    for (int G : grids) {
        const auto t0 = clock_type::now();
        // the most favourable brute force: the grid points in order of increasing change,
        // stopping at the first that meets the margin
        std::vector<std::pair<double, std::pair<double, double>>> pts;
        for (int i = 0; i < G; ++i)
            for (int j = 0; j < G; ++j) {
                const double a = k1 * std::pow(10.0, -1.0 + 2.0 * i / (G - 1)), b = k2 * std::pow(10.0, -1.0 + 2.0 * j / (G - 1));
                pts.push_back({std::hypot(a / k1 - 1.0, b / k2 - 1.0), {a, b}});
            }
        std::sort(pts.begin(), pts.end());
        double least = -1.0;
        long scanned = 0;
        for (const auto& [dist, ab] : pts) {
            ParameterMap p = car;
            p["k1"] = ab.first;
            p["k2"] = ab.second;
            const Linearisation lin = make_model("ovrv", p)->linearise();
            if (!is_computable(lin)) continue;
            ++scanned;
            const StringResult s = analyse_string(lin);
            if (s.plant_stable && attenuation_scan(lin).margin >= o.margin) {
                least = dist;
                break;
            }
        }
        const double t = seconds_since(t0);
        std::printf("%8d %12ld %14.10f %14.3e %10.3f\n", G, scanned, least, least - best, t);
    }
    return 0;
}
