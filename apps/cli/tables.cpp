#include "tables.hpp"

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
    out << "name      k1     k2     th     tau    eta     plant     ring      string    sup|Gamma|  w_peak   c2\n";
    for (const auto& row : rows) {
        char line[256];
        const auto& p = row.vehicle.parameters;
        std::snprintf(line, sizeof line, "%-7s %6.3f %6.3f %6.3f %6.3f %6.3f   %-9s %-9s %-9s %9.6f %7.4f %9.2e\n",
                      row.vehicle.name.c_str(), p.at("k1"), p.at("k2"), p.at("th"), p.at("tau"), p.at("eta"),
                      word(row.string.plant_verdict).c_str(), word(row.ring.verdict).c_str(),
                      word(row.string.string_verdict).c_str(), row.string.sup_gamma, row.string.omega_peak,
                      row.string.lowfreq_margin);
        out << line;
    }
    return out.str();
}

std::string growth_table(const std::vector<GrowthResult>& g) {
    std::ostringstream out;
    out << "name     amplification by position (speed drop / lead drop)                       platoon fails at\n";
    for (const auto& r : g) {
        char head[32];
        std::snprintf(head, sizeof head, "%-8s", r.name.c_str());
        out << head;
        for (std::size_t i = 0; i < r.amplification.size() && i < 8; ++i) out << " " << rounded(r.amplification[i], 3);
        if (r.amplification.size() > 8) out << " ...";
        out << "   ";
        if (r.failed_at) out << "car " << r.failed_at << " (" << r.failure << " at t = " << rounded(r.failure_time, 4) << " s)";
        else out << "none";
        out << "\n";
    }
    return out.str();
}

}  // namespace ddemap::cli
