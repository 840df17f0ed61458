// Scaling of the sparse path: the rightmost roots of mixed rings of N cars.
//   bench_mixed [--pattern P] [--count K] [--dense-max N] N1 N2 ...
// For each N: wall time, peak resident memory so far, collocation degree, shifts, residuals,
// and (for N <= dense-max) the dense path on the same ring for comparison.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ddemap/fleet.hpp"

using namespace ddemap;

namespace {
double peak_mib() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return u.ru_maxrss / 1024.0;
}
}  // namespace

int main(int argc, char** argv) {
    std::string pattern = "A_min,C_max,E_min,G_max";
    int count = 10, dense_max = 0;
    std::vector<int> sizes;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--pattern" && i + 1 < argc) pattern = argv[++i];
        else if (a == "--count" && i + 1 < argc) count = std::atoi(argv[++i]);
        else if (a == "--dense-max" && i + 1 < argc) dense_max = std::atoi(argv[++i]);
        else sizes.push_back(std::atoi(a.c_str()));
    }
    if (sizes.empty()) sizes = {100, 500, 1000, 2000};
    std::printf("pattern %s, %d rightmost roots, speed 20 m/s\n", pattern.c_str(), count);
    std::printf("%7s %7s %9s %9s %4s %6s %6s %10s %10s %13s %s\n", "N", "path", "time_s", "peak_MiB", "M", "shifts", "LUs", "residual",
                "eig_err", "abscissa", "status");
    for (int n : sizes) {
        for (int pass = 0; pass < (n <= dense_max ? 2 : 1); ++pass) {
            const Fleet fleet = fleet_from_pattern(pattern, n);
            MixedRingOptions o;
            o.speed = 20.0;
            o.roots.count = count;
            o.method = pass == 0 ? SolverMethod::Sparse : SolverMethod::Dense;
            const auto t0 = std::chrono::steady_clock::now();
            const MixedRingResult r = analyse_mixed_ring(fleet, o);
            const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            std::printf("%7d %7s %9.3f %9.1f %4d %6d %6d %10.2e %10.2e %13.6e %s\n", n, pass == 0 ? "sparse" : "dense", dt, peak_mib(),
                        r.roots.degree, r.roots.shifts, r.roots.factorizations, r.roots.max_residual, r.roots.collocation_error,
                        r.spectral_abscissa, to_string(r.roots.status).c_str());
            std::fflush(stdout);
        }
    }
    return 0;
}
