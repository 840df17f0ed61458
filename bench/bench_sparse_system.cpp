// Times rightmost_roots on a `roots --system` file with the sparse path (BENCHMARKS.md
// "Large sparse systems"): the compact Krylov basis (default) or Spectra's full basis.
//   build/bench/bench_sparse_system FILE.json [--arnoldi compact|spectra] [--count C] [--repeat R] [--restarts K] [--basis B] [--nev E] [--verbose 1]
// Prints one line per run (seconds, degree, shifts, Arnoldi steps, factorisations, status) and the
// roots of the last run (full precision, for comparison with bench_slepc).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "ddemap/io/system_json.hpp"
#include "ddemap/solve/roots.hpp"

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: bench_sparse_system FILE.json [--arnoldi compact|spectra] [--count C] [--repeat R] [--restarts K] [--basis B] [--nev E] [--verbose 1]\n");
        return 2;
    }
    ddemap::RootOptions o;
    o.method = "shift_invert";
    int repeat = 1;
    bool verbose = false;
    for (int i = 2; i + 1 < argc; i += 2) {
        const std::string f = argv[i];
        if (f == "--arnoldi") o.shift_invert.arnoldi = argv[i + 1];
        else if (f == "--count") o.count = std::atoi(argv[i + 1]);
        else if (f == "--restarts") o.shift_invert.compact_restarts = std::atoi(argv[i + 1]);
        else if (f == "--basis") o.shift_invert.compact_max_steps = std::atoi(argv[i + 1]);
        else if (f == "--nev") o.shift_invert.eigenvalues_per_shift = std::atoi(argv[i + 1]);
        else if (f == "--verbose") verbose = std::atoi(argv[i + 1]) != 0;
        else if (f == "--repeat") repeat = std::atoi(argv[i + 1]);
        else {
            std::fprintf(stderr, "bench_sparse_system: unknown flag %s\n", f.c_str());
            return 2;
        }
    }
    std::ifstream in(argv[1]);
    std::stringstream text;
    text << in.rdbuf();
    const ddemap::LinearDDE dde = ddemap::read_linear_dde_json(text.str(), argv[1]);
    const auto start = std::chrono::steady_clock::now();
    if (verbose)  // one line per shift: seconds since the start, shifts done, Re sigma
        o.progress = [&](long done, long, double re) {
            std::printf("  %.2f s: shift %ld at Re %.6g\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), done, re);
            std::fflush(stdout);
        };
    std::vector<double> times, cpu;
    ddemap::RootResult r;
    for (int k = 0; k < repeat; ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        r = ddemap::rightmost_roots(dde, o);
        cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);  // CPU time of the process
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        std::printf("run %d: %.3f s (cpu %.3f s)  n=%d M=%d shifts=%d arnoldi_steps=%d restarts=%d factorizations=%d status=%s\n", k,
                    times.back(), cpu.back(), dde.dimension(), r.degree, r.shifts, r.arnoldi_steps, r.arnoldi_restarts, r.factorizations,
                    ddemap::to_string(r.status).c_str());
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu.begin(), cpu.end());
    std::printf("median %.3f s, cpu %.3f s (%s, %d runs)\n", times[times.size() / 2], cpu[cpu.size() / 2], o.shift_invert.arnoldi.c_str(), repeat);
    std::printf("trusted: %s\n", r.message.c_str());
    for (const auto& x : r.roots) std::printf("%.15g %+.15g  residual %.2e\n", x.value.real(), x.value.imag(), x.residual);
    return 0;
}
