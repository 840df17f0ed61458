#pragma once
// Illinois regula falsi along the chord of a continuation step (Hopf curves, fold curves): the
// zero of a test function between two points of a curve, every trial corrected onto the curve.

#include <Eigen/Core>

#include "ddemap/core/newton.hpp"
#include "ddemap/core/status.hpp"
#include "ddemap/solve/continuation.hpp"

namespace ddemap::detail {

/// Illinois regula falsi on a test function g along the chord from ua to ub, g(ua) = fa and
/// g(ub) = fb of opposite signs, every trial corrected onto the curve. g(u, value) returns false
/// where it is not defined (the search stops there); done(u, value) says when a trial is the zero.
struct ChordZero {
    Eigen::VectorXd u;
    Status status = Status::MaxIterations;
};
/// The same with the corrector given: correct(u, dir, b) moves u onto the curve within the
/// hyperplane dir . u = b and returns its status (hopf.cpp's minimum-norm steps where the curve
/// system is singular at the point sought).
template <class Correct, class G, class Done>
ChordZero chord_zero_with(const Eigen::VectorXd& ua, const Eigen::VectorXd& ub, double fa, double fb, Correct correct_onto, G g, Done done) {
    ChordZero z;
    z.u = ua;
    const Eigen::VectorXd d = ub - ua;
    const Eigen::VectorXd dir = d / d.norm();
    double slo = 0.0, shi = 1.0, flo = fa, fhi = fb;
    int last = 0;
    for (int it = 0; it < 80; ++it) {
        const double sm = (slo * fhi - shi * flo) / (fhi - flo);
        const Eigen::VectorXd v = ua + sm * d;
        Eigen::VectorXd u = v;
        const Status cs = correct_onto(u, dir, dir.dot(v));
        if (!converged(cs)) {
            z.status = cs;
            break;
        }
        double value = 0.0;
        if (!g(u, value)) {
            z.status = Status::NumericalIssue;
            break;
        }
        z.u = u;
        // to rounding: the test function at the rounding level of its terms, or the chord interval at rounding
        if (done(u, value) || shi - slo <= 1e-14) {
            z.status = Status::Converged;
            break;
        }
        if ((value < 0.0) == (flo < 0.0)) {
            slo = sm, flo = value;
            if (last == -1) fhi *= 0.5;
            last = -1;
        } else {
            shi = sm, fhi = value;
            if (last == 1) flo *= 0.5;
            last = 1;
        }
    }
    return z;
}

template <class G, class Done>
ChordZero chord_zero(const ContinuationProblem& pr, const Eigen::VectorXd& ua, const Eigen::VectorXd& ub, double fa, double fb,
                     const NewtonOptions& newton, G g, Done done) {
    return chord_zero_with(
        ua, ub, fa, fb, [&](Eigen::VectorXd& u, const Eigen::VectorXd& dir, double b) { return correct(pr, u, dir, b, newton).status; }, g, done);
}

}  // namespace ddemap::detail
