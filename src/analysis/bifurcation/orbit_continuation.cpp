#include "analysis/bifurcation/internal/orbit_continuation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "core/internal/text.hpp"

namespace ddemap::orbit_continuation {

namespace {

/// The nontrivial multipliers (the one nearest 1 removed).
std::vector<cplx> nontrivial(const PeriodicOrbit& o) {
    std::vector<cplx> v = o.multipliers;
    if (v.empty()) return v;
    std::size_t k1 = 0;
    for (std::size_t k = 1; k < v.size(); ++k)
        if (std::abs(v[k] - 1.0) < std::abs(v[k1] - 1.0)) k1 = k;
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(k1));
    return v;
}

constexpr double kRealTolerance = 1e-6;  // |Im mu| below this: a real multiplier
constexpr double kCrossingTolerance = 1e-9;  // | |mu| - 1 | at a located period doubling or torus
constexpr double kCrossingJump = 1e-3;  // | |mu| - 1 | still above this on a bracket of 1e-12 h: a jump, not a crossing
/// the most a crossing multiplier may move in one step of the branch (or away from its linear
/// prediction in the location): farther apart, two multipliers are not the same one followed
/// (e.g. a complex pair that met the real axis paired with a small one)
constexpr double kCrossingMove = 0.25;

/// The nontrivial multipliers of one kind: real negative (period doubling) or complex with
/// Im > 0 (torus; one of each conjugate pair).
std::vector<cplx> of_kind(const PeriodicOrbit& o, bool pd) {
    std::vector<cplx> v;
    for (cplx z : nontrivial(o)) {
        const bool real = std::abs(z.imag()) <= kRealTolerance;
        if (pd ? (real && z.real() < 0.0) : (!real && z.imag() > 0.0)) v.push_back(z);
    }
    return v;
}

/// The multipliers of one kind that cross the unit circle between two orbits a and b of a branch:
/// the multipliers of that kind of a and of b are paired greedily by increasing distance
/// |mu_a - mu_b| up to kCrossingMove (each used once: one that has no partner of its kind nearby,
/// such as one of a complex pair that meets the real axis, is left alone), and a pair crosses
/// when |mu| - 1 changes sign between a and b. Every crossing of a step is found, also when several multipliers cross in one
/// step, or one leaves the circle while another enters it; a change of the number of multipliers
/// outside the circle without a crossing (two multipliers colliding on the real axis) gives none.
std::vector<std::pair<cplx, cplx>> circle_crossings(const PeriodicOrbit& a, const PeriodicOrbit& b, bool pd) {
    const std::vector<cplx> ma = of_kind(a, pd), mb = of_kind(b, pd);
    struct Pair {
        double dist;
        std::size_t i, j;
    };
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < ma.size(); ++i)
        for (std::size_t j = 0; j < mb.size(); ++j) pairs.push_back({std::abs(ma[i] - mb[j]), i, j});
    std::sort(pairs.begin(), pairs.end(), [](const Pair& x, const Pair& y) { return x.dist < y.dist; });
    std::vector<bool> used_a(ma.size(), false), used_b(mb.size(), false);
    std::vector<std::pair<cplx, cplx>> out;
    for (const Pair& q : pairs) {
        if (q.dist > kCrossingMove) break;
        if (used_a[q.i] || used_b[q.j]) continue;
        used_a[q.i] = used_b[q.j] = true;
        if ((std::abs(ma[q.i]) < 1.0) != (std::abs(mb[q.j]) < 1.0)) out.push_back({ma[q.i], mb[q.j]});
    }
    return out;
}

/// |mu| - 1 of the multiplier of the kind nearest `predicted` (the crossing multiplier followed
/// along the branch) and that multiplier; NaN when the orbit has none of that kind.
double tracked_value(const PeriodicOrbit& o, bool pd, cplx predicted, cplx& mu) {
    double best = std::numeric_limits<double>::infinity(), value = std::numeric_limits<double>::quiet_NaN();
    for (cplx z : of_kind(o, pd)) {
        if (std::abs(z - predicted) < best) {
            best = std::abs(z - predicted);
            value = std::abs(z) - 1.0;
            mu = z;
        }
    }
    return value;
}

/// Locates one crossing multiplier (mu0 at `prev` = u, mu1 at `orbit` = v, at s = step.length)
/// by Illinois regula falsi in the arclength s along the tangent t on g(s) = |mu(s)| - 1, mu(s)
/// the multiplier of the kind nearest the linear interpolation of the bracket ends' ones; then
/// checks a small bracket: the orbit a little beyond the zero (2 |g| / |g'| and at least 1e-8 h
/// in s, widened tenfold up to 4 times) must have g of the other sign, and par_bracket is the
/// width in p of that bracket (else of the regula falsi's last one). A crossing whose g still
/// jumps by more than kCrossingJump over a bracket of 1e-12 h, or whose multiplier is found
/// farther than kCrossingMove from its prediction, is no crossing (dropped).
void locate_crossing(const Step& step, double s_lo, double s_hi, const PeriodicOrbit& prev, const PeriodicOrbit& orbit,
                     const std::pair<cplx, cplx>& crossing, bool pd, const std::function<bool(double, PeriodicOrbit&)>& orbit_at, OrbitBranch& b) {
    const int after = step.after;
    const double h = step.h;
    OrbitCrossing x;
    x.after = after;
    const double g0 = std::abs(crossing.first) - 1.0, g1 = std::abs(crossing.second) - 1.0;
    // the interpolation, kept when the location fails
    const double frac = std::clamp(g0 / (g0 - g1), 0.0, 1.0);
    x.par = prev.par + frac * (orbit.par - prev.par);
    x.period = prev.period + frac * (orbit.period - prev.period);
    x.multiplier = crossing.second;
    double slo = s_lo, shi = s_hi, glo = g0, ghi = g1, plo = prev.par, phi = orbit.par;
    double glo_true = g0, ghi_true = g1;  // without the Illinois halving
    cplx mlo = crossing.first, mhi = crossing.second;
    int side = 0;
    for (int it = 0; it < 40; ++it) {
        const double sm = slo - glo * (shi - slo) / (ghi - glo);
        PeriodicOrbit trial;
        if (!orbit_at(sm, trial)) break;
        cplx mu;
        const cplx predicted = mlo + (mhi - mlo) * ((sm - slo) / (shi - slo));
        const double gv = tracked_value(trial, pd, predicted, mu);
        if (!std::isfinite(gv)) break;
        if (std::abs(mu - predicted) > kCrossingMove) return;  // not one multiplier followed continuously: no crossing
        if ((gv < 0.0) == (glo < 0.0)) {
            slo = sm;
            glo = glo_true = gv;
            plo = trial.par;
            mlo = mu;
            if (side == -1) ghi *= 0.5;
            side = -1;
        } else {
            shi = sm;
            ghi = ghi_true = gv;
            phi = trial.par;
            mhi = mu;
            if (side == 1) glo *= 0.5;
            side = 1;
        }
        if (std::abs(shi - slo) <= 1e-12 * h && std::abs(gv) > kCrossingJump) return;  // g jumps: no crossing
        if (std::abs(gv) <= kCrossingTolerance || std::abs(shi - slo) <= 1e-12 * h) {
            x.located = true;
            x.par = trial.par;
            x.period = trial.period;
            x.multiplier = mu.imag() < 0.0 ? std::conj(mu) : mu;
            x.accuracy = std::abs(gv);
            x.par_bracket = std::abs(phi - plo);
            // a small bracket around the zero: an orbit just beyond it, on the other side
            const double slope = (ghi_true - glo_true) / (shi - slo);
            double delta = std::max(2.0 * std::abs(gv / slope), 1e-8 * h);
            const double dir = (gv < 0.0) == (slope > 0.0) ? 1.0 : -1.0;  // towards the zero
            for (int k = 0; k < 4 && std::isfinite(delta); ++k, delta *= 10.0) {
                const double s2 = sm + dir * delta;
                if (s2 <= std::min(slo, shi) || s2 >= std::max(slo, shi)) break;  // the regula falsi's bracket is the smaller one
                PeriodicOrbit beyond;
                if (!orbit_at(s2, beyond)) break;
                cplx m2;
                const double g2 = tracked_value(beyond, pd, mu, m2);
                if (std::isfinite(g2) && (g2 < 0.0) != (gv < 0.0)) {
                    x.par_bracket = std::abs(beyond.par - trial.par);
                    break;
                }
            }
            x.orbit = std::move(trial);
            break;
        }
    }
    if (!x.located && b.status == Status::Converged) {
        b.status = Status::MaxIterations;
        b.message = std::string("a ") + (pd ? "period doubling" : "torus bifurcation") + " was detected but not located";
    }
    (pd ? b.period_doublings : b.tori).push_back(std::move(x));
}

/// Counts that need no pairing: real nontrivial multipliers < -1 (a period doubling changes its
/// parity), nontrivial multipliers outside the unit circle.
struct Counts {
    int pd = 0, unstable = 0;
};
Counts counts(const PeriodicOrbit& o) {
    Counts c;
    for (cplx z : nontrivial(o)) {
        if (!(std::abs(z) > 1.0)) continue;
        ++c.unstable;
        if (std::abs(z.imag()) <= kRealTolerance && z.real() < 0.0) ++c.pd;
    }
    return c;
}

/// The period doublings and tori between the orbits a (at s = s0) and c (at s1) of one step:
/// the crossings paired by distance, located; where the counts show a change that the pairing
/// does not (the parity of the number of real multipliers < -1 changes and no real negative
/// multiplier was paired across -1; or the number of unstable multipliers changes with no
/// crossing and no fold in the step) the interval is halved (the orbit at its middle corrected,
/// up to depth 6) and each half searched again. Still unexplained: the branch is undecided.
void crossings_in(const Step& step, double s0, double s1, const PeriodicOrbit& a, const PeriodicOrbit& c, bool folded, int depth, const Probe& probe,
                  OrbitBranch& b) {
    const std::vector<std::pair<cplx, cplx>> pds = circle_crossings(a, c, true), tori = circle_crossings(a, c, false);
    const Counts ca = counts(a), cc = counts(c);
    const bool unexplained = ((ca.pd - cc.pd) % 2 != 0 && pds.empty()) || (ca.unstable != cc.unstable && pds.empty() && tori.empty() && !folded);
    if (unexplained) {
        PeriodicOrbit mid;
        const double sm = 0.5 * (s0 + s1);
        if (depth < 6 && probe.orbit_at(sm, mid) && !mid.multipliers.empty()) {
            crossings_in(step, s0, sm, a, mid, folded, depth + 1, probe, b);
            crossings_in(step, sm, s1, mid, c, folded, depth + 1, probe, b);
            return;
        }
        if (b.status == Status::Converged) {
            b.status = Status::NumericalIssue;
            b.message = "the number of unstable multipliers changes from " + std::to_string(ca.unstable) + " to " + std::to_string(cc.unstable) +
                        " between the orbits at " + detail::format_number(a.par) + " and " + detail::format_number(c.par) + " but no special point was found there";
        }
    }
    for (const auto& x : pds) locate_crossing(step, s0, s1, a, c, x, true, probe.orbit_at, b);
    for (const auto& x : tori) locate_crossing(step, s0, s1, a, c, x, false, probe.orbit_at, b);
}

/// The fold of a step (see special_points): Illinois regula falsi in s on the parameter component
/// g of the unit tangent, from the bracket (0, t_par), (length, tn_par); every trial orbit corrected.
bool locate_fold(const Step& step, const Probe& probe) {
    double slo = 0.0, shi = step.length, glo = step.t_par, ghi = step.tn_par;
    int side = 0;
    for (int it = 0; it < 40; ++it) {
        const double s = slo - glo * (shi - slo) / (ghi - glo);
        double gv = 0.0;
        if (!probe.fold_trial(s, gv)) break;
        if (std::abs(gv) <= 1e-11 * step.par_scale || std::abs(shi - slo) <= 1e-12 * step.h) return true;
        if ((gv < 0.0) == (glo < 0.0)) {
            slo = s;
            glo = gv;
            if (side == -1) ghi *= 0.5;
            side = -1;
        } else {
            shi = s;
            ghi = gv;
            if (side == 1) glo *= 0.5;
            side = 1;
        }
    }
    return false;
}

}  // namespace

void check_accuracy(PeriodicOrbit& o) {
    if (!(o.trivial_distance > orbit_accuracy_limit)) return;
    o.stable = false;
    o.undecided = "|mu_trivial - 1| = " + detail::format_number(o.trivial_distance) + " > " + detail::format_number(orbit_accuracy_limit) +
                  ": the orbit failed its accuracy check";
}

bool special_points(const Step& step, const PeriodicOrbit& prev, const PeriodicOrbit& next, bool multipliers, const std::string& what,
                    const Probe& probe, OrbitBranch& b) {
    // an orbit that failed its accuracy check gives no special points (and the branch is undecided)
    if (!prev.undecided.empty() || !next.undecided.empty()) {
        if (b.status == Status::Converged) {
            b.status = Status::NumericalIssue;
            b.message = "the orbit at " + detail::format_number((prev.undecided.empty() ? next : prev).par) + " has no stability verdict (" +
                        (prev.undecided.empty() ? next : prev).undecided + "): no special points there";
        }
        return false;
    }
    bool folded = false;
    // fold: the parameter component of the tangent changes sign
    if (step.t_par * step.tn_par < 0.0) {
        OrbitFold f;
        f.after = step.after;
        f.located = locate_fold(step, probe);
        f.orbit = probe.fold_orbit();
        f.par = f.orbit.par;
        f.period = f.orbit.period;
        if (!f.located && b.status == Status::Converged) {
            b.status = Status::MaxIterations;
            b.message = "a fold of " + what + " was detected but not located";
        }
        b.folds.push_back(f);
        folded = true;
    }
    // period doubling and torus: the multipliers that cross the unit circle in this step
    if (multipliers && !prev.multipliers.empty() && !next.multipliers.empty()) {
        crossings_in(step, 0.0, step.length, prev, next, folded, 0, probe, b);
    }
    return folded;
}

}  // namespace ddemap::orbit_continuation
