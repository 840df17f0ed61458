// A branch of periodic orbits of the ov ring (Orosz, Wilson, Stepan 2004; alpha = tau = v0 =
// h_st = 1) from the subcritical Hopf point of ring mode 1 above the inflection of V:
//   bench_orbits [--points P] [--intervals L] [--degree D] N1 N2 ...
// For each N: wall time of the branch (P orbits, Floquet multipliers of every orbit), the fold of
// orbits, the largest |mu_trivial - 1|. The Hopf point comes from the ring modes' closed form
// (see test_equilibrium_branch.cpp), corrected by Newton, so the equilibrium branch is not timed.
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ddemap/analysis/equilibrium_branch.hpp"
#include "ddemap/analysis/periodic_orbit.hpp"
#include "ddemap/traffic/ov_ring.hpp"

using namespace ddemap;

namespace {
template <class G>
double bisect(G g, double lo, double hi) {
    const bool neg = g(lo) < 0;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        ((g(mid) < 0) == neg ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}
}  // namespace

int main(int argc, char** argv) {
    int points = 100, intervals = 40, degree = 4;
    std::vector<int> sizes;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--points" && i + 1 < argc) points = std::atoi(argv[++i]);
        else if (a == "--intervals" && i + 1 < argc) intervals = std::atoi(argv[++i]);
        else if (a == "--degree" && i + 1 < argc) degree = std::atoi(argv[++i]);
        else sizes.push_back(std::atoi(a.c_str()));
    }
    if (sizes.empty()) sizes = {5, 10};
    const double pi = 3.14159265358979323846, alpha = 1.0, tau = 1.0;
    std::printf("| N cars | states | orbits | wall [s] | CPU [s] | fold headway | max trivial dist | Newton its |\n|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (int n : sizes) {
        const double theta = 2 * pi / n;
        const double omega = bisect([&](double w) { return w * tau - theta / 2 + pi / 2 - std::atan(alpha / w); }, 1e-6, 10.0);
        const double slope = omega * std::sqrt(omega * omega + alpha * alpha) / (2 * alpha * std::sin(theta / 2));
        auto vprime = [](double h) {
            const double y = h - 1.0;
            return 3 * y * y / ((1 + y * y * y) * (1 + y * y * y));
        };
        const double h0 = bisect([&](double h) { return vprime(h) - slope; }, 1.0 + std::cbrt(0.5), 20.0);
        OvRing ring(n, alpha, tau, 1.0, 1.0, h0);
        const HopfPoint hopf = correct_hopf(ring, ring.parameter_index("headway"), ring.uniform_flow(), h0, omega);
        if (hopf.status != Status::Converged) {
            std::printf("| %d | Hopf point not converged |\n", n);
            continue;
        }
        ring.set_parameter("headway", hopf.par);
        PeriodicOrbitOptions o;
        o.parameter = "headway";
        o.from = hopf.par - 1.5;
        o.to = hopf.par + 1.5;
        o.max_points = points;
        o.intervals = intervals;
        o.degree = degree;
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        const OrbitBranch b = orbit_branch_from_hopf(ring, hopf, o);
        const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
        std::printf("| %d | %d | %zu | %.2f | %.2f | %s | %.1e | %d |\n", n, ring.dimension(), b.points.size(), t, cpu,
                    b.folds.empty() ? "-" : std::to_string(b.folds[0].par).c_str(), b.max_trivial_distance, b.newton_iterations);
        std::fflush(stdout);
    }
}
