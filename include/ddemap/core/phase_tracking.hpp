#pragma once
/// \file phase_tracking.hpp
/// The one argument-principle tracker of ddemap: the continuous change of arg f along a path,
/// followed with bounded steps (header-only, so that problem/ can use it as well as solve/).
/// The number of zeros of an analytic f inside a closed contour C is (1 / 2 pi) times the
/// change of arg f around C; the change is the sum of the wrapped phase increments
/// arg(f(z_{j+1}) / f(z_j)) provided every step turns the phase by less than pi.
///
/// The tracker owns the step control; the caller's path owns the evaluation and the test of a
/// step. A path provides
///     double cap() const;                    // the largest step the rates at the current point allow
///     bool trial(double t, double& darg);    // evaluate at arclength t, darg = phase change from
///                                            // the current point; false rejects the step
///     void accept();                         // the trial point becomes the current one
///     bool failed() const;                   // give up now (a zero met exactly, a budget used up)
/// Accepted steps grow by 1.6 (up to cap()), rejected ones shrink by 0.35; a step below `tiny`
/// ends the tracking as failed (a zero on or within rounding of the path).
/// Two step strategies share that contract:
///   * follow_phase: adaptive steps along a path (RingDeterminant::arg_change, traffic/);
///   * bisect_phase: recursive bisection of a piece (QuasiPolynomial::zeros_right_of,
///     problem/, the sweep's hot path; expressed through follow_phase it evaluated f as often
///     but cost 3.6% more instructions in bench_sweep).

#include <algorithm>
#include <cmath>
#include <complex>

namespace ddemap {

/// Adds the change of arg along a path of arclength `length` to `total`; false when the step
/// underflowed below `tiny` or the path failed.
template <class Path>
bool follow_phase(Path& path, double length, double tiny, double& total) {
    double t = 0.0, h = path.cap();
    while (t < length) {
        h = std::min(h, length - t);
        const double tn = (length - t - h <= tiny) ? length : t + h;
        double darg = 0.0;
        if (path.trial(tn, darg)) {
            total += darg;
            path.accept();
            t = tn;
            h = std::min(1.6 * h, path.cap());
        } else {
            if (path.failed()) return false;
            h *= 0.35;
            if (h < tiny) return false;
        }
    }
    return true;
}

/// A sample of f on a path parametrised by t: the value and |f'/f|^2 (|f'/f| bounds the phase
/// speed |d/dt arg f| and is at least 1 / the distance to a nearby zero).
struct PhaseSample {
    double t = 0.0;
    std::complex<double> f;
    double speed2 = 0.0;
};

/// The acceptance test of bisect_phase for the piece from a to b with midpoint m: on each half
/// the phase turns by less than pi/4 between the samples and |f'/f| at the three samples times
/// the half length is below pi/8.
inline bool phase_piece_resolved(const PhaseSample& a, const PhaseSample& m, const PhaseSample& b) {
    const double h = 0.5 * (b.t - a.t);
    constexpr double kEighth = 0.39269908169872414;  // pi / 8
    const double limit = kEighth * kEighth / (h * h);
    // |arg(b / a)| < pi/4 without atan2: Re(b conj a) > |Im(b conj a)|
    auto within_quarter = [](std::complex<double> y, std::complex<double> x) {
        const std::complex<double> w = y * std::conj(x);
        return w.real() > std::abs(w.imag());
    };
    const bool slow = a.speed2 < limit && m.speed2 < limit && b.speed2 < limit;
    return slow && within_quarter(m.f, a.f) && within_quarter(b.f, m.f);
}

/// The continuous change of arg f from sample a to sample b by bisection: a piece is accepted
/// when, on each of its halves, the phase turns by less than pi/4 between the samples and
/// |f'/f| at the three samples times the half length is below pi/8; otherwise it is split. A
/// zero within the piece's reach lies within about half its length of some sample, where
/// |f'/f| >= 1/distance, so it forces subdivision until the pieces near it are shorter than its
/// distance to the path. The sampler provides `PhaseSample operator()(double t)`, `bool failed`
/// (set when a zero is met exactly) and `int budget` (samples left); the budget and depth 80
/// bound the work, setting `failed`.
template <class Sampler>
double bisect_phase(Sampler& sample, const PhaseSample& a, const PhaseSample& b, int depth = 0) {
    if (--sample.budget < 0 || depth > 80) {
        sample.failed = true;
        return 0.0;
    }
    const PhaseSample m = sample(0.5 * (a.t + b.t));
    if (sample.failed) return 0.0;
    if (phase_piece_resolved(a, m, b)) return std::arg(b.f * std::conj(a.f));
    return bisect_phase(sample, a, m, depth + 1) + bisect_phase(sample, m, b, depth + 1);
}

}  // namespace ddemap
