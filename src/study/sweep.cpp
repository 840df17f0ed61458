#include "ddemap/study/sweep.hpp"
#include "ddemap/analysis/stability/peak_stability.hpp"

#include "study/internal/trackers.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "ddemap/solve/roots.hpp"
#include "ddemap/analysis/stability/ring_stability.hpp"
#include "ddemap/analysis/stability/ring_fast.hpp"  // kModesMaxCars, kWindingMaxCars
#include "ddemap/analysis/stability/ring_winding.hpp"
#include "ddemap/analysis/stability/string_stability.hpp"
#include "core/internal/text.hpp"

namespace ddemap {

namespace {

double certificate_gap(cplx z) { return 1e-10 * std::max(1.0, std::abs(z)); }

}  // namespace

Axis parse_axis(const std::string& name, const std::string& text) {
    Axis a;
    a.name = name;
    const auto c1 = text.find(':');
    const auto c2 = c1 == std::string::npos ? std::string::npos : text.find(':', c1 + 1);
    const std::string what = name + " = " + detail::quoted(text) + ": expected LO:HI:COUNT with finite LO < HI and an integer COUNT from 2 to 100000";
    if (c1 == std::string::npos || c2 == std::string::npos || text.find(':', c2 + 1) != std::string::npos) {
        throw std::invalid_argument(what);
    }
    auto number = [&](const std::string& t) {
        double v = 0.0;
        if (!detail::parse_finite(t, v)) throw std::invalid_argument(what);
        return v;
    };
    a.lo = number(text.substr(0, c1));
    a.hi = number(text.substr(c1 + 1, c2 - c1 - 1));
    const std::string cs = text.substr(c2 + 1);
    char* end = nullptr;
    const long n = std::strtol(cs.c_str(), &end, 10);
    if (cs.empty() || *end != '\0' || n < 2 || n > 100000 || !(a.lo < a.hi)) throw std::invalid_argument(what);
    a.count = static_cast<int>(n);
    return a;
}

namespace {

/// True when z is the rightmost zero of f (up to its conjugate twin for real f). Counts the zeros
/// right of a line a little left of z: exactly z (and its twin) means nothing else is further
/// right. Lines at a distance keep the argument tracking cheap; closer lines only when another
/// zero is near; the last resort is the line 1e-10 right of z.
///
/// With `wide` > 0 the first line lies wide * max(1, |z|) left of z: far from z the phase of f turns
/// slowly and the count needs fewer samples. Any line left of z certifies z when it counts exactly
/// z (and its twin); when it counts more (another zero lies between), `wide` is halved for the
/// caller's next point and the lines below decide (a `wide` of at most 1e-2 is not tried, only grown
/// by 1.25); when it certifies, `wide` grows back (at most kWideMax). The verdict is the same for any
/// `wide` whenever the usual lines decide; only the cost differs.
constexpr double kWideMax = 0.25;
bool is_rightmost(const QuasiPolynomial& f, cplx z, double* wide = nullptr) {
    const double scale = std::max(1.0, std::abs(z));
    const bool twin = f.is_real() && std::abs(z.imag()) > 1e-12 * scale;
    const int known = twin ? 2 : 1;
    if (wide && *wide > 1e-2) {
        const int left = f.zeros_right_of(z.real() - *wide * scale);
        if (left == known) {
            *wide = std::min(kWideMax, 1.5 * *wide);
            return true;
        }
        *wide *= 0.5;  // another zero between that line and z (or undecided): the lines below decide
    } else if (wide) {
        *wide *= 1.25;  // tried again from the point where it exceeds 1e-2
    }
    for (double delta : {1e-2, 1e-4, 1e-7}) {
        const int left = f.zeros_right_of(z.real() - delta * scale);
        if (left == known) return true;
        if (left >= 0 && left < known) return false;  // z itself is not a zero: inconsistent
        const int right = f.zeros_right_of(z.real() + delta * scale);
        if (right != 0) return false;  // something lies further right (or undecided)
    }
    return f.zeros_right_of(z.real() + certificate_gap(z)) == 0;
}

}  // namespace

/// Offsets (times max(1, |guess|)) of the two starts off the real axis tried after a real guess
/// (certified_rightmost): pairs born from two real zeros start with small imaginary parts.
constexpr double kOffAxisNear = 0.05, kOffAxisFar = 0.2;

namespace detail {

CertifiedRoot certified_rightmost(const QuasiPolynomial& f, const std::function<LinearDDE()>& dde,
                                  const std::optional<cplx>& guess, double* wide) {
    CertifiedRoot out;
    if (guess) {
        cplx z = *guess;
        if (f.newton(z)) {
            out.value = z;
            if (is_rightmost(f, z, wide)) {
                out.certified = true;
                return out;
            }
        }
        // A real guess of a real f keeps Newton on the real axis: where two real zeros have met and
        // left it as a complex pair (or the rightmost zero is now a pair next to a real one), start
        // off the axis. Any start is allowed: the certificate decides, as for the guess itself.
        if (f.is_real() && guess->imag() == 0.0) {
            const double scale = std::max(1.0, std::abs(*guess));
            for (double off : {kOffAxisNear, kOffAxisFar}) {
                cplx w(guess->real(), off * scale);
                if (f.newton(w) && is_rightmost(f, w)) {
                    out.value = w;
                    out.certified = true;
                    return out;
                }
            }
        }
    }
    out.fell_back = true;
    out.degree = 8;
    // a cheap low-degree collocation gives the guesses; the certificate decides
    const LinearDDE problem = dde();
    {
        std::vector<cplx> ev;
        collocation_eigenvalues(problem, 8, ev);
        std::sort(ev.begin(), ev.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
        bool have = false;
        cplx best;
        for (std::size_t i = 0; i < std::min<std::size_t>(ev.size(), 4); ++i) {
            cplx z = ev[i];
            if (f.newton(z) && (!have || z.real() > best.real())) {
                best = z;
                have = true;
            }
        }
        if (have && is_rightmost(f, best)) {
            out.value = best;
            out.certified = true;
            return out;
        }
    }
    RootOptions o;
    o.count = 1;
    const RootResult rr = rightmost_roots(problem, o);
    out.degree = std::max(out.degree, rr.degree);
    if (rr.roots.empty()) return out;
    cplx z = rr.roots.front().value;
    f.newton(z);
    out.value = z;
    out.certified = is_rightmost(f, z);
    return out;
}

RingTracker::RingTracker(int cars) : m_cars(cars) {
    if (cars != 0 && cars < 2) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected N >= 2 or inf");
    if (cars > 0) {
        for (int m = 0; 2 * m <= cars; ++m) m_thetas.push_back(2.0 * M_PI * m / cars);
    } else {
        const int g = 64;
        for (int k = 12; k >= 1; --k) m_thetas.push_back(M_PI * std::ldexp(1.0, -k) / g);
        for (int j = 1; j <= g; ++j) m_thetas.push_back(M_PI * j / g);
    }
    m_guess.assign(m_thetas.size(), std::nullopt);
}

void RingTracker::reset() { std::fill(m_guess.begin(), m_guess.end(), std::nullopt); }

RingSummary RingTracker::evaluate(const Linearisation& lin) {
    RingSummary s;
    const std::size_t n = m_thetas.size();
    std::vector<CertifiedRoot> roots(n);
    std::vector<QuasiPolynomial> fs;
    fs.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double theta = m_thetas[i];
        const bool mode0 = m_cars > 0 && i == 0;
        const cplx zeta = m_cars > 0 ? ring_zeta(static_cast<int>(i), m_cars) : std::polar(1.0, -theta);
        fs.push_back(mode0 ? ring_mode0_characteristic(lin) : ring_mode_characteristic(lin, zeta));
        roots[i] = certified_rightmost(
            fs.back(), [&] { return mode0 ? ring_mode0_dde(lin) : ring_mode_dde(lin, zeta); }, m_guess[i]);
        m_guess[i] = roots[i].value;
        s.fallbacks += roots[i].fell_back;
        s.degree = std::max(s.degree, roots[i].degree);
        s.certified = s.certified && roots[i].certified;
    }
    std::size_t best = 0;
    for (std::size_t i = 1; i < n; ++i)
        if (roots[i].value.real() > roots[best].value.real()) best = i;

    if (m_cars > 0) {
        s.spectral_abscissa = roots[best].value.real();
        s.abscissa_mode = static_cast<int>(best);
        s.abscissa_theta = m_thetas[best];
        s.abscissa_omega = std::abs(roots[best].value.imag());
        bool marginal = false;
        for (std::size_t i = 0; i < n; ++i) {
            const cplx z = roots[i].value;
            const double band = marginal_band(z);
            if (z.real() < -band) continue;
            if (z.real() <= band) marginal = true;
            const int weight = (i > 0 && 2 * static_cast<int>(i) != m_cars) ? 2 : 1;
            const int above = fs[i].zeros_right_of(band);
            if (above < 0) {
                s.certified = false;
                marginal = true;
                continue;
            }
            // roots on the axis matter only when nothing is unstable in this mode
            if (above == 0 && fs[i].zeros_right_of(-band) > 0) marginal = true;
            s.unstable_roots += weight * above;
        }
        s.stable = s.certified && s.unstable_roots == 0 && !marginal;
        return s;
    }

    // N = infinity: refine the best sample by golden section between its neighbours
    double lo = best > 0 ? m_thetas[best - 1] : 0.5 * m_thetas[best];
    double hi = best + 1 < n ? m_thetas[best + 1] : M_PI;
    double best_theta = m_thetas[best], best_value = roots[best].value.real();
    cplx seed = roots[best].value;
    auto alpha = [&](double theta) {
        const cplx zeta = std::polar(1.0, -theta);
        const QuasiPolynomial f = ring_mode_characteristic(lin, zeta);
        const CertifiedRoot c = certified_rightmost(f, [&] { return ring_mode_dde(lin, zeta); }, seed);
        s.fallbacks += c.fell_back;
        s.degree = std::max(s.degree, c.degree);
        s.certified = s.certified && c.certified;
        return c.value.real();
    };
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = alpha(x1), f2 = alpha(x2);
    for (int it = 0; it < 40 && hi - lo > 1e-9; ++it) {
        if (f1 < f2) {
            lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = alpha(x2);
        } else {
            hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = alpha(x1);
        }
    }
    if (std::max(f1, f2) > best_value) {
        best_value = std::max(f1, f2);
        best_theta = f1 > f2 ? x1 : x2;
    }
    const LowFrequency lf = low_frequency_expansion(lin);
    double margin = 0.0;
    switch (lf.decisive_order) {
        case 2: margin = lf.c2; break;
        case 4: margin = lf.c4; break;
        case 6: margin = lf.c6; break;
        case 8: margin = lf.c8; break;
        default: margin = 0.0;
    }
    const bool branch_stable = lf.decisive_order > 0 && lf.gamma_prime0 != 0.0 && lf.d0 != 0.0 && margin / lf.gamma_prime0 < 0.0;
    const bool grid_stable = best_value < 0.0;
    s.abscissa_mode = -1;
    s.unstable_roots = -1;
    s.spectral_abscissa = std::max(best_value, 0.0);
    s.abscissa_theta = best_value > 0.0 ? best_theta : 0.0;
    s.stable = s.certified && grid_stable && branch_stable;
    return s;
}

RootResult PlantTracker::evaluate(const Linearisation& lin, int& fallbacks) {
    const QuasiPolynomial f = plant_characteristic(lin);
    const CertifiedRoot c = certified_rightmost(f, [&] { return plant_dde(lin); }, m_guess, &m_wide);
    fallbacks += c.fell_back;
    m_guess = c.value;
    RootResult rr;
    if (!c.certified) {
        RootOptions o;
        o.count = 2;
        return rightmost_roots(plant_dde(lin), o);
    }
    // real coefficients: the conjugate is a root too
    cplx z = c.value;
    if (std::abs(z.imag()) <= 1e-14 * std::max(1.0, std::abs(z))) z = cplx(z.real(), 0.0);
    Root r;
    r.value = z.imag() < 0.0 ? std::conj(z) : z;
    r.residual = std::abs(f(r.value)) / (1.0 + std::norm(r.value));
    rr.roots.push_back(r);
    if (r.value.imag() > 0.0) {
        Root c2 = r;
        c2.value = std::conj(r.value);
        rr.roots.push_back(c2);
    }
    rr.status = Status::Converged;
    rr.message = "continued by Newton and certified by the argument principle";
    return rr;
}


RingSummary winding_ring_summary(const Linearisation& lin, int cars, RingWindingGuess& guess, std::optional<RingTracker>& reference,
                                 long& tables, int& winding_fallbacks) {
    RingSummary rs;
    const RingWindingResult w = analyse_ring_winding(lin, cars, {}, guess);
    tables += w.tables;
    if (w.status == Status::Converged && w.certified) {
        guess = w.next;
        rs.spectral_abscissa = w.spectral_abscissa;
        rs.abscissa_mode = w.abscissa_mode;
        rs.abscissa_theta = w.abscissa_theta;
        rs.abscissa_omega = std::abs(w.abscissa_root.imag());
        rs.unstable_roots = static_cast<int>(w.unstable_roots);
        rs.stable = w.verdict == Verdict::Stable;
        rs.certified = true;
    } else if (cars <= kWindingFallbackCars) {
        guess = RingWindingGuess{};
        if (!reference) reference.emplace(cars);
        rs = reference->evaluate(lin);
        ++winding_fallbacks;
    } else {
        guess = RingWindingGuess{};
        rs.certified = false;
        rs.stable = false;
        rs.spectral_abscissa = w.spectral_abscissa;
    }
    return rs;
}

RingSummary evaluate_sweep_point(const Linearisation& lin, RingTracker& ring, PlantTracker& plant, SweepPoint& p, int& fallbacks) {
    const RingSummary rs = ring.evaluate(lin);
    fill_sweep_point(lin, rs, plant, p, fallbacks);
    return rs;
}

void fill_sweep_point(const Linearisation& lin, const RingSummary& rs, PlantTracker& plant, SweepPoint& p, int& fallbacks,
                      StringGuess* string, bool peak) {
    StringOptions so;
    so.grid_points = 120;
    int fb = rs.fallbacks;
    RootResult plant_roots = plant.evaluate(lin, fb);
    std::optional<StringResult> continued;
    if (string) continued = analyse_string_continued(lin, plant_roots, *string);
    const StringResult sr = continued ? std::move(*continued) : analyse_string(lin, std::move(plant_roots), so);
    p.spectral_abscissa = rs.spectral_abscissa;
    p.unstable_roots = rs.unstable_roots;
    p.abscissa_mode = rs.abscissa_mode;
    p.abscissa_omega = rs.abscissa_omega;
    p.ring_stable = rs.stable;
    p.certified = rs.certified;
    p.sup_gamma = sr.sup_gamma;
    p.omega_peak = sr.omega_peak;
    p.lowfreq_margin = sr.lowfreq_margin;
    p.peak_gain = 0.0;
    p.peak_omega = 0.0;
    for (const auto& pk : sr.peaks) {
        if (pk.gain > p.peak_gain) {
            p.peak_gain = pk.gain;
            p.peak_omega = pk.omega;
        }
    }
    p.plant_root = sr.plant_roots.roots.empty() ? cplx(0.0) : sr.plant_roots.roots.front().value;
    p.plant_abscissa = sr.plant_abscissa;
    p.plant_stable = sr.plant_stable;
    p.string_stable = sr.string_stable;
    if (peak) {
        // ||h||_1 >= sup |Gamma(iw)|: only an L2-stable point can be peak stable
        p.has_peak = true;
        p.peak_stable = false;
        p.peak_norm = sr.plant_stable ? 0.0 : std::numeric_limits<double>::infinity();
        if (sr.string_stable) {
            const PeakResult pk = peak_string_stability(lin, sr.plant_abscissa);
            p.peak_norm = pk.finite ? pk.norm : std::numeric_limits<double>::infinity();
            p.peak_stable = pk.verdict == Verdict::Stable;
            if (pk.verdict == Verdict::Undecided) p.certified = false;
        }
    }
    if (string) {
        // the next point starts from this maximiser when it is the sup (the only case the shortcut covers)
        string->have = p.peak_gain >= 1.0 && p.peak_omega > 0.0;
        string->omega = p.peak_omega;
    }
    fallbacks += fb;
}

}  // namespace detail

void SweepSpec::validate() const {
    if (x.name == y.name) throw std::invalid_argument("the two swept parameters are both '" + x.name + "': expected two different parameters");
    if (x.count < 2 || y.count < 2) throw std::invalid_argument("a swept axis needs COUNT >= 2");
    if (cars != 0 && cars < 2) throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected N >= 2 or inf");
    for (const auto& a : {x, y}) {
        if (fixed.count(a.name)) throw std::invalid_argument("parameter '" + a.name + "' is both swept and fixed");
        if (!(std::isfinite(a.lo) && std::isfinite(a.hi) && a.lo < a.hi)) {
            throw std::invalid_argument(a.name + " range " + detail::format_number(a.lo) + ":" + detail::format_number(a.hi) + ": expected finite LO < HI");
        }
    }
    // the corners of the window inside the computable range (c grows with the gains, th and tau)
    for (double xv : {x.lo, x.hi})
        for (double yv : {y.lo, y.hi})
            require_computable(model_at(*this, xv, yv)->linearise(), "the corner " + x.name + " = " + detail::format_number(xv) + ", " +
                                                                        y.name + " = " + detail::format_number(yv) + " of the window");
    // every point's string verdict is the low-frequency condition and the peak of |Gamma|, which
    // need a law of the car ahead only: refuse others here, before any message about ring methods
    // or curves suggests an alternative that would fail on the same ground
    require_single_leader(model_at(*this, x.lo, y.lo)->linearise(), "a sweep's string verdict (the low-frequency string condition)");
    // a known method that applies to the model; the per-mode path solves N/2 + 1 modes per point
    if (sweep_ring_method(*this) == "modes" && cars > kModesMaxCars)
        throw std::invalid_argument("ring of " + std::to_string(cars) + " cars: expected at most " + std::to_string(kModesMaxCars) +
                                    " cars on the per-mode ring path (boundaries need every mode's root); the winding tables take up to " +
                                    std::to_string(kWindingMaxCars));
}

std::string sweep_ring_method(const SweepSpec& spec) {
    const std::string& m = spec.ring_method;
    if (m != "auto" && m != "winding" && m != "modes")
        throw std::invalid_argument("ring method " + detail::quoted(m) + ": expected auto, winding or modes");
    if (m == "modes") return m;
    const bool applies = ring_winding_applies(model_at(spec, spec.x.lo, spec.y.lo)->linearise());
    if (m == "winding" && !applies)
        throw std::invalid_argument("ring method winding: the model '" + spec.model +
                                    "' uses more than the car ahead; expected ring method modes or auto");
    return applies ? "winding" : "modes";
}

std::unique_ptr<CarModel> model_at(const SweepSpec& spec, double x, double y) {
    ParameterMap p = spec.fixed;
    p[spec.x.name] = x;
    p[spec.y.name] = y;
    return make_model(spec.model, p);
}

namespace {
/// "the point k1 = 0.5, k2 = 2 of the window" (for the message of a point outside the computable range).
std::string point_name(const SweepSpec& spec, double x, double y) {
    return "the point " + spec.x.name + " = " + detail::format_number(x) + ", " + spec.y.name + " = " + detail::format_number(y) +
           " of the window";
}
}  // namespace

SweepResult run_sweep(const SweepSpec& spec, const ExecutionPolicy& policy) {
    spec.validate();
    SweepResult result;
    result.spec = spec;
    const int nx = spec.x.count, ny = spec.y.count;
    result.ring_method = sweep_ring_method(spec);
    const bool winding = result.ring_method == "winding";
    result.points.resize(static_cast<std::size_t>(nx) * ny);
    result.modes = spec.cars > 0 && !winding ? spec.cars / 2 + 1 : 0;
    result.mode_roots.resize(result.points.size() * result.modes);
    const auto t0 = std::chrono::steady_clock::now();
    int fallbacks = 0, uncertified = 0, degree = 0;
    // The first column is continued sequentially (one collocation solve at its first point);
    // each row then starts from the roots of its first point. The path of every point is thus
    // fixed, whatever the number of threads.
    std::vector<detail::RingTracker> ring_seed;
    std::vector<detail::PlantTracker> plant_seed;
    std::vector<RingWindingGuess> winding_seed;
    long tables = 0;
    {
        detail::RingTracker ring(winding ? 2 : spec.cars);  // unused on the winding path
        detail::PlantTracker plant;
        RingWindingGuess guess;
        for (int iy = 0; iy < ny; ++iy) {
            const Linearisation lin = model_at(spec, spec.x.value(0), spec.y.value(iy))->linearise();
            if (!is_computable(lin)) require_computable(lin, point_name(spec, spec.x.value(0), spec.y.value(iy)));
            if (winding) {
                const RingWindingResult w = analyse_ring_winding(lin, spec.cars, {}, guess);
                tables += w.tables;
                guess = w.next;
            } else {
                const detail::RingSummary rs = ring.evaluate(lin);
                fallbacks += rs.fallbacks;
                degree = std::max(degree, rs.degree);
            }
            plant.evaluate(lin, fallbacks);
            ring_seed.push_back(ring);
            plant_seed.push_back(plant);
            winding_seed.push_back(guess);
        }
    }
    result.threads = thread_count(policy);
    // per-row counters, summed in row order after the loop
    std::vector<int> row_fallbacks(ny, 0), row_uncertified(ny, 0), row_degree(ny, 0), row_winding_fallbacks(ny, 0);
    std::vector<long> row_tables(ny, 0);
    parallel_for(ny, [&](long row) {
        const int iy = static_cast<int>(row);
        int& fallbacks = row_fallbacks[iy];
        int& uncertified = row_uncertified[iy];
        int& degree = row_degree[iy];
        RingWindingGuess guess = winding_seed[iy];
        std::optional<detail::RingTracker> reference;  // the per-mode path where a winding point is undecided
        detail::RingTracker ring = ring_seed[iy];
        detail::PlantTracker plant = plant_seed[iy];
        StringGuess string;  // continued along the row only: the same path for any number of threads
        for (int ix = 0; ix < nx; ++ix) {
            SweepPoint& p = result.points[static_cast<std::size_t>(iy) * nx + ix];
            p.x = spec.x.value(ix);
            p.y = spec.y.value(iy);
            const Linearisation lin = model_at(spec, p.x, p.y)->linearise();
            if (!is_computable(lin)) require_computable(lin, point_name(spec, p.x, p.y));
            const detail::RingSummary rs = winding ? detail::winding_ring_summary(lin, spec.cars, guess, reference, row_tables[iy],
                                                                                  row_winding_fallbacks[iy])
                                                   : ring.evaluate(lin);
            int fb = 0;
            detail::fill_sweep_point(lin, rs, plant, p, fb, &string, spec.peak);
            for (int m = 0; m < result.modes && !winding; ++m) {
                result.mode_roots[(static_cast<std::size_t>(iy) * nx + ix) * result.modes + m] = ring.roots()[m].value_or(cplx(0.0));
            }
            fallbacks += fb;
            degree = std::max(degree, rs.degree);
            uncertified += !p.certified;
        }
    }, policy);
    for (int iy = 0; iy < ny; ++iy) {
        fallbacks += row_fallbacks[iy];
        uncertified += row_uncertified[iy];
        degree = std::max(degree, row_degree[iy]);
        result.winding_fallbacks += row_winding_fallbacks[iy];
        tables += row_tables[iy];
    }
    result.winding_tables = tables;
    result.fallbacks = fallbacks;
    result.uncertified = uncertified;
    result.degree_max = degree;
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return result;
}

}  // namespace ddemap
