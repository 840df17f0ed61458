// A branch of periodic orbits of a car-following ring, every orbit with its Floquet multipliers.
//   bench_orbits [--model ov|idm] [--points P] [--intervals L] [--degree D] [--repeats R] [--max-step S] [--to G] [--csv FILE] N1 N2 ...
// --csv FILE: every orbit of the (last) branch, parameter, period, number of nontrivial
// multipliers with |mu| > 1, the largest nontrivial |mu| and |mu_trivial - 1| (for the point-by-point
// comparison with DDE-BIFTOOL's stability, bench/ddebiftool/compare_stability.py).
// ov (default): the ov ring of Orosz, Wilson, Stepan 2004 (alpha = tau = v0 = h_st = 1) from the
// subcritical Hopf point of ring mode 1 above the inflection of V (from the ring modes' closed
// form, corrected by Newton). idm: the IDM ring (th = 1.2 s, tau = 0.6 s, the other parameters
// at their defaults) from the first Hopf point of its equilibrium branch in the gap from 6 to G m
// (G = 40 unless --to), the branch the command line computes with
//   ddemap orbits --model idm --ring N --th 1.2 --tau 0.6 --par gap --from 6 --to G --points P [--max-step S]
// (--max-step: PeriodicOrbitOptions::max_step, default 0.1).
// In both cases the Hopf point is not timed. For each N: the median wall and CPU time of the
// branch over R runs, its folds, period doublings and tori, the largest |mu_trivial - 1|, the
// Newton iterations, and a few values of the branch (to compare results between builds).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "bench_util.hpp"
#include "ddemap/analysis/bifurcation/equilibrium_branch.hpp"
#include "ddemap/analysis/bifurcation/periodic_orbit.hpp"
#include "ddemap/traffic/nonlinear_ring.hpp"
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

using ddemap::bench::median;

struct Problem {
    std::unique_ptr<NonlinearDDE> system;
    HopfPoint hopf;
    PeriodicOrbitOptions options;
    bool ok = false;
};

Problem ov_problem(int n) {
    Problem r;
    const double pi = 3.14159265358979323846, alpha = 1.0, tau = 1.0;
    const double theta = 2 * pi / n;
    const double omega = bisect([&](double w) { return w * tau - theta / 2 + pi / 2 - std::atan(alpha / w); }, 1e-6, 10.0);
    const double slope = omega * std::sqrt(omega * omega + alpha * alpha) / (2 * alpha * std::sin(theta / 2));
    auto vprime = [](double h) {
        const double y = h - 1.0;
        return 3 * y * y / ((1 + y * y * y) * (1 + y * y * y));
    };
    const double h0 = bisect([&](double h) { return vprime(h) - slope; }, 1.0 + std::cbrt(0.5), 20.0);
    auto ring = std::make_unique<OvRing>(n, alpha, tau, 1.0, 1.0, h0);
    r.hopf = correct_hopf(*ring, ring->parameter_index("headway"), ring->uniform_flow(), h0, omega);
    if (r.hopf.status != Status::Converged) return r;
    ring->set_parameter("headway", r.hopf.par);
    r.options.parameter = "headway";
    r.options.from = r.hopf.par - 1.5;
    r.options.to = r.hopf.par + 1.5;
    r.system = std::move(ring);
    r.ok = true;
    return r;
}

Problem idm_problem(int n, double to) {
    Problem r;
    NonlinearRing ring = make_nonlinear_ring("idm", n, ParameterMap{{"th", 1.2}, {"tau", 0.6}}, "gap", 6.0);
    EquilibriumBranchOptions eo;
    eo.parameter = "gap";
    eo.from = 6.0;
    eo.to = to;
    eo.roots.count = 2;
    const EquilibriumBranch eq = equilibrium_branch(*ring.system, ring.uniform_flow, eo);
    if (eq.hopf.empty()) return r;
    r.hopf = eq.hopf.front();
    r.options.parameter = "gap";
    r.options.from = 6.0;
    r.options.to = to;
    r.system = std::move(ring.system);
    r.ok = r.hopf.status == Status::Converged;
    return r;
}
}  // namespace

int main(int argc, char** argv) {
    int points = 100, intervals = 40, degree = 4, repeats = 1;
    double max_step = PeriodicOrbitOptions().max_step, to = 40.0;
    std::string model = "ov", csv;
    std::vector<int> sizes;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--points" && i + 1 < argc) points = std::atoi(argv[++i]);
        else if (a == "--intervals" && i + 1 < argc) intervals = std::atoi(argv[++i]);
        else if (a == "--degree" && i + 1 < argc) degree = std::atoi(argv[++i]);
        else if (a == "--repeats" && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
        else if (a == "--model" && i + 1 < argc) model = argv[++i];
        else if (a == "--max-step" && i + 1 < argc) max_step = std::atof(argv[++i]);
        else if (a == "--to" && i + 1 < argc) to = std::atof(argv[++i]);
        else if (a == "--csv" && i + 1 < argc) csv = argv[++i];
        else sizes.push_back(std::atoi(a.c_str()));
    }
    if (model != "ov" && model != "idm") {
        std::fprintf(stderr, "bench_orbits: --model ov|idm\n");
        return 2;
    }
    if (sizes.empty()) sizes = {5, 10};
    if (!(to > 9.0) || !(max_step >= PeriodicOrbitOptions().initial_step)) {
        std::fprintf(stderr, "bench_orbits: --to above 9 (the Hopf points lie near 8), --max-step at least the initial step 0.02\n");
        return 2;
    }
    std::printf("model %s, degree %d, %d intervals, at most %d orbits, max step %g, median of %d run(s)\n", model.c_str(), degree, intervals, points,
                max_step, repeats);
    std::printf("| N cars | states | orbits | wall [s] | CPU [s] | folds | PD | tori | max trivial dist | Newton its |\n"
                "|---:|---:|---:|---:|---:|---|---|---|---:|---:|\n");
    for (int n : sizes) {
        Problem pr = model == "ov" ? ov_problem(n) : idm_problem(n, to);
        if (!pr.ok) {
            std::printf("| %d | Hopf point not found or not converged |\n", n);
            continue;
        }
        PeriodicOrbitOptions& o = pr.options;
        o.max_points = points;
        o.intervals = intervals;
        o.degree = degree;
        o.max_step = max_step;
        std::vector<double> walls, cpus;
        OrbitBranch b;
        for (int r = 0; r < repeats; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            const std::clock_t c0 = std::clock();
            b = orbit_branch_from_hopf(*pr.system, pr.hopf, o);
            walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            cpus.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
        }
        auto list = [](const std::vector<double>& v) {
            std::string s;
            for (double x : v) s += (s.empty() ? "" : ", ") + std::to_string(x);
            return s.empty() ? std::string("-") : s;
        };
        std::vector<double> folds, pds, tori;
        for (const auto& f : b.folds) folds.push_back(f.par);
        for (const auto& x : b.period_doublings) pds.push_back(x.par);
        for (const auto& x : b.tori) tori.push_back(x.par);
        std::printf("| %d | %d | %zu | %.2f | %.2f | %s | %s | %s | %.1e | %d |\n", n, pr.system->dimension(), b.points.size(), median(walls),
                    median(cpus), list(folds).c_str(), list(pds).c_str(), list(tori).c_str(), b.max_trivial_distance, b.newton_iterations);
        // a few values of the branch, to compare builds: the last orbit and the one in the middle
        for (std::size_t k : {b.points.size() / 2, b.points.size() - 1}) {
            if (k >= b.points.size()) continue;
            const PeriodicOrbit& p = b.points[k];
            std::printf("    orbit %zu: %s = %.10f, period %.10f, max |mu| nontrivial %.8f, |mu_trivial - 1| %.1e, %d Newton its\n", k,
                        o.parameter.c_str(), p.par, p.period, p.max_nontrivial, p.trivial_distance, p.iterations);
        }
        std::printf("    stop: %s; %s\n", b.stop.c_str(), b.message.c_str());
        for (const auto& x : b.period_doublings)
            std::printf("    period doubling: %s = %.10f, bracket %.1e, mu %.8f%+.8fi\n", o.parameter.c_str(), x.par, x.par_bracket, x.multiplier.real(),
                        x.multiplier.imag());
        for (const auto& x : b.tori)
            std::printf("    torus: %s = %.10f, bracket %.1e, mu %.8f%+.8fi\n", o.parameter.c_str(), x.par, x.par_bracket, x.multiplier.real(),
                        x.multiplier.imag());
        if (!csv.empty()) {
            std::FILE* f = std::fopen(csv.c_str(), "w");
            if (!f) {
                std::fprintf(stderr, "bench_orbits: cannot write %s\n", csv.c_str());
                return 5;
            }
            std::fprintf(f, "%s,period,nunst,max_nontrivial,trivial_distance\n", o.parameter.c_str());
            for (const PeriodicOrbit& p : b.points) {
                // the nontrivial multipliers outside the unit circle (the trivial one: nearest 1)
                std::size_t k1 = 0;
                for (std::size_t k = 1; k < p.multipliers.size(); ++k)
                    if (std::abs(p.multipliers[k] - 1.0) < std::abs(p.multipliers[k1] - 1.0)) k1 = k;
                int unstable = 0;
                for (std::size_t k = 0; k < p.multipliers.size(); ++k)
                    if (k != k1 && std::abs(p.multipliers[k]) > 1.0) ++unstable;
                std::fprintf(f, "%.12g,%.12g,%d,%.10g,%.3e\n", p.par, p.period, unstable, p.max_nontrivial, p.trivial_distance);
            }
            std::fclose(f);
        }
        std::fflush(stdout);
    }
}
