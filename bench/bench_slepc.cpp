// The same `roots --system` problems solved by SLEPc's nonlinear eigensolver (BENCHMARKS.md
// "Large sparse systems"), for timing side by side with bench_sparse_system. Split form
//     T(lambda) = lambda I - A0 - sum_k A_k exp(-tau_k lambda)
// (NEPSetSplitOperator, functions lambda, 1, exp(-tau_k lambda)). Default solver NLEIGS in the
// region [re_min, re_max] x [-im_max, im_max] for the `nev` eigenvalues with real part nearest re_max,
// tolerance 1e-10; PETSc options (-nep_type ciss, -nep_tol ...) override.
//   build/bench/bench_slepc FILE.json --nev 6 --region RE_MIN,RE_MAX,IM_MAX [--repeat R] [PETSc options]
// Needs complex-scalar PETSc/SLEPc (Debian libslepc-complex-dev); built only when found.
#include <slepcnep.h>

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

#if !defined(PETSC_USE_COMPLEX)
#error "bench_slepc needs PETSc/SLEPc built with complex scalars (libslepc-complex-dev)"
#endif

namespace {

Mat to_petsc(const Eigen::SparseMatrix<double>& a, double scale) {
    const Eigen::SparseMatrix<double, Eigen::RowMajor> r = a;
    const PetscInt n = static_cast<PetscInt>(r.rows());
    std::vector<PetscInt> nnz(static_cast<std::size_t>(n));
    for (PetscInt i = 0; i < n; ++i) nnz[static_cast<std::size_t>(i)] = static_cast<PetscInt>(r.outerIndexPtr()[i + 1] - r.outerIndexPtr()[i]);
    Mat m;
    MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 0, nnz.data(), &m);
    for (PetscInt i = 0; i < n; ++i)
        for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(r, i); it; ++it) {
            const PetscScalar v = scale * it.value();
            const PetscInt c = static_cast<PetscInt>(it.col());
            MatSetValues(m, 1, &i, 1, &c, &v, ADD_VALUES);
        }
    MatAssemblyBegin(m, MAT_FINAL_ASSEMBLY);
    MatAssemblyEnd(m, MAT_FINAL_ASSEMBLY);
    return m;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: bench_slepc FILE.json --nev N --region RE_MIN,RE_MAX,IM_MAX [--repeat R] [PETSc options]\n");
        return 2;
    }
    int nev = 6, repeat = 1;
    double re_min = -1.0, re_max = 1.0, im_max = 5.0;
    for (int i = 2; i + 1 < argc; ++i) {
        const std::string f = argv[i];
        if (f == "--nev") nev = std::atoi(argv[i + 1]);
        else if (f == "--repeat") repeat = std::atoi(argv[i + 1]);
        else if (f == "--region") std::sscanf(argv[i + 1], "%lf,%lf,%lf", &re_min, &re_max, &im_max);
    }
    std::ifstream in(argv[1]);
    std::stringstream text;
    text << in.rdbuf();
    const ddemap::LinearDDE dde = ddemap::read_linear_dde_json(text.str(), argv[1]).to_sparse();
    // PETSc sees the program name and its own options only
    std::vector<char*> petsc_argv{argv[0]};
    for (int i = 2; i < argc; ++i) {
        const std::string f = argv[i];
        if (f == "--nev" || f == "--repeat" || f == "--region") ++i;
        else petsc_argv.push_back(argv[i]);
    }
    int petsc_argc = static_cast<int>(petsc_argv.size());
    petsc_argv.push_back(nullptr);
    char** pargv = petsc_argv.data();
    PetscCall(SlepcInitialize(&petsc_argc, &pargv, nullptr, nullptr));
    const int n = dde.dimension();
    Eigen::SparseMatrix<double> eye(n, n);
    eye.setIdentity();
    std::vector<Mat> mats{to_petsc(eye, 1.0), to_petsc(dde.sparse_a0(), -1.0)};
    std::vector<FN> fns(2);
    FNCreate(PETSC_COMM_SELF, &fns[0]);
    FNSetType(fns[0], FNRATIONAL);
    PetscScalar lin[2] = {1.0, 0.0};
    FNRationalSetNumerator(fns[0], 2, lin);
    FNCreate(PETSC_COMM_SELF, &fns[1]);
    FNSetType(fns[1], FNRATIONAL);
    PetscScalar one[1] = {1.0};
    FNRationalSetNumerator(fns[1], 1, one);
    for (const auto& t : dde.sparse_delayed()) {
        mats.push_back(to_petsc(t.matrix, -1.0));
        FN f;
        FNCreate(PETSC_COMM_SELF, &f);
        FNSetType(f, FNEXP);
        FNSetScale(f, -t.delay, 1.0);
        fns.push_back(f);
    }
    std::vector<double> times, cpu;
    for (int run = 0; run < repeat; ++run) {
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        NEP nep;
        NEPCreate(PETSC_COMM_SELF, &nep);
        NEPSetSplitOperator(nep, static_cast<PetscInt>(mats.size()), mats.data(), fns.data(), DIFFERENT_NONZERO_PATTERN);
        NEPSetType(nep, NEPNLEIGS);
        RG rg;
        NEPGetRG(nep, &rg);
        RGSetType(rg, RGINTERVAL);
        RGIntervalSetEndpoints(rg, re_min, re_max, -im_max, im_max);
        // NLEIGS selects by a target only: real parts nearest re_max, i.e. the rightmost in the region
        NEPSetTarget(nep, re_max);
        NEPSetWhichEigenpairs(nep, NEP_TARGET_REAL);
        NEPSetDimensions(nep, nev, PETSC_DEFAULT, PETSC_DEFAULT);
        NEPSetTolerances(nep, 1e-10, PETSC_DEFAULT);
        NEPSetFromOptions(nep);
        NEPSolve(nep);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const double cpu_seconds = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;  // CPU time of the process
        times.push_back(seconds);
        cpu.push_back(cpu_seconds);
        PetscInt nconv = 0, its = 0;
        NEPGetConverged(nep, &nconv);
        NEPGetIterationNumber(nep, &its);
        NEPType type;
        NEPGetType(nep, &type);
        std::printf("run %d: %.3f s (cpu %.3f s)  n=%d %s converged=%d iterations=%d\n", run, seconds, cpu_seconds, n, type, static_cast<int>(nconv),
                    static_cast<int>(its));
        if (run + 1 == repeat) {
            std::vector<PetscScalar> values;
            for (PetscInt i = 0; i < nconv; ++i) {
                PetscScalar l;
                NEPGetEigenpair(nep, i, &l, nullptr, nullptr, nullptr);
                values.push_back(l);
            }
            std::sort(values.begin(), values.end(), [](PetscScalar a, PetscScalar b) {
                return PetscRealPart(a) != PetscRealPart(b) ? PetscRealPart(a) > PetscRealPart(b) : PetscImaginaryPart(a) > PetscImaginaryPart(b);
            });
            for (PetscInt i = 0; i < nconv; ++i) {
                PetscReal err = 0.0;
                NEPComputeError(nep, i, NEP_ERROR_RELATIVE, &err);
                std::printf("%.15g %+.15g  relative error %.2e\n", static_cast<double>(PetscRealPart(values[static_cast<std::size_t>(i)])),
                            static_cast<double>(PetscImaginaryPart(values[static_cast<std::size_t>(i)])), static_cast<double>(err));
            }
        }
        NEPDestroy(&nep);
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu.begin(), cpu.end());
    std::printf("median %.3f s, cpu %.3f s (SLEPc, %d runs)\n", times[times.size() / 2], cpu[cpu.size() / 2], repeat);
    for (auto& m : mats) MatDestroy(&m);
    for (auto& f : fns) FNDestroy(&f);
    PetscCall(SlepcFinalize());
    return 0;
}
