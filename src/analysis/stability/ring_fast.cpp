// The ring of identical cars for roots and string: winding verdict, listed roots (ring_fast.hpp).
#include "ddemap/analysis/stability/ring_fast.hpp"

#include <algorithm>
#include <climits>
#include <cmath>

#include <stdexcept>
#include "ddemap/problem/root_bounds.hpp"
#include "ddemap/traffic/ring.hpp"

namespace ddemap {

std::string resolve_ring_method(const std::string& given, const Linearisation& lin) {
    if (given != "auto" && given != "winding" && given != "modes")
        throw std::invalid_argument("ring method '" + given + "': expected auto, winding or modes");
    if (given == "modes") return given;
    const bool applies = ring_winding_applies(lin);
    if (given == "winding" && !applies)
        throw std::invalid_argument("ring method 'winding': this car law reacts to more than the car ahead; expected auto or modes");
    return applies ? "winding" : "modes";
}

namespace {

constexpr double kTwoPi = 6.283185307179586;

/// Newton on mode m from z (or its conjugate, whichever is nearer a zero); false when it fails.
bool mode_root(const Linearisation& lin, int cars, long long m, cplx z, RingRoot& out) {
    const cplx zeta = ring_zeta(static_cast<int>(m), cars);
    const QuasiPolynomial f = m == 0 ? ring_mode0_characteristic(lin) : ring_mode_characteristic(lin, zeta);
    if (std::abs(f(std::conj(z))) < std::abs(f(z))) z = std::conj(z);
    if (!f.newton(z) || !std::isfinite(z.real()) || !std::isfinite(z.imag())) return false;
    const LinearDDE dde = m == 0 ? ring_mode0_dde(lin) : ring_mode_dde(lin, zeta);
    out.root.value = z;
    out.root.eigenvalue = z;
    out.root.residual = relative_residual(dde, z);
    out.root.newton_step = 0.0;
    out.mode = static_cast<int>(m);
    out.theta = kTwoPi * static_cast<double>(m) / cars;
    return true;
}

/// The roots of the abscissa mode and of up to `count` neighbouring modes on each side (m <= N/2),
/// each by Newton from its neighbour's root; the `count` rightmost of them, rightmost first.
std::vector<RingRoot> neighbour_roots(const Linearisation& lin, int cars, const RingWindingResult& w, int count) {
    std::vector<RingRoot> found;
    const long long m0 = w.abscissa_mode, half = cars / 2;
    RingRoot first;
    if (!mode_root(lin, cars, m0, w.abscissa_root, first)) return found;
    found.push_back(first);
    for (const int step : {-1, 1}) {
        cplx z = first.root.value;
        for (long long m = m0 + step, k = 0; k < count && m >= 1 && m <= half; m += step, ++k) {
            RingRoot r;
            if (!mode_root(lin, cars, m, z, r)) break;
            found.push_back(r);
            z = r.root.value;
        }
    }
    // mode N - m holds the conjugates of mode m's roots (m = 0 and m = N/2 are real: their own)
    const std::size_t solved = found.size();
    for (std::size_t i = 0; i < solved; ++i) {
        const RingRoot& x = found[i];
        if (x.mode == 0 || 2LL * x.mode == cars) continue;
        RingRoot c = x;
        c.root.value = std::conj(x.root.value);
        c.root.eigenvalue = c.root.value;
        c.mode = static_cast<int>(cars - static_cast<long long>(x.mode));
        c.theta = kTwoPi * static_cast<double>(c.mode) / cars;
        found.push_back(c);
    }
    // rightmost first, ties: larger imaginary part first (as rightmost_roots orders them)
    std::sort(found.begin(), found.end(), [](const RingRoot& a, const RingRoot& b) {
        if (a.root.value.real() != b.root.value.real()) return a.root.value.real() > b.root.value.real();
        if (a.root.value.imag() != b.root.value.imag()) return a.root.value.imag() > b.root.value.imag();
        return a.mode < b.mode;
    });
    if (static_cast<int>(found.size()) > count) found.resize(static_cast<std::size_t>(count));
    return found;
}

}  // namespace

FastRing analyse_ring_fast(const Linearisation& lin, int cars, const std::string& method, int count, const Progress& progress,
                           const BranchProgress& search, const std::function<void(long, const RootWorkEstimate&)>& before) {
    FastRing f;
    RingOptions opt;
    opt.progress = progress;
    opt.before = before;
    if (cars == 0) opt.roots.progress = search;  // N finite: every mode's search would call it
    if (count > 0) opt.roots.count = count;
    if (method == "modes") {
        f.ring = analyse_ring(lin, cars, opt);
        f.method_used = "modes";
        f.listed_by = count > 0 ? "modes" : "none";
        return f;
    }
    f.winding = analyse_ring_winding(lin, cars);
    f.winding_ran = true;
    const RingWindingResult& w = f.winding;
    const bool small = cars == 0 || cars <= kWindingFallbackCars;
    if (!(w.status == Status::Converged && w.certified)) {
        if (small) {  // today's path decides
            f.ring = analyse_ring(lin, cars, opt);
            f.method_used = "modes";
            f.listed_by = count > 0 ? "modes" : "none";
            f.fell_back = true;
            return f;
        }
        f.method_used = "winding";
        f.listed_by = "none";
        f.ring.cars = cars;
        f.ring.verdict = Verdict::Undecided;
        f.ring.status = w.status == Status::Converged ? Status::NumericalIssue : w.status;
        f.ring.reason = "the winding pass did not certify the ring (" + w.message + ") and the ring is too long (N > " +
                        std::to_string(kWindingFallbackCars) + ") for the per-mode path to decide it here (--ring-method modes decides rings of at most " +
                        std::to_string(kModesMaxCars) + " cars mode by mode, about 0.3 ms per mode)";
        f.ring.unstable_roots = -1;
        return f;
    }
    RingResult& r = f.ring;
    f.method_used = "winding";
    if (count > 0 && small) {
        r = analyse_ring(lin, cars, opt);  // the listed roots, mode by mode
        f.listed_by = "modes";
    } else if (count > 0) {
        r.roots = neighbour_roots(lin, cars, w, count);
        f.listed_by = "newton";
    } else {
        f.listed_by = "none";
    }
    const Status listing = r.status;
    const std::string listing_reason = r.reason;
    r.cars = cars;
    r.verdict = w.verdict;
    r.stable = w.verdict == Verdict::Stable;
    r.spectral_abscissa = w.spectral_abscissa;
    r.abscissa_is_limit = w.abscissa_is_limit;
    r.abscissa_mode = w.abscissa_mode;
    r.abscissa_theta = w.abscissa_theta;
    // a count beyond int (over 2^31 unstable roots) is reported only in the winding object
    r.unstable_roots = w.unstable_roots <= INT_MAX ? static_cast<int>(w.unstable_roots) : -1;
    r.marginal_roots = w.marginal_roots <= INT_MAX ? static_cast<int>(w.marginal_roots) : -1;
    r.trivial_branch_stable = cars == 0 && w.verdict != Verdict::Unstable;
    // the listed rightmost root is the winding abscissa's root when within its certificate gap
    // 1e-10 max(1, |z|): the abscissa is then reported as that root's real part and mode, so the
    // table's first root and the abscissa are the same number (but never with the sign the
    // verdict contradicts: an unstable ring keeps a positive abscissa, a stable one a negative)
    if (!r.roots.empty() && !w.abscissa_is_limit) {
        const RingRoot& top = r.roots.front();
        const double re = top.root.value.real();
        const bool sign_ok = (w.verdict != Verdict::Unstable || re > 0.0) && (w.verdict != Verdict::Stable || re < 0.0);
        if (sign_ok && std::abs(re - w.spectral_abscissa) <= 1e-10 * std::max(1.0, std::abs(top.root.value))) {
            r.spectral_abscissa = top.root.value.real();
            if (cars > 0) r.abscissa_mode = top.mode;
            r.abscissa_theta = top.theta;
        }
    }
    r.status = listing;
    r.reason = "verdict, counts and abscissa from " + std::to_string(w.tables) + " certified winding passes (" +
               std::to_string(w.evaluations) + " evaluations); " +
               (f.listed_by == "modes"     ? "listed roots mode by mode: " + listing_reason
                : f.listed_by == "newton" ? std::string("listed roots by Newton on the abscissa mode and its neighbouring modes "
                                                         "(not certified to be the rightmost of all modes)")
                                           : std::string("no roots listed"));
    if (f.listed_by == "newton" && r.roots.empty()) {
        r.status = Status::NumericalIssue;
        r.reason += "; Newton on the abscissa mode failed";
    }
    return f;
}

}  // namespace ddemap
