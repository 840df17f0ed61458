#include "ddemap/analysis/stability/classify.hpp"

#include "ddemap/analysis/stability/attenuation_margin.hpp"

#include "ddemap/analysis/calibration/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include "core/internal/text.hpp"

namespace ddemap {

namespace {

const char* const kNames[5] = {"k1", "k2", "th", "tau", "eta"};

/// z with Phi(z) = q (0 < q < 1): Newton on the complementary error function from z = 0;
/// Phi is log-concave, so the iteration from the centre converges monotonically.
double normal_quantile(double q) {
    double z = 0.0;
    for (int it = 0; it < 100; ++it) {
        const double cdf = 0.5 * std::erfc(-z / std::sqrt(2.0));
        const double pdf = std::exp(-0.5 * z * z) / std::sqrt(2.0 * M_PI);
        const double step = (cdf - q) / pdf;
        z -= step;
        if (std::abs(step) <= 1e-14 * std::max(1.0, std::abs(z))) break;
    }
    return z;
}

/// Standard normal draws by the Box-Muller transform on 53-bit uniforms of a 64-bit Mersenne
/// twister (the same numbers on every platform, unlike std::normal_distribution).
class NormalDraws {
public:
    explicit NormalDraws(unsigned long long seed) : m_rng(seed) {}
    double next() {
        if (m_has_spare) {
            m_has_spare = false;
            return m_spare;
        }
        const double u1 = (static_cast<double>(m_rng() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
        const double u2 = static_cast<double>(m_rng() >> 11) * 0x1.0p-53;          // [0, 1)
        const double r = std::sqrt(-2.0 * std::log(u1));
        m_spare = r * std::sin(2.0 * M_PI * u2);
        m_has_spare = true;
        return r * std::cos(2.0 * M_PI * u2);
    }

private:
    std::mt19937_64 m_rng;
    double m_spare = 0.0;
    bool m_has_spare = false;
};

/// Quantile of sorted values by linear interpolation between order statistics (type 7).
double quantile(const std::vector<double>& sorted, double q) {
    if (sorted.empty()) return 0.0;
    const double h = q * static_cast<double>(sorted.size() - 1);
    const auto i = static_cast<std::size_t>(std::floor(h));
    if (i + 1 >= sorted.size()) return sorted.back();
    return sorted[i] + (h - static_cast<double>(i)) * (sorted[i + 1] - sorted[i]);
}

MarginInterval interval(std::vector<double> v, double level) {
    std::sort(v.begin(), v.end());
    return {quantile(v, 0.5 * (1.0 - level)), quantile(v, 0.5), quantile(v, 0.5 * (1.0 + level))};
}

Status worse(Status a, Status b) { return a != Status::Converged ? a : b; }

}  // namespace

bool UncertaintyOptions::is_valid() const {
    try {
        validate();
        return true;
    } catch (const std::invalid_argument&) {
        return false;
    }
}

void UncertaintyOptions::validate() const {
    if (samples < 1) throw std::invalid_argument("uncertainty samples = " + std::to_string(samples) + ": expected >= 1");
    if (ring_samples < 0) throw std::invalid_argument("uncertainty ring_samples = " + std::to_string(ring_samples) + ": expected >= 0");
    if (!(level > 0.0 && level < 1.0))
        throw std::invalid_argument("uncertainty level = " + detail::format_number(level) + ": expected 0 < level < 1");
    validate_bounds(domain, {"k1", "k2", "th", "tau", "eta"});
    for (const auto& b : domain)
        if (b.lower < 0.0) throw std::invalid_argument("uncertainty domain: " + b.name + " >= " + detail::format_number(b.lower) + ": expected a lower bound >= 0");
    if (max_draws_per_sample < 1)
        throw std::invalid_argument("uncertainty max_draws_per_sample = " + std::to_string(max_draws_per_sample) + ": expected >= 1");
}

ProbabilityEstimate probability_estimate(int successes, int trials, double level) {
    if (trials < 1 || successes < 0 || successes > trials)
        throw std::invalid_argument("probability estimate of " + std::to_string(successes) + " successes in " + std::to_string(trials) +
                                    " trials: expected 0 <= successes <= trials, trials >= 1");
    if (!(level > 0.0 && level < 1.0))
        throw std::invalid_argument("probability level = " + detail::format_number(level) + ": expected 0 < level < 1");
    ProbabilityEstimate e;
    e.successes = successes;
    e.trials = trials;
    const double n = trials;
    e.p = successes / n;
    e.standard_error = std::sqrt(e.p * (1.0 - e.p) / n);
    const double z = normal_quantile(0.5 * (1.0 + level));
    const double denom = 1.0 + z * z / n;
    const double centre = (e.p + z * z / (2.0 * n)) / denom;
    const double half = z * std::sqrt(e.p * (1.0 - e.p) / n + z * z / (4.0 * n * n)) / denom;
    e.lower = successes == 0 ? 0.0 : std::max(0.0, centre - half);
    e.upper = successes == trials ? 1.0 : std::min(1.0, centre + half);
    return e;
}

VerdictUncertainty classify_with_uncertainty(const ParameterMap& ovrv, const Eigen::Matrix<double, 5, 5>& covariance, int cars,
                                             const UncertaintyOptions& options, const ExecutionPolicy& policy) {
    options.validate();
    if (!covariance.allFinite()) throw std::invalid_argument("parameter covariance: expected finite entries");
    const double scale = covariance.cwiseAbs().maxCoeff();
    if ((covariance - covariance.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale)
        throw std::invalid_argument("parameter covariance: expected a symmetric matrix");
    Eigen::Matrix<double, 5, 1> mean;
    for (int i = 0; i < 5; ++i) {
        const auto it = ovrv.find(kNames[i]);
        if (it == ovrv.end()) throw std::invalid_argument(std::string("parameters: expected a value for ") + kNames[i]);
        mean[i] = it->second;
    }
    (void)make_model("ovrv", ovrv);  // the centre itself must be a valid setting
    // C = V Lambda V^T; theta = mean + V sqrt(Lambda) z
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> es(Eigen::Matrix<double, 5, 5>(0.5 * (covariance + covariance.transpose())));
    Eigen::Matrix<double, 5, 1> lam = es.eigenvalues();
    const double lmax = lam.cwiseAbs().maxCoeff();
    for (int i = 0; i < 5; ++i) {
        if (lam[i] < -1e-12 * lmax)
            throw std::invalid_argument("parameter covariance: expected positive semidefinite (eigenvalue " + detail::format_number(lam[i]) + ")");
        if (std::abs(lam[i]) <= 1e-12 * lmax) lam[i] = 0.0;
    }
    const Eigen::Matrix<double, 5, 5> A = es.eigenvectors() * lam.cwiseSqrt().asDiagonal();

    // unlisted: [0, inf), the model's domain
    Eigen::Matrix<double, 5, 1> lo = Eigen::Matrix<double, 5, 1>::Zero(), hi;
    hi.setConstant(std::numeric_limits<double>::infinity());
    for (const auto& b : options.domain)
        for (int i = 0; i < 5; ++i)
            if (b.name == kNames[i]) {
                lo[i] = b.lower;
                hi[i] = b.upper;
            }
    std::string box;
    for (int i = 0; i < 5; ++i)
        if (std::isfinite(lo[i]) || std::isfinite(hi[i]))
            box += std::string(box.empty() ? "" : ", ") + kNames[i] +
                   (!std::isfinite(hi[i])   ? " >= " + detail::format_number(lo[i])  // (no "inf" in a message)
                    : !std::isfinite(lo[i]) ? " <= " + detail::format_number(hi[i])
                                            : " in [" + detail::format_number(lo[i]) + ", " + detail::format_number(hi[i]) + "]");

    VerdictUncertainty out;
    out.domain = options.domain;
    // draws on one thread in order, so the samples do not depend on the thread count
    NormalDraws normal(options.seed);
    const long budget = static_cast<long>(options.samples) * options.max_draws_per_sample;
    std::vector<Eigen::Matrix<double, 5, 1>> thetas;
    thetas.reserve(static_cast<std::size_t>(options.samples));
    while (static_cast<int>(thetas.size()) < options.samples && out.draws < budget) {
        Eigen::Matrix<double, 5, 1> z;
        for (int i = 0; i < 5; ++i) z[i] = normal.next();
        const Eigen::Matrix<double, 5, 1> theta = mean + A * z;
        ++out.draws;
        if ((theta.array() >= lo.array()).all() && (theta.array() <= hi.array()).all()) thetas.push_back(theta);
    }
    out.samples = static_cast<int>(thetas.size());
    out.verdicts.resize(thetas.size());
    parallel_for(static_cast<long>(thetas.size()), [&](long j) {
        VerdictSample& s = out.verdicts[static_cast<std::size_t>(j)];
        s.parameters = ovrv;
        for (int i = 0; i < 5; ++i) s.parameters[kNames[i]] = thetas[static_cast<std::size_t>(j)][i];
        const Linearisation lin = make_model("ovrv", s.parameters)->linearise();
        try {
            require_computable(lin);
        } catch (const std::invalid_argument&) {
            s.computable = false;  // undecided: no verdict outside the computable range
            return;
        }
        const StringResult st = analyse_string(lin);
        s.c2 = st.lowfreq.c2;
        s.sup_gamma_excess = st.sup_gamma - 1.0;
        s.plant_stable = st.plant_stable;
        s.string_stable = st.string_stable;
        s.decided = converged(st.plant_roots.status);
        if (j < options.ring_samples) {
            const RingResult ring = analyse_ring(lin, cars);
            s.has_ring = true;
            s.ring_abscissa = ring.spectral_abscissa;
            s.ring_stable = ring.stable;
            s.decided = s.decided && converged(ring.status);
        }
    }, policy);

    std::vector<double> c2, excess, abscissa;
    int string_unstable = 0, ring_unstable = 0, plant_unstable = 0;
    for (const auto& s : out.verdicts) {
        out.ring_samples += s.has_ring ? 1 : 0;
        if (!s.decided) {
            ++out.undecided;
            continue;
        }
        c2.push_back(s.c2);
        excess.push_back(s.sup_gamma_excess);
        string_unstable += s.string_stable ? 0 : 1;
        plant_unstable += s.plant_stable ? 0 : 1;
        if (s.has_ring) {
            abscissa.push_back(s.ring_abscissa);
            ring_unstable += s.ring_stable ? 0 : 1;
        }
    }
    const int decided = out.samples - out.undecided;
    if (decided > 0) {
        out.string_unstable = probability_estimate(string_unstable, decided, options.level);
        out.plant_unstable = probability_estimate(plant_unstable, decided, options.level);
        out.c2 = interval(c2, options.level);
        out.sup_gamma_excess = interval(excess, options.level);
    }
    if (!abscissa.empty()) {
        out.ring_unstable = probability_estimate(ring_unstable, static_cast<int>(abscissa.size()), options.level);
        out.ring_abscissa = interval(abscissa, options.level);
    }
    out.message = std::to_string(out.samples) + " samples of N(theta, C) restricted to " + box + " (" +
                  std::to_string(out.draws) + " draws, seed " + std::to_string(options.seed) + "), each classified exactly; the first " +
                  std::to_string(out.ring_samples) + " also as rings";
    if (out.samples < options.samples) {
        out.status = Status::BudgetExhausted;
        out.message = "only " + std::to_string(out.samples) + " of " + std::to_string(options.samples) + " samples in " +
                      std::to_string(out.draws) + " draws fell inside " + box + ": the parameter distribution lies mostly outside it (a parameter the data hardly determine)";
    }
    const auto outside = std::count_if(out.verdicts.begin(), out.verdicts.end(), [](const VerdictSample& s) { return !s.computable; });
    if (out.undecided > outside) {
        out.status = worse(out.status, Status::NumericalIssue);
        out.message += "; " + std::to_string(out.undecided - outside) + " samples undecided (a root computation did not converge), left out of p";
    }
    if (outside > 0) {
        out.status = worse(out.status, Status::NumericalIssue);
        out.message += "; " + std::to_string(outside) + " samples outside the computable range (README \"Verdicts and the computable range\"), left out of p";
    }
    if (decided == 0) out.status = worse(out.status, Status::NumericalIssue);
    return out;
}

std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars, const ExecutionPolicy& policy,
                                     const StringOptions& string_options) {
    string_options.validate();
    for (const auto& v : vehicles)  // every vehicle inside the computable range before any work
        require_computable(make_model("ovrv", v.parameters)->linearise(), "vehicle " + detail::quoted(v.name));
    std::vector<Classification> out(vehicles.size());
    parallel_for(static_cast<long>(vehicles.size()), [&](long i) {
        const Linearisation lin = make_model("ovrv", vehicles[i].parameters)->linearise();
        out[i].vehicle = vehicles[i];
        out[i].string = analyse_string(lin, string_options);
        if (out[i].string.plant_stable) out[i].attenuation_margin = attenuation_scan(lin).margin;
        out[i].ring = analyse_ring(lin, cars);
    }, policy);
    return out;
}

std::vector<Classification> classify(const std::vector<CalibratedVehicle>& vehicles, int cars, const UncertaintyOptions& uncertainty,
                                     const ExecutionPolicy& policy, const StringOptions& string_options) {
    uncertainty.validate();
    std::vector<Classification> out = classify(vehicles, cars, policy, string_options);
    ExecutionPolicy inner = policy;
    inner.progress = nullptr;
    for (std::size_t i = 0; i < vehicles.size(); ++i) {
        if (!vehicles[i].has_covariance) continue;
        // the fit's own search space, where the file carries it
        UncertaintyOptions own = uncertainty;
        bool from_fit = false;
        for (auto& b : own.domain)
            if (const BoundedParameter* f = find_bound(vehicles[i].bounds, b.name)) {
                b = *f;
                from_fit = true;
            }
        if (from_fit) own.validate();
        out[i].uncertainty = classify_with_uncertainty(vehicles[i].parameters, vehicles[i].covariance, cars, own, inner);
        out[i].uncertainty.domain_from_fit = from_fit;
        out[i].has_uncertainty = true;
        if (policy.progress) policy.progress(static_cast<long>(i + 1), static_cast<long>(vehicles.size()));
    }
    return out;
}

Status classification_status(const std::vector<Classification>& rows) {
    Status status = Status::Converged;
    for (const auto& r : rows) {
        if (r.ring.status != Status::Converged) status = r.ring.status;
        if (r.string.plant_roots.status != Status::Converged) status = r.string.plant_roots.status;
        if (r.has_uncertainty && r.uncertainty.status != Status::Converged) status = r.uncertainty.status;
        if (r.has_distance && r.distance.status != Status::Converged) status = r.distance.status;
        if (r.string.peak && r.string.peak->verdict == Verdict::Undecided) status = r.string.peak->status;
    }
    return status;
}

ParameterBounds classification_domain() {
    ParameterBounds d;
    for (const auto& b : paper_calibration_bounds())
        if (b.name != "eta") d.push_back(b);
    return d;
}

}  // namespace ddemap
