#pragma once
// Tall complex matrix-vector kernels for the Krylov bases of the sparse path (shift_invert.cpp):
// the products with an n x r basis Q (n up to 10^5, r up to a few hundred) that dominate a
// compact Arnoldi step once the sparse solves are cheap.
//
// Eigen's column-major complex gemv (w -= Q p) ran at half the speed of its adjoint product
// (Q^H w) here, and classical Gram-Schmidt twice reads Q four times. These kernels work on row
// blocks of Q small enough to stay in the L2 cache: w -= Q p is an unrolled axpy over four
// columns at a time, and CGS2 fuses its middle two passes (w -= Q p, then Q^H w: each block of w is
// final once its rows are updated), so Q is read from memory three times instead of four.
// Sequential and in a fixed order: the results do not depend on the number of threads.

#include <algorithm>
#include <complex>

#include <Eigen/Dense>

namespace ddemap::detail {

using GsMatrix = Eigen::Ref<const Eigen::MatrixXcd>;

/// Rows per block: 256 rows of 200 complex columns are 800 KiB.
inline constexpr Eigen::Index kGsRows = 256;

/// w[i0:i0+b] += Q[i0:i0+b, :] p (column-major Q with leading dimension ld), four columns at a time.
inline void add_times_rows(const std::complex<double>* q, Eigen::Index ld, Eigen::Index i0, Eigen::Index b,
                           Eigen::Index r, const std::complex<double>* p, std::complex<double>* w) {
    double* wd = reinterpret_cast<double*>(w + i0);
    Eigen::Index j = 0;
    for (; j + 4 <= r; j += 4) {
        const double* q0 = reinterpret_cast<const double*>(q + j * ld + i0);
        const double* q1 = reinterpret_cast<const double*>(q + (j + 1) * ld + i0);
        const double* q2 = reinterpret_cast<const double*>(q + (j + 2) * ld + i0);
        const double* q3 = reinterpret_cast<const double*>(q + (j + 3) * ld + i0);
        const double a0 = p[j].real(), b0 = p[j].imag(), a1 = p[j + 1].real(), b1 = p[j + 1].imag();
        const double a2 = p[j + 2].real(), b2 = p[j + 2].imag(), a3 = p[j + 3].real(), b3 = p[j + 3].imag();
        for (Eigen::Index i = 0; i < b; ++i) {
            double re = wd[2 * i], im = wd[2 * i + 1];
            re += q0[2 * i] * a0 - q0[2 * i + 1] * b0;
            im += q0[2 * i] * b0 + q0[2 * i + 1] * a0;
            re += q1[2 * i] * a1 - q1[2 * i + 1] * b1;
            im += q1[2 * i] * b1 + q1[2 * i + 1] * a1;
            re += q2[2 * i] * a2 - q2[2 * i + 1] * b2;
            im += q2[2 * i] * b2 + q2[2 * i + 1] * a2;
            re += q3[2 * i] * a3 - q3[2 * i + 1] * b3;
            im += q3[2 * i] * b3 + q3[2 * i + 1] * a3;
            wd[2 * i] = re;
            wd[2 * i + 1] = im;
        }
    }
    for (; j < r; ++j) {
        const double* q0 = reinterpret_cast<const double*>(q + j * ld + i0);
        const double a0 = p[j].real(), b0 = p[j].imag();
        for (Eigen::Index i = 0; i < b; ++i) {
            wd[2 * i] += q0[2 * i] * a0 - q0[2 * i + 1] * b0;
            wd[2 * i + 1] += q0[2 * i] * b0 + q0[2 * i + 1] * a0;
        }
    }
}

/// w += Q p.
inline void add_times(const GsMatrix& q, const Eigen::Ref<const Eigen::VectorXcd>& p, Eigen::Ref<Eigen::VectorXcd> w) {
    const Eigen::Index n = q.rows();
    for (Eigen::Index i0 = 0; i0 < n; i0 += kGsRows)
        add_times_rows(q.data(), q.outerStride(), i0, std::min(kGsRows, n - i0), q.cols(), p.data(), w.data());
}

/// Y = Q X (X: r x c, c small), one pass over Q: every block of Q is used for all c columns.
inline Eigen::MatrixXcd times_columns(const GsMatrix& q, const Eigen::MatrixXcd& x) {
    const Eigen::Index n = q.rows();
    Eigen::MatrixXcd y = Eigen::MatrixXcd::Zero(n, x.cols());
    for (Eigen::Index i0 = 0; i0 < n; i0 += kGsRows)
        for (Eigen::Index c = 0; c < x.cols(); ++c)
            add_times_rows(q.data(), q.outerStride(), i0, std::min(kGsRows, n - i0), q.cols(), x.col(c).data(), y.col(c).data());
    return y;
}

/// Classical Gram-Schmidt twice against the orthonormal columns of Q: w <- (I - Q Q^H)^2 w,
/// returning h = h1 + h2 (h1 = Q^H w, h2 = Q^H (w - Q h1)), so that w_in = Q h + w_out.
/// The second and third reads of Q are one pass: w -= Q h1 and h2 += Q_b^H w_b block by block.
inline Eigen::VectorXcd orthogonalise_twice(const GsMatrix& q, Eigen::Ref<Eigen::VectorXcd> w) {
    const Eigen::Index n = q.rows(), r = q.cols();
    Eigen::VectorXcd h = q.adjoint() * w;
    if (r == 0) return h;
    const Eigen::VectorXcd minus_h = -h;
    Eigen::VectorXcd h2 = Eigen::VectorXcd::Zero(r);
    for (Eigen::Index i0 = 0; i0 < n; i0 += kGsRows) {
        const Eigen::Index b = std::min(kGsRows, n - i0);
        add_times_rows(q.data(), q.outerStride(), i0, b, r, minus_h.data(), w.data());
        h2.noalias() += q.middleRows(i0, b).adjoint() * w.segment(i0, b);
    }
    const Eigen::VectorXcd minus_h2 = -h2;
    add_times(q, minus_h2, w);
    return h + h2;
}

}  // namespace ddemap::detail
