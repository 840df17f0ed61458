#include "tables.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common.hpp"
#include "format.hpp"

namespace ddemap::cli {

namespace {
/// The table's verdict words: stable in lower case (the common case), the others in capitals.
std::string word(Verdict v) { return v == Verdict::Stable ? std::string("stable") : verdict_word(v); }
}  // namespace

std::string classification_table(const std::vector<Classification>& rows, int cars, const std::string& source) {
    std::ostringstream out;
    out << "vehicle settings of " << source << "; ring N = " << ring_name(cars) << "\n\n";
    // the name column as wide as the longest name (names from files can be long), so the columns stay aligned
    int width = 7;
    for (const auto& row : rows) width = std::max(width, static_cast<int>(row.vehicle.name.size()));
    // peak (L-infinity) verdict and ||h||_1, when asked (classify --peak)
    const bool peak = std::any_of(rows.begin(), rows.end(), [](const Classification& r) { return r.string.peak.has_value(); });
    char header[256];
    std::snprintf(header, sizeof header, " %6s %6s %6s %6s %6s   %-9s %-9s %-9s %10s %7s %9s %7s", "k1", "k2", "th", "tau", "eta",
                  "plant", "ring", "string", "sup|Gamma|", "w_peak", "c2", "m*");
    out << "name" << std::string(static_cast<std::size_t>(width) - 4, ' ') << header;
    if (peak) {
        std::snprintf(header, sizeof header, "   %-9s %10s", "peak", "||h||_1");
        out << header;
    }
    const bool dist = std::any_of(rows.begin(), rows.end(), [](const Classification& r) { return r.has_distance; });
    if (dist) out << "   flip at";
    out << "\n";
    // the units under their columns (c2: the w^2 coefficient of |D(i w)|^2 - |N(i w)|^2)
    std::snprintf(header, sizeof header, " %6s %6s %6s %6s %6s   %-9s %-9s %-9s %10s %7s %9s %7s", "1/s^2", "1/s", "s", "s", "m", "", "", "", "1",
                  "rad/s", "1/s^2", "s");
    out << std::string(static_cast<std::size_t>(width), ' ') << header;
    if (peak) {
        std::snprintf(header, sizeof header, "   %-9s %10s", "", "1");
        out << header;
    }
    if (dist) out << "  change";
    out << "\n";
    for (const auto& row : rows) {
        char line[256];
        const auto& p = row.vehicle.parameters;
        out << row.vehicle.name << std::string(static_cast<std::size_t>(width) - row.vehicle.name.size(), ' ');
        std::snprintf(line, sizeof line, " %6.3f %6.3f %6.3f %6.3f %6.3f   %-9s %-9s %-9s %10.6f %7.4f %9.2e",
                      p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"), p.at("eta"),
                      word(row.string.plant_verdict).c_str(), word(row.ring.verdict).c_str(),
                      word(row.string.string_verdict).c_str(), row.string.sup_gamma, row.string.omega_peak,
                      row.string.lowfreq_margin);
        out << line;
        // m*: the attenuation margin (> 0 inside the string-stable set, < 0 outside)
        if (std::isfinite(row.attenuation_margin)) std::snprintf(line, sizeof line, " %7.3f", row.attenuation_margin);
        else std::snprintf(line, sizeof line, " %7s", "-");
        out << line;
        if (peak) {
            const PeakResult* pk = row.string.peak ? &*row.string.peak : nullptr;
            if (pk && pk->verdict != Verdict::Undecided && pk->finite) std::snprintf(line, sizeof line, "   %-9s %10.6f", word(pk->verdict).c_str(), pk->norm);
            else std::snprintf(line, sizeof line, "   %-9s %10s", pk ? word(pk->verdict).c_str() : "", pk && pk->verdict != Verdict::Undecided ? "inf" : "");
            out << line;
        }
        if (dist) {
            // the relative change of (k1, k2, th, tau) that flips the string verdict
            if (row.has_distance && row.distance.status == Status::Converged) std::snprintf(line, sizeof line, " %8.1f %%", 100.0 * row.distance.distance);
            else std::snprintf(line, sizeof line, " %10s", row.has_distance ? "undecided" : "-");
            out << line;
        }
        out << "\n";
    }
    if (dist) {
        out << "\nflip at: the smallest relative change of (k1, k2, th, tau), sqrt(sum ((x - x0) / x0)^2), found to turn a string-stable car\n"
               "unstable or an unstable one stable (certified verdicts on either side; a local search, docs/reference/outputs.md)\n";
    }
    bool any = false;
    for (const auto& row : rows) any = any || row.has_uncertainty;
    if (!any) return out.str();
    out << "\nverdicts under the calibration's parameter uncertainty (p: probability of string instability, "
        << "Wilson 95 % bounds when every sample agrees, else p -+ its Monte Carlo standard error; margins: 95 % intervals)\n";
    for (const auto& row : rows) {
        out << row.vehicle.name << ": ";
        if (!row.has_uncertainty) {
            out << "no covariance given\n";
            continue;
        }
        const VerdictUncertainty& u = row.uncertainty;
        out << "string " << (row.string.string_stable ? "stable" : "UNSTABLE") << " (" << probability_text(u.string_unstable) << ")";
        if (u.ring_unstable.trials > 0)
            out << ", ring " << (row.ring.stable ? "stable" : "UNSTABLE") << " (" << probability_text(u.ring_unstable) << ")";
        if (u.string_unstable.trials > 0) {
            out << "; 95 % intervals: c2 [" << rounded(u.c2.lower, 3) << ", " << rounded(u.c2.upper, 3) << "] 1/s^2, sup|Gamma|-1 ["
                << rounded(u.sup_gamma_excess.lower, 3) << ", " << rounded(u.sup_gamma_excess.upper, 3) << "]";
            if (u.ring_unstable.trials > 0)
                out << ", ring abscissa [" << rounded(u.ring_abscissa.lower, 3) << ", " << rounded(u.ring_abscissa.upper, 3) << "] 1/s";
        }
        out << "; " << u.samples << " samples (" << u.ring_samples << " as rings)";
        if (u.status != Status::Converged) out << "; UNDECIDED: " << u.message;
        out << "\n";
    }
    return out.str();
}

std::string probability_text(const ProbabilityEstimate& e) {
    if (e.trials == 0) return "p undecided";
    char b[64];
    if (e.successes == e.trials) {
        std::snprintf(b, sizeof b, "p > %.3f", std::floor(e.lower * 1000.0) / 1000.0);
    } else if (e.successes == 0) {
        std::snprintf(b, sizeof b, "p < %.3f", std::ceil(e.upper * 1000.0) / 1000.0);
    } else {
        std::snprintf(b, sizeof b, "p = %.3f +- %.3f", e.p, e.standard_error);
    }
    return b;
}

std::string growth_table(const std::vector<GrowthResult>& g) {
    // columns: the name as wide as the longest, then one 6-wide column per follower position
    // (at most 8 shown), then where the platoon fails
    std::size_t width = 4, shown = 0;
    for (const auto& r : g) {
        width = std::max(width, r.name.size());
        shown = std::max(shown, std::min<std::size_t>(r.amplification.size(), 8));
    }
    const bool more = std::any_of(g.begin(), g.end(), [](const GrowthResult& r) { return r.amplification.size() > 8; });
    std::ostringstream out;
    out << "amplification of the lead's speed drop by follower position (speed drop / lead drop)\n";
    out << "name" << std::string(width - 4, ' ');
    for (std::size_t i = 0; i < shown; ++i) {
        char c[16];
        std::snprintf(c, sizeof c, " %6s", ("#" + std::to_string(i + 1)).c_str());
        out << c;
    }
    out << (more ? "    " : "") << "   platoon fails at\n";
    for (const auto& r : g) {
        out << r.name << std::string(width - r.name.size(), ' ');
        for (std::size_t i = 0; i < shown; ++i) {
            char c[16];
            if (i < r.amplification.size()) std::snprintf(c, sizeof c, " %6.3f", r.amplification[i]);
            else std::snprintf(c, sizeof c, " %6s", "");
            out << c;
        }
        out << (more ? (r.amplification.size() > 8 ? " ..." : "    ") : "") << "   ";
        if (r.status != Status::Converged) out << "UNDECIDED (" << to_string(r.status) << ")";
        else if (r.failed_at) out << "car " << r.failed_at << " (" << r.failure << " at t = " << rounded(r.failure_time, 4) << " s)";
        else out << "none";
        out << "\n";
    }
    return out.str();
}

}  // namespace ddemap::cli
