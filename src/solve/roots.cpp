#include "ddemap/solve/roots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace ddemap {

namespace {

double scale_of(cplx z) { return std::max(1.0, std::abs(z)); }

bool rightmost_first(const Root& a, const Root& b) {
    if (a.value.real() != b.value.real()) return a.value.real() > b.value.real();
    return a.value.imag() > b.value.imag();
}

}  // namespace

namespace detail {

int degree_for_radius(double radius, double tau) {
    const double m = 0.7 * radius * tau + 15.0;
    return m > 1e6 ? 1000000 : static_cast<int>(std::ceil(m));
}

double radius_for_degree(int degree, double tau) { return std::max(0.0, (degree - 15.0) / (0.7 * tau)); }

}  // namespace detail

using detail::degree_for_radius;
using detail::radius_for_degree;

std::string to_string(RootStatus s) {
    switch (s) {
        case RootStatus::Converged: return "converged";
        case RootStatus::MaxDegreeReached: return "max_degree_reached";
        case RootStatus::EigenFailure: return "eigen_failure";
    }
    return "unknown";
}

void RootOptions::validate() const {
    auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
    if (count < 1) fail("count = " + std::to_string(count) + ": expected an integer >= 1");
    if (initial_degree < 0) fail("initial_degree = " + std::to_string(initial_degree) + ": expected 0 (automatic) or >= 1");
    if (max_degree < 2) fail("max_degree = " + std::to_string(max_degree) + ": expected an integer >= 2");
    if (initial_degree > max_degree) fail("initial_degree exceeds max_degree");
    if (newton_max_iterations < 1) fail("newton_max_iterations: expected >= 1");
    auto positive = [&](double v, const char* name) {
        if (!(std::isfinite(v) && v > 0.0)) {
            std::ostringstream os;
            os << name << " = " << v << ": expected a finite value > 0";
            fail(os.str());
        }
    };
    positive(newton_tolerance, "newton_tolerance");
    positive(residual_tolerance, "residual_tolerance");
    positive(agreement_tolerance, "agreement_tolerance");
    positive(collocation_tolerance, "collocation_tolerance");
    positive(spectral_tolerance, "spectral_tolerance");
    if (!(std::isfinite(depth) && depth >= 0.0)) {
        std::ostringstream os;
        os << "depth = " << depth << ": expected a finite value >= 0 (0 = automatic)";
        fail(os.str());
    }
}

double marginal_band(cplx lambda) { return 1e-13 * std::max(1.0, std::abs(lambda)); }

double RootResult::spectral_abscissa() const {
    double a = -std::numeric_limits<double>::infinity();
    for (const auto& r : roots) a = std::max(a, r.value.real());
    return a;
}

double relative_residual(const LinearDDE& dde, cplx lambda) {
    const MatrixXc d = dde.characteristic_matrix(lambda);
    Eigen::JacobiSVD<MatrixXc> svd(d);
    const double smin = svd.singularValues()(svd.singularValues().size() - 1);
    const double scale = std::abs(lambda) + dde.root_bound(lambda.real());
    return scale > 0.0 ? smin / scale : smin;
}

bool refine_root(const LinearDDE& dde, cplx guess, const RootOptions& options, Root& out) {
    cplx lambda = guess;
    double last_step = std::numeric_limits<double>::infinity();
    bool converged = false;
    for (int it = 0; it < options.newton_max_iterations; ++it) {
        const MatrixXc d = dde.characteristic_matrix(lambda);
        const MatrixXc dp = dde.characteristic_derivative(lambda);
        Eigen::PartialPivLU<MatrixXc> lu(d);
        const cplx t = lu.solve(dp).trace();
        if (!std::isfinite(t.real()) || !std::isfinite(t.imag()) || t == cplx(0.0)) {
            // Delta(lambda) exactly singular: lambda is a root to machine precision
            last_step = 0.0;
            converged = true;
            break;
        }
        const cplx step = 1.0 / t;
        lambda -= step;
        last_step = std::abs(step);
        if (!std::isfinite(lambda.real()) || !std::isfinite(lambda.imag())) return false;
        if (last_step <= options.newton_tolerance * scale_of(lambda)) {
            converged = true;
            break;
        }
    }
    out.value = lambda;
    out.newton_step = last_step;
    out.residual = relative_residual(dde, lambda);
    out.collocation_error = std::abs(lambda - guess);
    // A multiple root converges only linearly and stalls near sqrt(eps): accept it on the residual.
    return (converged || last_step <= 1e-6 * scale_of(lambda)) && out.residual <= options.residual_tolerance;
}

namespace {

/// Refine candidates, merge duplicates, return sorted rightmost first.
std::vector<Root> refine_all(const LinearDDE& dde, std::vector<cplx> candidates, const RootOptions& options,
                             int& dropped) {
    const bool real = dde.is_real();
    std::vector<Root> found;
    for (cplx c : candidates) {
        if (real && c.imag() < 0.0) continue;  // the conjugate partner is (or will be) refined instead
        Root r;
        if (!refine_root(dde, c, options, r)) {
            ++dropped;
            continue;
        }
        if (real) {
            if (r.value.imag() < 0.0) r.value = std::conj(r.value);
            if (std::abs(r.value.imag()) <= 1e-12 * scale_of(r.value) && r.value.imag() != 0.0) {
                Root rr;
                if (refine_root(dde, cplx(r.value.real(), 0.0), options, rr) && rr.value.imag() == 0.0) {
                    rr.collocation_error = std::abs(rr.value - c);
                    r = rr;
                }
            }
        }
        bool dup = false;
        for (auto& f : found) {
            if (std::abs(f.value - r.value) <= 1e-9 * scale_of(r.value)) {
                dup = true;
                ++dropped;
                f.collocation_error = std::min(f.collocation_error, r.collocation_error);
                if (r.residual < f.residual) {
                    const double ce = f.collocation_error;
                    f = r;
                    f.collocation_error = ce;
                }
                break;
            }
        }
        if (!dup) found.push_back(r);
    }
    if (real) {
        const std::size_t n = found.size();
        for (std::size_t i = 0; i < n; ++i) {
            if (found[i].value.imag() > 0.0) {
                Root c = found[i];
                c.value = std::conj(c.value);
                found.push_back(c);
            }
        }
    }
    std::sort(found.begin(), found.end(), rightmost_first);
    return found;
}

}  // namespace

std::vector<Root> detail::cut_rightmost(const std::vector<Root>& all, int count) {
    std::vector<Root> out(all.begin(), all.begin() + std::min<std::size_t>(all.size(), count));
    if (!out.empty() && out.size() < all.size()) {
        const Root& last = out.back();
        const Root& next = all[out.size()];
        if (last.value.imag() > 0.0 && next.value == std::conj(last.value)) out.push_back(next);
    }
    return out;
}

using detail::cut_rightmost;

RootResult rightmost_roots(const LinearDDE& dde, const RootOptions& options, const EigenSolverBackend* backend) {
    options.validate();
    DenseEigenSolver dense;
    if (backend == nullptr) backend = &dense;
    RootResult result;

    if (dde.is_ode()) {
        const MatrixXc a = dde.a0();
        std::vector<cplx> ev;
        if (dde.is_real()) {
            // real arithmetic: exact conjugate pairs and real eigenvalues with zero imaginary part
            // (refine_all skips Im < 0, so a real eigenvalue computed as x - 1e-18 i would be lost)
            Eigen::EigenSolver<Eigen::MatrixXd> es(a.real(), false);
            ev.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
        } else {
            Eigen::ComplexEigenSolver<MatrixXc> es(a, false);
            ev.assign(es.eigenvalues().data(), es.eigenvalues().data() + es.eigenvalues().size());
        }
        result.roots = cut_rightmost(refine_all(dde, ev, options, result.dropped), options.count);
        result.degree = 0;
        result.status = RootStatus::Converged;
        result.covered_radius = std::numeric_limits<double>::infinity();
        result.reason = "no delay: the eigenvalues of the ODE matrix A0 + sum A_k, refined by Newton";
        return result;
    }

    const double tau = dde.max_delay();
    int m = options.initial_degree > 0
                ? options.initial_degree
                : std::clamp(degree_for_radius(dde.root_bound(0.0), tau), 8, options.max_degree);
    std::vector<Root> previous;
    std::size_t previous_in_strip = 0;
    int previous_degree = 0;
    const int wanted = options.count + 4;
    for (;;) {
        const EigenResult eig = backend->eigenvalues(dde, m, wanted);
        if (eig.status != EigenStatus::Successful) {
            result.status = RootStatus::EigenFailure;
            result.degree = m;
            result.roots = previous;
            result.reason = "the " + backend->name() + " eigen-solver failed at degree " + std::to_string(m);
            return result;
        }
        const double covered = radius_for_degree(m, tau);
        // eigenvalues beyond the resolved radius are discretisation artefacts, not roots
        std::vector<cplx> ev;
        for (cplx z : eig.values)
            if (std::abs(z) <= 1.5 * covered + 1.0) ev.push_back(z);
        std::sort(ev.begin(), ev.end(), [](cplx a, cplx b) { return a.real() > b.real(); });
        const std::size_t k = std::min<std::size_t>(ev.size(), 2 * options.count + 8);
        ev.resize(k);
        int dropped = 0;
        std::vector<Root> current = cut_rightmost(refine_all(dde, ev, options, dropped), options.count);
        // Completeness is certified right of sigma: the last of the `count` roots, or, when fewer
        // were found, the floor of the strip Re >= alpha - depth (all roots there are listed).
        const double depth = options.depth > 0.0 ? options.depth : 2.0 / tau;
        const bool full = current.size() >= std::size_t(options.count);
        const double floor = current.empty() ? -depth : current.front().value.real() - depth;
        const double sigma = full ? current.back().value.real() : floor;
        std::size_t in_strip = 0;
        while (in_strip < current.size() && current[in_strip].value.real() >= sigma) ++in_strip;
        // every root right of sigma is within the bound; M must resolve that disc
        const double needed = dde.root_bound(sigma);
        double change = std::numeric_limits<double>::infinity();
        bool collocated = true;
        if (previous_degree > 0 && previous_in_strip == in_strip) {
            change = 0.0;
            for (std::size_t i = 0; i < in_strip; ++i) {
                change = std::max(change, std::abs(current[i].value - previous[i].value) / scale_of(current[i].value));
            }
        }
        double worst_collocation = 0.0;
        for (std::size_t i = 0; i < in_strip; ++i) {
            const double e = current[i].collocation_error / scale_of(current[i].value);
            worst_collocation = std::max(worst_collocation, e);
            if (e > options.collocation_tolerance) collocated = false;
        }
        // Two certificates: the eigenvalues themselves already equal the Newton-refined roots
        // (spectral accuracy reached at this M), or the refined roots agree between two degrees.
        const bool covers = covered >= needed;
        // (With fewer than `count` roots found only the second certificate applies: a larger M
        // may reveal more roots, so the same set must come out of two degrees.)
        const bool spectral = full && worst_collocation <= options.spectral_tolerance && covers;
        const bool agreed = change <= options.agreement_tolerance && collocated && covers;
        const bool settled = spectral || agreed;
        if (settled || m >= options.max_degree) {
            result.roots = current;
            result.degree = m;
            result.previous_degree = previous_degree;
            result.degree_change = change;
            result.collocation_error = worst_collocation;
            result.covered_radius = covered;
            result.strip_floor = sigma;
            result.dropped = dropped;
            std::ostringstream os;
            os.precision(3);
            if (settled) {
                result.status = RootStatus::Converged;
                os << "the " << in_strip << " rightmost roots" << (full ? "" : " (all with Re >= " + std::to_string(floor) + ")");
                if (spectral) {
                    os << " equal collocation eigenvalues at M=" << m << " to " << worst_collocation
                       << " (relative; spectral accuracy reached)";
                } else {
                    os << " agree between M=" << previous_degree << " and M=" << m << " (max relative change " << change
                       << "; eigenvalues within " << worst_collocation << ")";
                }
                os << ", and M resolves |lambda| <= " << covered << ", beyond the bound " << needed
                   << " on any root with Re >= " << sigma;
            } else {
                result.status = RootStatus::MaxDegreeReached;
                os << "max degree M=" << m << " reached before the roots settled (change " << change
                   << ", resolved radius " << covered << " of needed " << needed << ")";
            }
            result.reason = os.str();
            return result;
        }
        previous = current;
        previous_in_strip = in_strip;
        previous_degree = m;
        int next = static_cast<int>(std::ceil(1.5 * m));
        if (covered < needed) next = std::max(next, degree_for_radius(needed, tau));
        m = std::min(next, options.max_degree);
    }
}

}  // namespace ddemap
