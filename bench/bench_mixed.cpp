// Scaling of the sparse path: the rightmost roots of mixed rings of N cars.
//   bench_mixed [--pattern P] [--count K] [--sparse-max N] [--dense-max N]
//               [--ccc MODEL:NAME=VALUE,... [--ccc-share S] [--seed K]] N1 N2 ...
// --ccc puts that car (connected cruise control) on round(S N) places of the ring, the first
// car of the pattern on the others, in a random order (then the product path is the
// transfer-matrix determinant prod P_i det(I - prod T_i)).
// For each N: the product path (argument principle on prod P_i - prod Q_i), then for
// N <= sparse-max the sparse collocation path and for N <= dense-max the dense path on the same
// ring: wall time, peak resident memory so far, collocation degree, shifts, residuals, and the
// largest distance of the listed roots from those of the first path, and the CPU time (all threads).
#include <sys/resource.h>

#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "ddemap/study/penetration.hpp"

using namespace ddemap;

namespace {
double peak_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024.0;
}
}  // namespace

int main(int argc, char** argv) {
    std::string pattern = "A_min,C_max,E_min,G_max", ccc;
    int count = 10, dense_max = 0, sparse_max = 1000;
    double ccc_share = 0.5;
    unsigned seed = 1;
    std::vector<int> sizes;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--pattern" && i + 1 < argc) pattern = argv[++i];
        else if (a == "--count" && i + 1 < argc) count = std::atoi(argv[++i]);
        else if (a == "--dense-max" && i + 1 < argc) dense_max = std::atoi(argv[++i]);
        else if (a == "--sparse-max" && i + 1 < argc) sparse_max = std::atoi(argv[++i]);
        else if (a == "--ccc" && i + 1 < argc) ccc = argv[++i];
        else if (a == "--ccc-share" && i + 1 < argc) ccc_share = std::atof(argv[++i]);
        else if (a == "--seed" && i + 1 < argc) seed = static_cast<unsigned>(std::atoi(argv[++i]));
        else sizes.push_back(std::atoi(a.c_str()));
    }
    if (sizes.empty()) sizes = {100, 500, 1000, 2000};
    if (ccc.empty())
        std::printf("pattern %s, %d rightmost roots, speed 20 m/s\n", pattern.c_str(), count);
    else
        std::printf("round(%g N) cars %s among %s cars in random order (seed %u), %d rightmost roots, speed 20 m/s\n", ccc_share,
                    ccc.c_str(), pattern.c_str(), seed, count);
    std::printf("%7s %7s %9s %9s %4s %6s %6s %10s %10s %22s %s\n", "N", "path", "time_s", "peak_MiB", "M", "shifts", "LUs", "residual",
                "vs_first", "abscissa", "status cpu_s");
    // the paths by their old names: product = contour, sparse = shift_invert
    const std::pair<const char*, const char*> paths[] = {{"product", "contour"}, {"sparse", "shift_invert"}, {"dense", "dense"}};
    for (int n : sizes) {
        // --ccc: that car (MODEL:NAME=VALUE,...) on a share of the ring, the first car of the
        // pattern on the rest, in a random order (mixed_fleet's draw 1 from the seed)
        const Fleet fleet = ccc.empty() ? fleet_from_pattern(pattern, n)
                                        : mixed_fleet(parse_fleet_car(ccc), fleet_from_pattern(pattern, 1)[0], n,
                                                      static_cast<int>(std::lround(ccc_share * n)), 1, seed);
        std::vector<Root> first;
        for (const auto& [label, method] : paths) {
            if (std::string(method) == "shift_invert" && n > sparse_max) continue;
            if (std::string(method) == "dense" && n > dense_max) continue;
            MixedRingOptions o;
            o.speed = 20.0;
            o.roots.count = count;
            o.roots.method = method;
            const auto t0 = std::chrono::steady_clock::now();
            const std::clock_t c0 = std::clock();
            const MixedRingResult r = analyse_mixed_ring(fleet, o);
            const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
            double diff = 0.0;
            if (first.empty()) {
                first = r.roots.roots;
            } else {
                for (std::size_t i = 0; i < std::min(first.size(), r.roots.roots.size()); ++i)
                    diff = std::max(diff, std::abs(first[i].value - r.roots.roots[i].value));
                if (first.size() != r.roots.roots.size()) diff = std::numeric_limits<double>::infinity();
            }
            std::printf("%7d %7s %9.3f %9.1f %4d %6d %6d %10.2e %10.2e %22.17g %s %.3f\n", n, label, dt, peak_mib(),
                        r.roots.degree, r.roots.shifts, r.roots.factorizations, r.roots.max_residual, diff, r.spectral_abscissa,
                        to_string(r.roots.status).c_str(), cpu);
            std::fflush(stdout);
        }
    }
    return 0;
}
