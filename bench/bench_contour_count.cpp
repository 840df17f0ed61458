// Feasibility measurement for counting and locating the roots of a `roots --system` file in a
// rectangle by contour integrals with sparse LUs (Beyn's method), BENCHMARKS.md "Large sparse
// systems", fourth attempt. Not a solver of the library: it measures how many evaluations of
// Delta(z)^{-1} V the quadrature needs and what one costs.
//   build/bench/bench_contour_count FILE.json C BETA R L [TOL]
// The rectangle [C, BETA] x [-R, R] (real problem: only the upper half is integrated, the lower
// half is its conjugate), L random real probe columns V (fixed seed), adaptive Gauss-Kronrod
// 7/15 panels on each edge until max |K15 - G7| <= TOL |panel| / |upper path| (default 1e-9).
//     A_p = (1 / 2 pi i) oint ((z - z_c) / rho)^p Delta(z)^{-1} V dz = Im(upper integral) / pi,
// rank of A_0 by its singular values (printed), and the eigenvalues of
// U^T A_1 W Sigma^{-1} (A_0 = U Sigma W^T truncated at 1e-7 sigma_1) mapped back, z_c + rho mu.
// Beyn's count is the number of linearly independent eigenvectors in the rectangle: a conjugate
// pair sharing a real eigenvector (the reaction-diffusion files) counts once.
#include <Eigen/Dense>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ddemap/io/system_json.hpp"
#include "ddemap/problem/linear_dde.hpp"

namespace {

using ddemap::cplx;
using MatC = Eigen::MatrixXcd;

struct Counter {
    const ddemap::LinearDDE& dde;
    MatC v;  // probe columns (real values)
    Eigen::UmfPackLU<Eigen::SparseMatrix<cplx>> lu;
    bool analysed = false;
    long evaluations = 0;
    double lu_seconds = 0.0, solve_seconds = 0.0;
    cplx zc;
    double rho = 1.0;

    Counter(const ddemap::LinearDDE& d, int l) : dde(d), v(d.dimension(), l) {
        std::mt19937_64 g(1);
        std::normal_distribution<double> normal;
        for (int j = 0; j < l; ++j)
            for (int i = 0; i < d.dimension(); ++i) v(i, j) = normal(g);
    }
    // [Delta^{-1} V, ((z - zc) / rho) Delta^{-1} V]
    MatC eval(cplx z) {
        const auto t0 = std::chrono::steady_clock::now();
        const Eigen::SparseMatrix<cplx> delta = dde.sparse_characteristic_matrix(z);
        if (!analysed) {
            lu.analyzePattern(delta);
            analysed = true;
        }
        lu.factorize(delta);
        const auto t1 = std::chrono::steady_clock::now();
        const MatC x = lu.solve(v);
        const auto t2 = std::chrono::steady_clock::now();
        lu_seconds += std::chrono::duration<double>(t1 - t0).count();
        solve_seconds += std::chrono::duration<double>(t2 - t1).count();
        ++evaluations;
        MatC out(x.rows(), 2 * x.cols());
        out.leftCols(x.cols()) = x;
        out.rightCols(x.cols()) = ((z - zc) / rho) * x;
        return out;
    }
};

// Gauss-Kronrod 7/15 nodes and weights on [-1, 1] (QUADPACK qk15)
const double xgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851, 0.864864423359769072789712788640926,
                       0.741531185599394439863864773280788, 0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                       0.207784955007898467600689403773245, 0.0};
const double wgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204, 0.104790010322250183839876322541518,
                       0.140653259715525918745189590510238, 0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                       0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
const double wg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780, 0.381830050505118944950369775488975,
                      0.417959183673469387755102040816327};

int panels = 0;

void integrate(Counter& c, cplx a, cplx b, double tol_per_length, MatC& sum, int depth) {
    const cplx mid = 0.5 * (a + b), h = 0.5 * (b - a);
    const MatC f0 = c.eval(mid);
    MatC k = wgk[7] * f0, g = wg[3] * f0;
    for (int j = 0; j < 7; ++j) {
        const MatC f = c.eval(mid - h * xgk[j]) + c.eval(mid + h * xgk[j]);
        k += wgk[j] * f;
        if (j % 2 == 1) g += wg[j / 2] * f;
    }
    ++panels;
    const double error = std::abs(h) * (k - g).cwiseAbs().maxCoeff();
    if (error <= tol_per_length * std::abs(b - a) || depth >= 40) {
        sum += h * k;
        return;
    }
    integrate(c, a, mid, tol_per_length, sum, depth + 1);
    integrate(c, mid, b, tol_per_length, sum, depth + 1);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 6) {
        std::fprintf(stderr, "usage: bench_contour_count FILE.json C BETA R L [TOL]\n");
        return 2;
    }
    std::ifstream in(argv[1]);
    std::stringstream text;
    text << in.rdbuf();
    const ddemap::LinearDDE dde = ddemap::read_linear_dde_json(text.str(), argv[1]).to_sparse();
    const double c0 = std::atof(argv[2]), beta = std::atof(argv[3]), height = std::atof(argv[4]);
    const int l = std::atoi(argv[5]);
    const double tol = argc > 6 ? std::atof(argv[6]) : 1e-9;
    if (!(c0 < beta) || !(height > 0.0) || l < 1 || !(tol > 0.0)) {
        std::fprintf(stderr, "bench_contour_count: expected C < BETA, R > 0, L >= 1, TOL > 0\n");
        return 2;
    }
    Counter c(dde, l);
    c.zc = cplx(0.5 * (c0 + beta), 0.0);
    c.rho = std::max(0.5 * (beta - c0), height);
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    MatC sum = MatC::Zero(dde.dimension(), 2 * l);
    const double per_length = tol / (2.0 * height + (beta - c0));
    integrate(c, cplx(beta, 0.0), cplx(beta, height), per_length, sum, 0);
    integrate(c, cplx(beta, height), cplx(c0, height), per_length, sum, 0);
    integrate(c, cplx(c0, height), cplx(c0, 0.0), per_length, sum, 0);
    const Eigen::MatrixXd moments = sum.imag() / M_PI;  // [A_0, A_1], real
    const Eigen::MatrixXd a0 = moments.leftCols(l), a1 = moments.rightCols(l);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(a0, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("n=%d evaluations=%ld panels=%d wall %.3f s cpu %.3f s (LU %.3f s, solves %.3f s)\n", dde.dimension(), c.evaluations, panels,
                wall, cpu, c.lu_seconds, c.solve_seconds);
    int rank = 0;
    while (rank < sv.size() && sv(rank) > 1e-7 * sv(0)) ++rank;
    for (int i = 0; i < sv.size(); ++i) std::printf("  singular value %d: %.3e\n", i, sv(i));
    std::printf("rank %d\n", rank);
    if (rank == 0) return 0;
    const Eigen::MatrixXd b = svd.matrixU().leftCols(rank).transpose() * a1 * svd.matrixV().leftCols(rank) *
                              sv.head(rank).cwiseInverse().asDiagonal();
    const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(b, false).eigenvalues();
    std::vector<cplx> roots;
    for (int i = 0; i < rank; ++i) roots.push_back(c.zc + c.rho * mu(i));
    std::sort(roots.begin(), roots.end(), [](cplx x, cplx y) { return x.real() > y.real(); });
    for (const cplx z : roots) std::printf("  %.15g %+.15g\n", z.real(), z.imag());
    return 0;
}
