#include "ddemap/study/atlas.hpp"

#include "study/internal/trackers.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>

#include "ddemap/analysis/stability/ring_fast.hpp"  // kModesMaxCars, kWindingMaxCars, resolve_ring_method
#include "ddemap/analysis/stability/string_stability.hpp"
#include "core/internal/text.hpp"

namespace ddemap {

Axis AtlasAxis::sweep_axis() const {
    if (!uniform || values.size() < 2) throw std::invalid_argument("axis '" + name + "': expected an axis given as lo, hi, count");
    Axis a;
    a.name = name;
    a.lo = lo;
    a.hi = hi;
    a.count = static_cast<int>(values.size());
    return a;
}

std::vector<long> AtlasSpec::shape() const {
    std::vector<long> s{static_cast<long>(rings.size())};
    for (const auto& a : axes) s.push_back(static_cast<long>(a.values.size()));
    return s;
}

long AtlasSpec::points() const {
    long n = 1;
    for (long k : shape()) n *= k;
    return n;
}

long AtlasSpec::chunk_size() const {
    if (chunk > 0) return chunk;
    return axes.empty() ? 1 : std::max<long>(1, static_cast<long>(axes.back().values.size()));
}

long AtlasSpec::chunks() const { return (points() + chunk_size() - 1) / chunk_size(); }

long AtlasSpec::chunk_end(long c) const { return std::min(points(), (c + 1) * chunk_size()); }

int AtlasSpec::ring_at(long index) const {
    long per_ring = 1;
    for (const auto& a : axes) per_ring *= static_cast<long>(a.values.size());
    return rings.at(static_cast<std::size_t>(index / per_ring));
}

ParameterMap AtlasSpec::parameters_at(long index) const {
    ParameterMap p = fixed;
    for (std::size_t k = axes.size(); k-- > 0;) {
        const long n = static_cast<long>(axes[k].values.size());
        p[axes[k].name] = axes[k].values[static_cast<std::size_t>(index % n)];
        index /= n;
    }
    return p;
}

std::string AtlasSpec::ring_method_used() const {
    if (axes.empty()) throw std::invalid_argument("an atlas has no axes: expected 2 to 5 swept parameters");
    return resolve_ring_method(ring_method, make_model(model, parameters_at(0))->linearise());
}

void AtlasSpec::validate() const {
    if (axes.size() < 2 || axes.size() > 5) {
        throw std::invalid_argument("an atlas has " + std::to_string(axes.size()) + " axes: expected 2 to 5 swept parameters");
    }
    std::set<std::string> names;
    for (const auto& a : axes) {
        if (!names.insert(a.name).second) throw std::invalid_argument("parameter '" + a.name + "' is swept twice: expected each axis once");
        if (fixed.count(a.name)) throw std::invalid_argument("parameter '" + a.name + "' is both swept and fixed");
        if (a.values.empty()) throw std::invalid_argument("axis '" + a.name + "' has no values");
        for (double v : a.values)
            if (!std::isfinite(v)) throw std::invalid_argument("axis '" + a.name + "': expected finite values");
        std::set<double> distinct(a.values.begin(), a.values.end());
        if (distinct.size() != a.values.size()) throw std::invalid_argument("axis '" + a.name + "': a value is repeated");
    }
    for (std::size_t k = axes.size() - 2; k < axes.size(); ++k)
        if (!axes[k].uniform || axes[k].values.size() < 2)
            throw std::invalid_argument("axis '" + axes[k].name + "': the last two axes (the plane of the figure) need lo, hi and count >= 2");
    if (rings.empty()) throw std::invalid_argument("rings: expected at least one ring size");
    std::set<int> ring_set;
    for (int n : rings) {
        if (n != 0 && n < 2) throw std::invalid_argument("ring of " + std::to_string(n) + " cars: expected N >= 2 or inf");
        if (!ring_set.insert(n).second) throw std::invalid_argument("rings: a ring size is repeated");
    }
    for (int n : rings)
        if (n > kWindingMaxCars)
            throw std::invalid_argument("ring of " + std::to_string(n) + " cars: expected at most " + std::to_string(kWindingMaxCars) + " cars");
    if (chunk < 0) throw std::invalid_argument("chunk = " + std::to_string(chunk) + ": expected a positive number of points");
    // every corner of the grid builds a model inside the computable range (as a sweep's window)
    const std::size_t corners = std::size_t(1) << axes.size();
    for (std::size_t mask = 0; mask < corners; ++mask) {
        ParameterMap p = fixed;
        std::string where;
        for (std::size_t k = 0; k < axes.size(); ++k) {
            const double v = (mask >> k) & 1 ? *std::max_element(axes[k].values.begin(), axes[k].values.end())
                                             : *std::min_element(axes[k].values.begin(), axes[k].values.end());
            p[axes[k].name] = v;
            where += (where.empty() ? "" : ", ") + axes[k].name + " = " + detail::format_number(v);
        }
        require_computable(make_model(model, p)->linearise(), "the corner " + where + " of the atlas");
    }
    // a known method that applies to the model; the per-mode path solves N/2 + 1 modes per point
    if (ring_method_used() == "modes")
        for (int n : rings)
            if (n > kModesMaxCars)
                throw std::invalid_argument("ring of " + std::to_string(n) + " cars: expected at most " + std::to_string(kModesMaxCars) +
                                            " cars on the per-mode ring path (ring_method = \"modes\"); the winding tables take up to " +
                                            std::to_string(kWindingMaxCars));
}

const std::vector<AtlasField>& atlas_fields() {
    static const std::vector<AtlasField> fields = {
        {"spectral_abscissa", 'f', "largest real part of the ring's characteristic roots, trivial zero excluded (1/s); N = inf: max(0, sup over wave numbers)"},
        {"unstable_roots", 'i', "ring roots with Re > 0, counted with multiplicity over all modes (-1 for N = inf)"},
        {"abscissa_mode", 'i', "Fourier mode m of the spectral abscissa (-1 for N = inf)"},
        {"sup_gamma", 'f', "sup over w > 0 of |Gamma(iw)|, the head-to-tail transfer function"},
        {"omega_peak", 'f', "frequency of sup |Gamma| (rad/s)"},
        {"lowfreq_margin", 'f', "low-frequency string stability margin (the decisive coefficient of |Gamma(iw)|^2 - 1)"},
        {"peak_gain", 'f', "highest local maximum of |Gamma(iw)| at w > 0 (0 if none)"},
        {"peak_omega", 'f', "its frequency (rad/s)"},
        {"plant_abscissa", 'f', "real part of the plant's rightmost root (1/s)"},
        {"plant_root_re", 'f', "the plant's rightmost root, real part (1/s)"},
        {"plant_root_im", 'f', "the plant's rightmost root, imaginary part >= 0 (rad/s)"},
        {"plant_stable", 'b', "plant verdict: every root of the single car's loop in Re < 0"},
        {"ring_stable", 'b', "ring verdict (certified, nothing on or right of the axis)"},
        {"string_stable", 'b', "string verdict: |Gamma(iw)| <= 1 for all w > 0"},
        {"certified", 'b', "the ring's certificate: every mode's rightmost root certified by the argument principle (ring method modes), or the abscissa and the counts by winding tables (ring method winding)"},
        {"region", 'i', "chart class: 0 plant unstable, 1 ring unstable, 2 string unstable, 3 string stable"},
    };
    return fields;
}

namespace {

void pack(const SweepPoint& p, double* out) {
    const int region = !p.plant_stable ? 0 : !p.ring_stable ? 1 : !p.string_stable ? 2 : 3;
    const double v[] = {p.spectral_abscissa, double(p.unstable_roots), double(p.abscissa_mode), p.sup_gamma, p.omega_peak,
                        p.lowfreq_margin, p.peak_gain, p.peak_omega, p.plant_abscissa, p.plant_root.real(), p.plant_root.imag(),
                        double(p.plant_stable), double(p.ring_stable), double(p.string_stable), double(p.certified), double(region)};
    static_assert(sizeof v / sizeof v[0] == 16, "one value per atlas field");
    for (std::size_t i = 0; i < 16; ++i) out[i] = v[i];
}

}  // namespace

SweepPoint atlas_point(const double* v) {
    SweepPoint p;
    p.spectral_abscissa = v[0];
    p.unstable_roots = static_cast<int>(v[1]);
    p.abscissa_mode = static_cast<int>(v[2]);
    p.sup_gamma = v[3];
    p.omega_peak = v[4];
    p.lowfreq_margin = v[5];
    p.peak_gain = v[6];
    p.peak_omega = v[7];
    p.plant_abscissa = v[8];
    p.plant_root = cplx(v[9], v[10]);
    p.plant_stable = v[11] != 0.0;
    p.ring_stable = v[12] != 0.0;
    p.string_stable = v[13] != 0.0;
    p.certified = v[14] != 0.0;
    return p;
}

std::vector<double> evaluate_atlas_chunk(const AtlasSpec& spec, long c) {
    if (c < 0 || c >= spec.chunks()) throw std::invalid_argument("chunk " + std::to_string(c) + " is outside the atlas");
    const std::size_t nf = atlas_fields().size();
    const long begin = spec.chunk_begin(c), end = spec.chunk_end(c);
    std::vector<double> out(static_cast<std::size_t>(end - begin) * nf);
    const bool winding = spec.ring_method_used() == "winding";
    std::optional<detail::RingTracker> ring;       // the per-mode path
    std::optional<detail::RingTracker> reference;  // the winding path's fallback where undecided
    std::optional<detail::PlantTracker> plant;
    RingWindingGuess guess;
    int cars = -1;
    long tables = 0;
    int winding_fallbacks = 0;
    for (long i = begin; i < end; ++i) {
        const int n = spec.ring_at(i);
        if (n != cars) {  // a fresh start: the first point of the chunk or a new ring size
            if (!winding) ring.emplace(n);
            reference.reset();
            guess = RingWindingGuess{};
            plant.emplace();
            cars = n;
        }
        const Linearisation lin = make_model(spec.model, spec.parameters_at(i))->linearise();
        // the range need not be largest at a corner (IDM): every point is checked
        if (!is_computable(lin)) require_computable(lin, "point " + std::to_string(i) + " of the atlas");
        SweepPoint p;
        int fallbacks = 0;
        if (winding) {
            const detail::RingSummary rs = detail::winding_ring_summary(lin, n, guess, reference, tables, winding_fallbacks);
            detail::fill_sweep_point(lin, rs, *plant, p, fallbacks);
        } else {
            detail::evaluate_sweep_point(lin, *ring, *plant, p, fallbacks);
        }
        pack(p, out.data() + static_cast<std::size_t>(i - begin) * nf);
    }
    return out;
}

unsigned long long fnv1a64(const void* data, std::size_t size, unsigned long long seed) {
    const auto* b = static_cast<const unsigned char*>(data);
    unsigned long long h = seed;
    for (std::size_t i = 0; i < size; ++i) {
        h ^= b[i];
        h *= 1099511628211ull;
    }
    return h;
}

}  // namespace ddemap
