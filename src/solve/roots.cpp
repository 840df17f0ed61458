#include "ddemap/solve/roots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "internal/backends.hpp"

namespace ddemap {


namespace {

/// THE registry: every backend of rightmost_roots, in one place.
const detail::RootBackend kBackends[] = {
    {"dense", detail::dense_why_not, detail::dense_roots, detail::dense_estimate},
    {"shift_invert", detail::shift_invert_why_not, detail::shift_invert_roots, detail::shift_invert_estimate},
    {"contour", detail::contour_why_not, detail::contour_roots, detail::contour_estimate},
};

const detail::RootBackend* find_backend(const std::string& name) {
    for (const auto& b : kBackends)
        if (name == b.name) return &b;
    return nullptr;
}

}  // namespace

int degree_for_radius(double radius, double tau) {
    const double m = 0.7 * radius * tau + 15.0;
    return m > 1e6 ? 1000000 : static_cast<int>(std::ceil(m));
}

double radius_for_degree(int degree, double tau) { return std::max(0.0, (degree - 15.0) / (0.7 * tau)); }

bool rightmost_first(const Root& a, const Root& b) {
    if (a.value.real() != b.value.real()) return a.value.real() > b.value.real();
    return a.value.imag() > b.value.imag();
}

std::vector<Root> cut_rightmost(const std::vector<Root>& all, int count) {
    std::vector<Root> out(all.begin(), all.begin() + std::min<std::size_t>(all.size(), count));
    if (!out.empty() && out.size() < all.size()) {
        const Root& last = out.back();
        const Root& next = all[out.size()];
        if (last.value.imag() > 0.0 && next.value == std::conj(last.value)) out.push_back(next);
    }
    return out;
}


std::vector<std::string> root_methods() {
    std::vector<std::string> names;
    for (const auto& b : kBackends) names.emplace_back(b.name);
    return names;
}

bool RootOptions::is_valid(std::string* why) const {
    std::ostringstream os;
    auto positive = [&](double v, const char* name) {
        if (std::isfinite(v) && v > 0.0) return true;
        os << name << " = " << v << ": expected a finite value > 0";
        return false;
    };
    auto newton_ok = [&](const NewtonOptions& n, const char* prefix) {
        std::string m;
        if (n.is_valid(&m)) return true;
        os << prefix << ".newton." << m;
        return false;
    };
    bool ok = true;
    if (method != "auto" && find_backend(method) == nullptr) {
        os << "method = '" << method << "': expected auto";
        const std::vector<std::string> names = root_methods();
        for (std::size_t i = 0; i < names.size(); ++i) os << (i + 1 < names.size() ? ", " : " or ") << names[i];
        ok = false;
    } else if (count < 1) {
        os << "count = " << count << ": expected an integer >= 1";
        ok = false;
    } else if (degree < 0 || degree == 1) {
        os << "degree = " << degree << ": expected 0 (automatic) or an integer >= 2";
        ok = false;
    } else if (dense_limit < 0) {
        os << "dense_limit = " << dense_limit << ": expected an integer >= 0";
        ok = false;
    } else if (!positive(residual_tolerance, "residual_tolerance")) {
        ok = false;
    } else if (dense.max_degree < 2) {
        os << "dense.max_degree = " << dense.max_degree << ": expected an integer >= 2";
        ok = false;
    } else if (dense.max_rows < 3) {
        os << "dense.max_rows = " << dense.max_rows << ": expected an integer >= 3";
        ok = false;
    } else if (method == "dense" && degree > dense.max_degree) {
        os << "degree = " << degree << " exceeds dense.max_degree = " << dense.max_degree;
        ok = false;
    } else if (!positive(dense.agreement_tolerance, "dense.agreement_tolerance") ||
               !positive(dense.collocation_tolerance, "dense.collocation_tolerance") ||
               !positive(dense.spectral_tolerance, "dense.spectral_tolerance") || !newton_ok(dense.newton, "dense")) {
        ok = false;
    } else if (!(std::isfinite(dense.depth) && dense.depth >= 0.0)) {
        os << "dense.depth = " << dense.depth << ": expected a finite value >= 0 (0 = automatic)";
        ok = false;
    } else if (shift_invert.max_degree < 2) {
        os << "shift_invert.max_degree = " << shift_invert.max_degree << ": expected an integer >= 2";
        ok = false;
    } else if (method == "shift_invert" && degree > shift_invert.max_degree) {
        os << "degree = " << degree << " exceeds shift_invert.max_degree = " << shift_invert.max_degree;
        ok = false;
    } else if (shift_invert.eigenvalues_per_shift < 2) {
        os << "shift_invert.eigenvalues_per_shift = " << shift_invert.eigenvalues_per_shift << ": expected an integer >= 2";
        ok = false;
    } else if (shift_invert.max_shifts < 1) {
        os << "shift_invert.max_shifts = " << shift_invert.max_shifts << ": expected an integer >= 1";
        ok = false;
    } else if (!(std::isfinite(shift_invert.expected_shifts) && shift_invert.expected_shifts >= 0.0)) {
        os << "shift_invert.expected_shifts = " << shift_invert.expected_shifts << ": expected a finite number >= 0 (0 = automatic)";
        ok = false;
    } else if (shift_invert.arnoldi != "compact" && shift_invert.arnoldi != "spectra") {
        os << "shift_invert.arnoldi = '" << shift_invert.arnoldi << "': expected compact or spectra";
        ok = false;
    } else if (shift_invert.compact_max_steps < 2) {
        os << "shift_invert.compact_max_steps = " << shift_invert.compact_max_steps << ": expected an integer >= 2";
        ok = false;
    } else if (shift_invert.compact_restarts < 0) {
        os << "shift_invert.compact_restarts = " << shift_invert.compact_restarts << ": expected an integer >= 0";
        ok = false;
    } else if (shift_invert.arnoldi_max_restarts < 1) {
        os << "shift_invert.arnoldi_max_restarts = " << shift_invert.arnoldi_max_restarts << ": expected an integer >= 1";
        ok = false;
    } else if (!positive(shift_invert.arnoldi_tolerance, "shift_invert.arnoldi_tolerance") ||
               !positive(shift_invert.collocation_tolerance, "shift_invert.collocation_tolerance") ||
               !newton_ok(shift_invert.newton, "shift_invert")) {
        ok = false;
    } else if (!(contour.max_arg_step > 0.0 && contour.max_arg_step <= 1.0)) {
        os << "contour.max_arg_step = " << contour.max_arg_step << ": expected a value in (0, 1] radians";
        ok = false;
    } else if (contour.max_cells < 1) {
        os << "contour.max_cells = " << contour.max_cells << ": expected an integer >= 1";
        ok = false;
    } else if (!(contour.max_type_evaluations >= 1.0)) {
        os << "contour.max_type_evaluations = " << contour.max_type_evaluations << ": expected a value >= 1";
        ok = false;
    } else if (!newton_ok(contour.newton, "contour")) {
        ok = false;
    }
    if (!ok && why) *why = os.str();
    return ok;
}

void RootOptions::validate() const {
    std::string why;
    if (!is_valid(&why)) throw std::invalid_argument(why);
}

double marginal_band(cplx lambda) { return 1e-13 * std::max(1.0, std::abs(lambda)); }

double RootResult::spectral_abscissa() const {
    double a = -std::numeric_limits<double>::infinity();
    for (const auto& r : roots) a = std::max(a, r.value.real());
    return a;
}

std::string choose_root_method(const RootProblem& problem, const RootOptions& options) {
    options.validate();
    if (options.method != "auto") {
        const detail::RootBackend* b = find_backend(options.method);
        const std::string why = b->why_not(problem, options);
        if (!why.empty()) throw std::invalid_argument(why);
        return options.method;
    }
    const LinearDDE& dde = problem.dde;
    if (problem.characteristic && options.degree == 0) return "contour";
    if (dde.dimension() <= options.dense_limit || !dde.is_real() || dde.is_ode()) return "dense";
    return "shift_invert";
}

RootWorkEstimate estimate_root_work(const RootProblem& problem, const RootOptions& options) {
    const std::string method = choose_root_method(problem, options);
    RootWorkEstimate e = find_backend(method)->estimate(problem, options);
    e.method = method;
    return e;
}

RootResult rightmost_roots(const RootProblem& problem, const RootOptions& options) {
    const std::string method = choose_root_method(problem, options);
    if (options.before) {
        RootWorkEstimate e = find_backend(method)->estimate(problem, options);
        e.method = method;
        options.before(e);
    }
    RootResult r;
    long units = 0;
    try {
        // the backends run their loops on this thread (no parallel region): the callback's
        // exception reaches here
        if (!options.progress) {
            r = find_backend(method)->solve(problem, options);
        } else {
            RootOptions counted = options;
            counted.progress = [&units, &options](long done, long total, double par) {
                units = done;
                options.progress(done, total, par);
            };
            r = find_backend(method)->solve(problem, counted);
        }
    } catch (const Cancelled&) {
        r = RootResult{};
        r.status = Status::Cancelled;
        r.message = "cancelled by the progress callback after " + std::to_string(units) + " units of work (" + method + ")";
    }
    r.method_given = options.method;
    r.method_used = method;
    r.max_residual = 0.0;
    for (const auto& x : r.roots) r.max_residual = std::max(r.max_residual, x.residual);
    return r;
}

RootResult rightmost_roots(const LinearDDE& dde, const RootOptions& options) {
    return rightmost_roots(RootProblem{dde, nullptr}, options);
}

}  // namespace ddemap
